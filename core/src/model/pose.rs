//! Rigid transforms used throughout the kinematic chain.
//!
//! Frames: a `Pose` maps coordinates expressed in a child frame into its parent
//! frame, `x_parent = r * x_child + p`. Units: metres and radians (SI), as every
//! internal quantity in robocal. The elementary transforms `Rot(x, ·)`, `Tr(x, ·)`,
//! … are those of the thesis's eq. 4.1 (Craig's modified DH) and are applied by
//! post-multiplication, which keeps forward kinematics allocation-free.

pub use super::orientation::rotation_log;
use nalgebra::{Matrix3, Vector3};
use serde::{Deserialize, Serialize};

/// A rigid transform `x_parent = r · x_child + p` (SI units).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Pose {
    /// Rotation; its columns are the child axes expressed in the parent frame.
    pub r: Matrix3<f64>,
    /// Origin of the child frame in the parent frame [m].
    pub p: Vector3<f64>,
}

impl Default for Pose {
    fn default() -> Self {
        Self::identity()
    }
}

impl Pose {
    /// The identity transform.
    pub fn identity() -> Self {
        Pose {
            r: Matrix3::identity(),
            p: Vector3::zeros(),
        }
    }

    /// The transform with rotation `r` and translation `p`.
    pub fn new(r: Matrix3<f64>, p: Vector3<f64>) -> Self {
        Pose { r, p }
    }

    /// A pure translation by `p`.
    pub fn from_translation(p: Vector3<f64>) -> Self {
        Pose {
            r: Matrix3::identity(),
            p,
        }
    }

    /// `self · other`.
    pub fn compose(&self, other: &Pose) -> Pose {
        Pose {
            r: self.r * other.r,
            p: self.r * other.p + self.p,
        }
    }

    /// The inverse transform, `(Rᵀ, −Rᵀ·p)`.
    pub fn inverse(&self) -> Pose {
        let rt = self.r.transpose();
        Pose {
            r: rt,
            p: -(rt * self.p),
        }
    }

    /// Maps a point of the child frame into the parent frame.
    pub fn transform_point(&self, x: &Vector3<f64>) -> Vector3<f64> {
        self.r * x + self.p
    }

    /// The child frame's x axis in the parent frame (first column of `r`).
    pub fn x_axis(&self) -> Vector3<f64> {
        self.r.column(0).into_owned()
    }
    /// The child frame's y axis in the parent frame (second column of `r`).
    pub fn y_axis(&self) -> Vector3<f64> {
        self.r.column(1).into_owned()
    }
    /// The child frame's z axis in the parent frame (third column of `r`).
    pub fn z_axis(&self) -> Vector3<f64> {
        self.r.column(2).into_owned()
    }

    /// `self · Rot(x, angle)`.
    pub fn rot_x(&mut self, angle: f64) {
        self.rot_x_sc(angle.sin_cos());
    }

    /// `self · Rot(x, α)` from `(sin α, cos α)`, for callers that keep the
    /// sines and cosines of constant angles.
    #[inline(always)]
    pub fn rot_x_sc(&mut self, (s, c): (f64, f64)) {
        let c1 = self.r.column(1).into_owned();
        let c2 = self.r.column(2).into_owned();
        self.r.set_column(1, &(c1 * c + c2 * s));
        self.r.set_column(2, &(c2 * c - c1 * s));
    }

    /// `self · Rot(y, angle)`.
    pub fn rot_y(&mut self, angle: f64) {
        self.rot_y_sc(angle.sin_cos());
    }

    /// `self · Rot(y, β)` from `(sin β, cos β)`.
    #[inline(always)]
    pub fn rot_y_sc(&mut self, (s, c): (f64, f64)) {
        let c0 = self.r.column(0).into_owned();
        let c2 = self.r.column(2).into_owned();
        self.r.set_column(0, &(c0 * c - c2 * s));
        self.r.set_column(2, &(c0 * s + c2 * c));
    }

    /// `self · Rot(z, angle)`.
    pub fn rot_z(&mut self, angle: f64) {
        self.rot_z_sc(angle.sin_cos());
    }

    /// `self · Rot(z, θ)` from `(sin θ, cos θ)`.
    #[inline(always)]
    pub fn rot_z_sc(&mut self, (s, c): (f64, f64)) {
        let c0 = self.r.column(0).into_owned();
        let c1 = self.r.column(1).into_owned();
        self.r.set_column(0, &(c0 * c + c1 * s));
        self.r.set_column(1, &(c1 * c - c0 * s));
    }

    /// `self · Tr(v)` with `v` in the child frame.
    pub fn translate(&mut self, v: &Vector3<f64>) {
        self.p += self.r * v;
    }

    /// `self · Tr(x, a)`.
    pub fn tr_x(&mut self, a: f64) {
        self.p += self.r.column(0) * a;
    }
    /// `self · Tr(y, b)`.
    pub fn tr_y(&mut self, b: f64) {
        self.p += self.r.column(1) * b;
    }
    /// `self · Tr(z, d)`.
    pub fn tr_z(&mut self, d: f64) {
        self.p += self.r.column(2) * d;
    }
}

/// Rotation `Rz(rz) · Ry(ry) · Rx(rx)` (fixed-axis XYZ), angles in radians:
/// [`super::orientation::fixed_xyz_matrix`].
pub fn rpy_matrix(rx: f64, ry: f64, rz: f64) -> Matrix3<f64> {
    super::orientation::fixed_xyz_matrix(rx, ry, rz)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn elementary_rotations_match_nalgebra() {
        for &ang in &[0.3_f64, -1.2, 2.9] {
            let mut p = Pose::identity();
            p.rot_x(ang);
            let e = nalgebra::Rotation3::from_axis_angle(&Vector3::x_axis(), ang);
            assert!((p.r - e.matrix()).norm() < 1e-15);
            let mut p = Pose::identity();
            p.rot_y(ang);
            let e = nalgebra::Rotation3::from_axis_angle(&Vector3::y_axis(), ang);
            assert!((p.r - e.matrix()).norm() < 1e-15);
            let mut p = Pose::identity();
            p.rot_z(ang);
            let e = nalgebra::Rotation3::from_axis_angle(&Vector3::z_axis(), ang);
            assert!((p.r - e.matrix()).norm() < 1e-15);
        }
    }

    #[test]
    fn rotation_log_is_accurate_for_small_and_large_angles() {
        for &ang in &[1e-9_f64, 2e-6, 0.3, 2.5, 3.1] {
            let axis = Vector3::new(0.3, -0.5, 0.8).normalize();
            let r = nalgebra::Rotation3::from_axis_angle(&nalgebra::Unit::new_normalize(axis), ang);
            let w = rotation_log(r.matrix());
            assert!((w - axis * ang).norm() < 1e-15 + 1e-12 * ang, "{ang}");
        }
    }

    #[test]
    fn compose_and_inverse() {
        let mut a = Pose::identity();
        a.rot_z(0.4);
        a.tr_x(1.0);
        a.rot_y(-0.7);
        a.tr_z(0.3);
        let i = a.compose(&a.inverse());
        assert!((i.r - Matrix3::identity()).norm() < 1e-14);
        assert!(i.p.norm() < 1e-14);
        // Translation along the rotated x axis.
        let mut b = Pose::identity();
        b.rot_z(std::f64::consts::FRAC_PI_2);
        b.tr_x(2.0);
        assert!((b.p - Vector3::new(0.0, 2.0, 0.0)).norm() < 1e-15);
    }
}

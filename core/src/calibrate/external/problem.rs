//! The joint least-squares problem of a tilt-rotate positioner: every
//! reading of every reflector, both axes' lines, zero offsets and scales and
//! the reflectors' positions on the face plate at once.
//!
//! Prediction (cell frame): `x = T·(M1(θ1)·M2(θ2)·F·p)`, `T` the base in the
//! cell, `Mk` the motion about axis k's line (`R(u, θ)(y − c) + c`), `F` the
//! nominal face plate frame, `p` the reflector in it, `θk = sk·vk + ok`.
//! Residual `r = x_measured − x` [m]; cost `‖r‖²`.
//!
//! Parameters, as increments at the current point (retracted onto it by
//! [`State::step`]):
//! - axis 1: two small rotations of `u1` about `a1`, `b1` (an orthonormal
//!   pair across `u1`), two moves of its line along `a1`, `b1`, `o1`, `s1`;
//! - axis 2: `γ`, the angle of `u2` out of the plane across nominal `u1`
//!   (`u2 = cos γ·e + sin γ·u1ⁿ`, `e` nominal `u2` made orthogonal to nominal
//!   `u1`), two moves of its line across `u2`, `o2`, `s2`;
//! - reflector 0 (the reference): along its design radius and along the face
//!   plate's z; the other reflectors: x, y, z.
//!
//! Gauge: turning all that axis 1 carries about axis 1 and taking the same
//! angle off `o1` changes no reading; holding `u2` in the plane of nominal
//! `u1` and `e` fixes it, so `o1` is the tilt angle at which axis 2 lies in
//! that plane. Likewise turning the reflectors about axis 2 against `o2`:
//! holding reflector 0 at its design azimuth fixes it, so `o2` is the rotate
//! angle at which reflector 0 stands on its design azimuth in the face plate
//! frame.
//!
//! Jacobian (of the prediction, `r(x ⊕ δ) ≈ r − J·δ`), with `z = y − c`:
//! a move `e` of the line: `(I − R)·e`; a rotation `ω` of the direction:
//! `ω × (R·z) − R·(ω × z)` (since `R(Q·u, θ) = Q·R(u, θ)·Qᵀ`); the angle:
//! `u × (R·z)`; axis 2's terms carried by `R1`, a reflector's by `R1·R2·F.r`;
//! all carried into the cell frame by `T.r`. Checked against central
//! differences in the tests.

use super::outcome::PositionerReading;
use crate::model::external::rotary::closest_to_origin;
use crate::model::external::{RotaryAxis, TiltRotate};
use crate::model::Pose;
use crate::optim::lm::LeastSquaresProblem;
use nalgebra::{DMatrix, DVector, Matrix3, Rotation3, Vector3};

/// Parameters before the reflectors'.
pub const AXIS_PARAMETERS: usize = 11;

/// An orthonormal pair across the unit `u`.
pub fn across(u: &Vector3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    let hint = if u.x.abs() < 0.9 {
        Vector3::x()
    } else {
        Vector3::y()
    };
    let a = u.cross(&hint).normalize();
    (a, u.cross(&a))
}

/// What stays fixed: the nominal frames and the gauge's directions.
#[derive(Debug, Clone)]
pub struct Gauge {
    /// The nominal positioner base in the cell frame.
    pub cell_from_base: Pose,
    /// The nominal face plate frame in the rotate frame.
    pub face_plate: Pose,
    /// Nominal `u1`.
    pub u1: Vector3<f64>,
    /// Nominal `u2` made orthogonal to nominal `u1`, unit.
    pub e: Vector3<f64>,
    /// Reflector 0's design position and its free directions (face plate frame).
    pub reference: Vector3<f64>,
    /// Reflector 0's radial direction on the face plate (unit).
    pub radial: Vector3<f64>,
    /// The face plate's normal, the other free direction of reflector 0.
    pub along_z: Vector3<f64>,
}

impl Gauge {
    /// The gauge of `nominal` with reflector 0 designed at `reference_m` (face plate frame).
    pub fn new(nominal: &TiltRotate, reference_m: Vector3<f64>) -> Self {
        let u1 = nominal.tilt.direction;
        let u2 = nominal.rotate.direction;
        let e = (u2 - u1 * u1.dot(&u2)).normalize();
        let along_z = Vector3::z();
        let flat = Vector3::new(reference_m.x, reference_m.y, 0.0);
        let radial = if flat.norm() > 0.0 {
            flat.normalize()
        } else {
            Vector3::x()
        };
        Gauge {
            cell_from_base: nominal.cell_from_base,
            face_plate: nominal.face_plate,
            u1,
            e,
            reference: reference_m,
            radial,
            along_z,
        }
    }

    /// `u2` at out-of-plane angle `gamma`.
    pub fn u2(&self, gamma: f64) -> Vector3<f64> {
        self.e * gamma.cos() + self.u1 * gamma.sin()
    }
}

/// A point of the parameter space.
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    /// Axis 1, in the base frame.
    pub tilt: RotaryAxis,
    /// Axis 2, in the tilt frame.
    pub rotate: RotaryAxis,
    /// `u2`'s out-of-plane angle [rad].
    pub gamma: f64,
    /// Reflector 0's moves along `radial` and `along_z` [m].
    pub reference: [f64; 2],
    /// Reflectors 1.. in the face plate frame [m].
    pub others: Vec<Vector3<f64>>,
}

impl State {
    /// Reflector `k` in the face plate frame [m].
    pub fn reflector(&self, g: &Gauge, k: usize) -> Vector3<f64> {
        if k == 0 {
            g.reference + g.radial * self.reference[0] + g.along_z * self.reference[1]
        } else {
            self.others[k - 1]
        }
    }

    /// How many reflectors the state holds.
    pub fn reflectors(&self) -> usize {
        1 + self.others.len()
    }

    /// How many parameters the state has.
    pub fn parameters(&self) -> usize {
        AXIS_PARAMETERS + 2 + 3 * self.others.len()
    }

    /// The model with these axes.
    pub fn model(&self, g: &Gauge) -> TiltRotate {
        TiltRotate {
            cell_from_base: g.cell_from_base,
            tilt: self.tilt,
            rotate: self.rotate,
            face_plate: g.face_plate,
        }
    }

    /// The point `self ⊕ delta` (parameter order: module docs).
    pub fn step(&self, g: &Gauge, delta: &DVector<f64>) -> State {
        let mut s = self.clone();
        let (a1, b1) = across(&self.tilt.direction);
        let w = a1 * delta[0] + b1 * delta[1];
        let u1 = (Rotation3::new(w) * self.tilt.direction).normalize();
        s.tilt.direction = u1;
        s.tilt.point = closest_to_origin(&u1, &(self.tilt.point + a1 * delta[2] + b1 * delta[3]));
        s.tilt.zero_offset += delta[4];
        s.tilt.scale += delta[5];
        s.gamma += delta[6];
        let u2 = g.u2(s.gamma);
        let (a2, b2) = across(&self.rotate.direction);
        s.rotate.direction = u2;
        s.rotate.point =
            closest_to_origin(&u2, &(self.rotate.point + a2 * delta[7] + b2 * delta[8]));
        s.rotate.zero_offset += delta[9];
        s.rotate.scale += delta[10];
        s.reference[0] += delta[11];
        s.reference[1] += delta[12];
        for (k, p) in s.others.iter_mut().enumerate() {
            let i = AXIS_PARAMETERS + 2 + 3 * k;
            *p += Vector3::new(delta[i], delta[i + 1], delta[i + 2]);
        }
        s
    }
}

/// Readings in SI: reflector, controller values [rad], measured point [m].
#[derive(Debug, Clone)]
pub struct Row {
    /// The reflector read.
    pub reflector: usize,
    /// Controller values of axis 1 and 2 [rad].
    pub values: [f64; 2],
    /// The measured point in the cell frame [m].
    pub x: Vector3<f64>,
}

impl Row {
    /// A reading in SI.
    pub fn of(r: &PositionerReading) -> Self {
        Row {
            reflector: r.reflector,
            values: r.values_deg.map(f64::to_radians),
            x: Vector3::from(r.xyz_mm) * 1e-3,
        }
    }
}

/// Residuals `x_measured − x` of every row at `s` (3 per row) [m].
pub fn residuals(g: &Gauge, s: &State, rows: &[Row]) -> DVector<f64> {
    let m = s.model(g);
    let mut r = DVector::zeros(3 * rows.len());
    for (i, row) in rows.iter().enumerate() {
        let deg = row.values.map(f64::to_degrees);
        let x = m.point_in_cell(deg, &s.reflector(g, row.reflector));
        r.fixed_rows_mut::<3>(3 * i).copy_from(&(row.x - x));
    }
    r
}

/// `ω × (R·z) − R·(ω × z)`: the move of `R·z` when the axis turns by `ω`.
pub(crate) fn turned_axis(w: &Vector3<f64>, r: &Matrix3<f64>, z: &Vector3<f64>) -> Vector3<f64> {
    w.cross(&(r * z)) - r * w.cross(z)
}

/// The Jacobian of the predictions at `s` (module docs).
pub fn jacobian(g: &Gauge, s: &State, rows: &[Row]) -> DMatrix<f64> {
    let mut j = DMatrix::zeros(3 * rows.len(), s.parameters());
    let (a1, b1) = across(&s.tilt.direction);
    let (a2, b2) = across(&s.rotate.direction);
    let (u1, c1, u2, c2) = (
        s.tilt.direction,
        s.tilt.point,
        s.rotate.direction,
        s.rotate.point,
    );
    let t = -g.e * s.gamma.sin() + g.u1 * s.gamma.cos();
    let w_gamma = u2.cross(&t);
    let tr = g.cell_from_base.r;
    for (i, row) in rows.iter().enumerate() {
        let th1 = s.tilt.scale * row.values[0] + s.tilt.zero_offset;
        let th2 = s.rotate.scale * row.values[1] + s.rotate.zero_offset;
        let r1 = s.tilt.rotation(th1);
        let r2 = s.rotate.rotation(th2);
        let y2 = g.face_plate.transform_point(&s.reflector(g, row.reflector));
        let z2 = y2 - c2;
        let y1 = r2 * z2 + c2;
        let z1 = y1 - c1;
        let cols: Vec<(usize, Vector3<f64>)> = {
            let d_th1 = u1.cross(&(r1 * z1));
            let d_th2 = r1 * u2.cross(&(r2 * z2));
            let carry = r1 * r2 * g.face_plate.r;
            let mut c = vec![
                (0, turned_axis(&a1, &r1, &z1)),
                (1, turned_axis(&b1, &r1, &z1)),
                (2, a1 - r1 * a1),
                (3, b1 - r1 * b1),
                (4, d_th1),
                (5, d_th1 * row.values[0]),
                (6, r1 * turned_axis(&w_gamma, &r2, &z2)),
                (7, r1 * (a2 - r2 * a2)),
                (8, r1 * (b2 - r2 * b2)),
                (9, d_th2),
                (10, d_th2 * row.values[1]),
            ];
            if row.reflector == 0 {
                c.push((11, carry * g.radial));
                c.push((12, carry * g.along_z));
            } else {
                let base = AXIS_PARAMETERS + 2 + 3 * (row.reflector - 1);
                for (k, e) in [Vector3::x(), Vector3::y(), Vector3::z()]
                    .iter()
                    .enumerate()
                {
                    c.push((base + k, carry * e));
                }
            }
            c
        };
        for (col, v) in cols {
            j.fixed_view_mut::<3, 1>(3 * i, col).copy_from(&(tr * v));
        }
    }
    j
}

/// A point of an external axis fit's parameter space, what [`Problem`]
/// moves: its readings' residuals and their Jacobian at it, and the point
/// `self ⊕ delta` (the positioner's [`State`], the turntable's).
pub trait FitState: Clone {
    /// What stays fixed.
    type Gauge;
    /// One reading.
    type Row;
    /// Residuals `x_measured − x` of every row (3 per row) [m].
    fn residuals(&self, g: &Self::Gauge, rows: &[Self::Row]) -> DVector<f64>;
    /// The Jacobian of the predictions (`r(x ⊕ δ) ≈ r − J·δ`).
    fn jacobian(&self, g: &Self::Gauge, rows: &[Self::Row]) -> DMatrix<f64>;
    /// The point `self ⊕ delta`.
    fn step(&self, g: &Self::Gauge, delta: &DVector<f64>) -> Self;
}

impl FitState for State {
    type Gauge = Gauge;
    type Row = Row;
    fn residuals(&self, g: &Gauge, rows: &[Row]) -> DVector<f64> {
        residuals(g, self, rows)
    }
    fn jacobian(&self, g: &Gauge, rows: &[Row]) -> DMatrix<f64> {
        jacobian(g, self, rows)
    }
    fn step(&self, g: &Gauge, delta: &DVector<f64>) -> State {
        State::step(self, g, delta)
    }
}

/// The problem the LM driver moves: a fit's readings under its gauge, from
/// a starting point.
pub struct Problem<'a, S: FitState> {
    /// What stays fixed.
    pub gauge: &'a S::Gauge,
    /// The readings.
    pub rows: &'a [S::Row],
    /// The current point of the parameter space.
    pub state: S,
    next: Option<S>,
    r: DVector<f64>,
    j: DMatrix<f64>,
}

impl<'a, S: FitState> Problem<'a, S> {
    /// The problem of `rows` under `gauge`, started at `state`.
    pub fn new(gauge: &'a S::Gauge, rows: &'a [S::Row], state: S) -> Self {
        Problem {
            gauge,
            rows,
            state,
            next: None,
            r: DVector::zeros(0),
            j: DMatrix::zeros(0, 0),
        }
    }
}

impl<S: FitState> LeastSquaresProblem for Problem<'_, S> {
    fn cost(&self) -> f64 {
        self.state.residuals(self.gauge, self.rows).norm_squared()
    }
    fn linearise(&mut self) -> &mut DMatrix<f64> {
        self.r = self.state.residuals(self.gauge, self.rows);
        self.j = self.state.jacobian(self.gauge, self.rows);
        &mut self.j
    }
    fn residuals(&self) -> &DVector<f64> {
        &self.r
    }
    fn jacobian(&self) -> &DMatrix<f64> {
        &self.j
    }
    fn trial(&mut self, delta: &mut DVector<f64>) -> Option<f64> {
        let s = self.state.step(self.gauge, delta);
        let c = s.residuals(self.gauge, self.rows).norm_squared();
        self.next = Some(s);
        c.is_finite().then_some(c)
    }
    fn accept(&mut self) {
        if let Some(s) = self.next.take() {
            self.state = s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The analytic Jacobian equals central differences of the residuals
    /// (`J = −∂r/∂δ`) at a point away from nominal, for every column.
    #[test]
    fn jacobian_matches_finite_differences() {
        let nominal = TiltRotate {
            cell_from_base: Pose::new(
                crate::model::pose::rpy_matrix(0.02, -0.01, 0.4),
                Vector3::new(2.0, 0.5, 0.1),
            ),
            tilt: RotaryAxis::new(Vector3::x(), Vector3::new(0.0, 0.0, 0.8), 0.0, 1.0),
            rotate: RotaryAxis::new(Vector3::z(), Vector3::zeros(), 0.0, 1.0),
            face_plate: Pose::from_translation(Vector3::new(0.0, 0.0, 1.1)),
        };
        let g = Gauge::new(&nominal, Vector3::new(0.4, 0.0, 0.02));
        let s = State {
            tilt: RotaryAxis::new(
                Vector3::new(1.0, 0.002, -0.001),
                Vector3::new(0.0, 0.001, 0.8),
                0.01,
                1.0004,
            ),
            rotate: RotaryAxis::new(
                g.u2(0.003),
                Vector3::new(0.0005, -0.0003, 0.0),
                -0.02,
                0.9997,
            ),
            gamma: 0.003,
            reference: [0.0004, -0.0002],
            others: vec![Vector3::new(-0.15, 0.1, 0.02)],
        };
        let rows: Vec<Row> = [(0, 10.0, -50.0), (1, -70.0, 120.0), (0, 45.0, 170.0)]
            .iter()
            .map(|&(k, a, b)| Row {
                reflector: k,
                values: [f64::to_radians(a), f64::to_radians(b)],
                x: Vector3::new(2.1, 0.4, 1.0),
            })
            .collect();
        let j = jacobian(&g, &s, &rows);
        let h = 1e-7;
        for col in 0..s.parameters() {
            let mut d = DVector::zeros(s.parameters());
            d[col] = h;
            let rp = residuals(&g, &s.step(&g, &d), &rows);
            d[col] = -h;
            let rm = residuals(&g, &s.step(&g, &d), &rows);
            let fd = -(rp - rm) / (2.0 * h);
            let err = (fd - j.column(col)).amax();
            assert!(
                err < 1e-7,
                "column {col}: {err:e} (analytic {:?})",
                j.column(col)
            );
        }
    }
}

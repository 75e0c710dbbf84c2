//! The least-squares problem of a one-axis turntable: every reading of every
//! reflector, the axis's line, zero offset and scale and the reflectors'
//! positions on the face plate at once.
//!
//! Prediction (cell frame): `x = T·(M(θ)·F·p)`, `T` the base in the cell,
//! `M` the motion about the axis's line (`R(u, θ)(y − c) + c`), `F` the
//! nominal face plate frame, `p` the reflector in it, `θ = s·v + o`.
//! Residual `r = x_measured − x` [m]; cost `‖r‖²`.
//!
//! Parameters, as increments at the current point (retracted onto it by
//! [`State::step`]): two small rotations of `u` about `a`, `b` (an
//! orthonormal pair across `u`), two moves of its line along `a`, `b`, `o`,
//! `s`; reflector 0 (the reference) along its radius from the nominal axis
//! and along the nominal axis; the other reflectors x, y, z.
//!
//! Gauge: turning the reflectors about the axis and taking the same angle
//! off `o` changes no reading; holding reflector 0 at its design azimuth
//! about the nominal axis fixes it, so `o` is the angle at which reflector 0
//! stands on its design azimuth in the face plate frame (as axis 2's of a
//! tilt-rotate positioner, `super::super::problem`).
//!
//! Jacobian (of the prediction, `r(x ⊕ δ) ≈ r − J·δ`), with `z = F·p − c`:
//! a move `e` of the line `(I − R)·e`; a rotation `ω` of the direction
//! `ω × (R·z) − R·(ω × z)`; the angle `u × (R·z)`; a reflector's move `d`
//! `R·F.r·d`; all carried into the cell frame by `T.r`. Checked against
//! central differences in the tests. The LM driver moves it through
//! `super::super::problem::Problem` ([`FitState`]).

use super::super::problem::{across, turned_axis, FitState};
use crate::model::external::rotary::closest_to_origin;
use crate::model::external::{RotaryAxis, Turntable};
use crate::model::Pose;
use nalgebra::{DMatrix, DVector, Rotation3, Vector3};

/// Parameters before the reflectors'.
pub const AXIS_PARAMETERS: usize = 6;

/// What stays fixed: the nominal frames and the reference's free directions.
#[derive(Debug, Clone)]
pub struct Gauge {
    /// The nominal base in the cell frame.
    pub cell_from_base: Pose,
    /// The nominal face plate frame in the frame the axis carries.
    pub face_plate: Pose,
    /// Reflector 0's design position (face plate frame) [m].
    pub reference: Vector3<f64>,
    /// Its direction from the nominal axis, across it (face plate frame, unit).
    pub radial: Vector3<f64>,
    /// The nominal axis's direction in the face plate frame (unit).
    pub along: Vector3<f64>,
}

impl Gauge {
    /// The gauge of `nominal` with reflector 0 designed at `reference_m`
    /// (face plate frame).
    pub fn new(nominal: &Turntable, reference_m: Vector3<f64>) -> Self {
        let plate_from_carried = nominal.face_plate.inverse();
        let along = plate_from_carried.r * nominal.axis.direction;
        let centre = plate_from_carried.transform_point(&nominal.axis.point);
        let out = reference_m - centre;
        let across_axis = out - along * out.dot(&along);
        let radial = if across_axis.norm() > 1e-9 {
            across_axis.normalize()
        } else {
            across(&along).0
        };
        Gauge {
            cell_from_base: nominal.cell_from_base,
            face_plate: nominal.face_plate,
            reference: reference_m,
            radial,
            along,
        }
    }
}

/// A point of the parameter space.
#[derive(Debug, Clone, PartialEq)]
pub struct State {
    /// The axis, in the base frame.
    pub axis: RotaryAxis,
    /// Reflector 0's moves along `radial` and `along` [m].
    pub reference: [f64; 2],
    /// Reflectors 1.. in the face plate frame [m].
    pub others: Vec<Vector3<f64>>,
}

impl State {
    /// Reflector `k` in the face plate frame [m].
    pub fn reflector(&self, g: &Gauge, k: usize) -> Vector3<f64> {
        if k == 0 {
            g.reference + g.radial * self.reference[0] + g.along * self.reference[1]
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

    /// The model with this axis.
    pub fn model(&self, g: &Gauge) -> Turntable {
        Turntable {
            cell_from_base: g.cell_from_base,
            axis: self.axis,
            face_plate: g.face_plate,
        }
    }

    /// The point `self ⊕ delta` (parameter order: module docs).
    pub fn step(&self, delta: &DVector<f64>) -> State {
        let mut s = self.clone();
        let (a, b) = across(&self.axis.direction);
        let u = (Rotation3::new(a * delta[0] + b * delta[1]) * self.axis.direction).normalize();
        s.axis.direction = u;
        s.axis.point = closest_to_origin(&u, &(self.axis.point + a * delta[2] + b * delta[3]));
        s.axis.zero_offset += delta[4];
        s.axis.scale += delta[5];
        s.reference[0] += delta[6];
        s.reference[1] += delta[7];
        for (k, p) in s.others.iter_mut().enumerate() {
            let i = AXIS_PARAMETERS + 2 + 3 * k;
            *p += Vector3::new(delta[i], delta[i + 1], delta[i + 2]);
        }
        s
    }
}

/// A reading in SI: reflector, controller value [rad], measured point [m].
#[derive(Debug, Clone)]
pub struct Row {
    /// The reflector read.
    pub reflector: usize,
    /// The controller value [rad].
    pub value: f64,
    /// The measured point in the cell frame [m].
    pub x: Vector3<f64>,
}

/// Residuals `x_measured − x` of every row at `s` (3 per row) [m].
pub fn residuals(g: &Gauge, s: &State, rows: &[Row]) -> DVector<f64> {
    let m = s.model(g);
    let mut r = DVector::zeros(3 * rows.len());
    for (i, row) in rows.iter().enumerate() {
        let x = m.point_in_cell(row.value.to_degrees(), &s.reflector(g, row.reflector));
        r.fixed_rows_mut::<3>(3 * i).copy_from(&(row.x - x));
    }
    r
}

/// The Jacobian of the predictions at `s` (module docs).
pub fn jacobian(g: &Gauge, s: &State, rows: &[Row]) -> DMatrix<f64> {
    let mut j = DMatrix::zeros(3 * rows.len(), s.parameters());
    let (a, b) = across(&s.axis.direction);
    let (u, c) = (s.axis.direction, s.axis.point);
    let tr = g.cell_from_base.r;
    for (i, row) in rows.iter().enumerate() {
        let r = s
            .axis
            .rotation(s.axis.scale * row.value + s.axis.zero_offset);
        let z = g.face_plate.transform_point(&s.reflector(g, row.reflector)) - c;
        let d_th = u.cross(&(r * z));
        let carry = r * g.face_plate.r;
        let mut cols = vec![
            (0, turned_axis(&a, &r, &z)),
            (1, turned_axis(&b, &r, &z)),
            (2, a - r * a),
            (3, b - r * b),
            (4, d_th),
            (5, d_th * row.value),
        ];
        if row.reflector == 0 {
            cols.push((6, carry * g.radial));
            cols.push((7, carry * g.along));
        } else {
            let first = AXIS_PARAMETERS + 2 + 3 * (row.reflector - 1);
            for (k, e) in [Vector3::x(), Vector3::y(), Vector3::z()]
                .iter()
                .enumerate()
            {
                cols.push((first + k, carry * e));
            }
        }
        for (col, v) in cols {
            j.fixed_view_mut::<3, 1>(3 * i, col).copy_from(&(tr * v));
        }
    }
    j
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
    fn step(&self, _: &Gauge, delta: &DVector<f64>) -> State {
        State::step(self, delta)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The analytic Jacobian equals central differences of the residuals
    /// (`J = −∂r/∂δ`) at a point away from nominal, for every column.
    #[test]
    fn jacobian_matches_finite_differences() {
        let nominal = Turntable {
            cell_from_base: Pose::new(
                crate::model::pose::rpy_matrix(0.02, -0.01, 0.4),
                Vector3::new(2.0, 0.5, 0.1),
            ),
            axis: RotaryAxis::new(Vector3::z(), Vector3::zeros(), 0.0, 1.0),
            face_plate: Pose::from_translation(Vector3::new(0.0, 0.0, 0.9)),
        };
        let g = Gauge::new(&nominal, Vector3::new(0.4, 0.0, 0.02));
        let s = State {
            axis: RotaryAxis::new(
                Vector3::new(0.002, -0.001, 1.0),
                Vector3::new(0.0005, -0.0003, 0.0),
                -0.02,
                0.9997,
            ),
            reference: [0.0004, -0.0002],
            others: vec![Vector3::new(-0.15, 0.1, 0.02)],
        };
        let rows: Vec<Row> = [(0, -50.0), (1, 120.0), (0, 170.0)]
            .iter()
            .map(|&(k, v)| Row {
                reflector: k,
                value: f64::to_radians(v),
                x: Vector3::new(2.1, 0.4, 1.0),
            })
            .collect();
        let j = jacobian(&g, &s, &rows);
        let h = 1e-7;
        for col in 0..s.parameters() {
            let mut d = DVector::zeros(s.parameters());
            d[col] = h;
            let rp = residuals(&g, &s.step(&d), &rows);
            d[col] = -h;
            let rm = residuals(&g, &s.step(&d), &rows);
            let fd = -(rp - rm) / (2.0 * h);
            let err = (fd - j.column(col)).amax();
            assert!(err < 1e-7, "column {col}: {err:e}");
        }
    }
}

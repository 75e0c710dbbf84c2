//! A pose as each controller language writes it: mm and degrees to 6 and 9
//! decimals (KRL), mm and a quaternion (RAPID), m and a rotation vector
//! (URScript), so a pose reads back to better than 1e-6 mm.

use crate::model::orientation::{rotation_to, OrientationConvention};
use crate::model::Pose;

/// A KRL `FRAME` aggregate: mm, `A, B, C` with `R = Rz(A)·Ry(B)·Rx(C)`.
pub(crate) fn kuka_frame(p: &Pose) -> String {
    let abc = rotation_to(OrientationConvention::KukaAbc, &p.r);
    format!(
        "{{X {:.6},Y {:.6},Z {:.6},A {:.9},B {:.9},C {:.9}}}",
        p.p.x * 1e3,
        p.p.y * 1e3,
        p.p.z * 1e3,
        abc[0],
        abc[1],
        abc[2]
    )
}

/// A RAPID `pose`: mm and a quaternion, scalar first.
pub(crate) fn abb_frame(p: &Pose) -> String {
    let q = rotation_to(OrientationConvention::AbbQ1q4, &p.r);
    format!(
        "[[{:.6},{:.6},{:.6}],[{:.12},{:.12},{:.12},{:.12}]]",
        p.p.x * 1e3,
        p.p.y * 1e3,
        p.p.z * 1e3,
        q[0],
        q[1],
        q[2],
        q[3]
    )
}

/// A URScript pose: m and a rotation vector in rad.
pub(crate) fn ur_pose(p: &Pose) -> String {
    let r = rotation_to(OrientationConvention::UrRotvec, &p.r);
    format!(
        "p[{:.9}, {:.9}, {:.9}, {:.12}, {:.12}, {:.12}]",
        p.p.x, p.p.y, p.p.z, r[0], r[1], r[2]
    )
}

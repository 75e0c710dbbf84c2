#!/usr/bin/env python3
"""Generate golden forward-kinematics values for robocal's Rust tests.

Primary oracle : roboticstoolbox-python (DHRobot + RevoluteDH / RevoluteMDH,
                 robot.tool = SE3(...)), fed in METRES, converted to mm here.
Cross-checks   : (1) pybotics (MDH-only library; a standard-DH chain is
                     re-expressed as an MDH chain, see `pybotics_fk`), in mm;
                 (2) a plain numpy chain written straight from the convention
                     strings below, in mm.
Every sample must agree across all three to 1e-9 (mm for translation,
unitless for rotation), otherwise the script aborts without writing.

Output: core/tests/golden/fk_<name>.json (mm, degrees). See scripts/golden/README.md.
This file is a record of how the golden values were made; it is not part of
the Rust build.
"""
from __future__ import annotations

import json
import sys
from importlib.metadata import version
from pathlib import Path

import numpy as np
import roboticstoolbox as rtb
from spatialmath import SE3

import pybotics
from pybotics.kinematic_chain import MDHKinematicChain
from pybotics.robot import Robot as PbRobot
from pybotics.tool import Tool as PbTool

TOL = 1e-9
N_RANDOM = 29  # plus q = 0 first -> 30 samples
Q_LIM_DEG = 170.0
Q_DECIMALS = 6  # q is rounded so the JSON value is exactly what was evaluated
BASE_SEED = 20240601

CONV_DH = "standard DH: Rz(theta)Tz(d)Tx(a)Rx(alpha)"
CONV_MDH = "modified DH (Craig): Rx(alpha_{i-1})Tx(a_{i-1})Rz(theta_i)Tz(d_i)"
TOOL_CONV = (
    "T = (product of link transforms, joint 1 first) * T_tool; "
    "T_tool = transl(xyz_mm) * Rz(rz) * Ry(ry) * Rx(rx) with rpy_deg = [rx, ry, rz] "
    "(rotations about fixed/base axes X then Y then Z, i.e. intrinsic Z-Y'-X''); "
    "tool is post-multiplied after the last link frame; base = identity"
)
THETA_CONV = "theta = q + theta_offset (q in degrees, as stored)"

# dh rows: (a_mm, alpha_deg, d_mm, theta_offset_deg)
# For MDH, a_mm / alpha_deg in row i are a_{i-1} / alpha_{i-1} (Craig).
ROBOTS = [
    dict(
        name="ur5",
        mdh=False,
        dh=[
            (0.0, 90.0, 89.159, 0.0),
            (-425.0, 0.0, 0.0, 0.0),
            (-392.25, 0.0, 0.0, 0.0),
            (0.0, 90.0, 109.15, 0.0),
            (0.0, -90.0, 94.65, 0.0),
            (0.0, 0.0, 82.3, 0.0),
        ],
        tool_xyz=(0.0, 0.09, 31.0),
        tool_rpy=(0.0, 0.0, 0.0),
    ),
    dict(
        name="ur10",
        mdh=False,
        dh=[
            (0.0, 90.0, 127.3, 0.0),
            (-612.0, 0.0, 0.0, 0.0),
            (-572.3, 0.0, 0.0, 0.0),
            (0.0, 90.0, 163.941, 0.0),
            (0.0, -90.0, 115.7, 0.0),
            (0.0, 0.0, 92.2, 0.0),
        ],
        tool_xyz=(10.0, -20.0, 50.0),
        tool_rpy=(5.0, -10.0, 15.0),
    ),
    dict(
        name="wam7",
        mdh=False,
        dh=[
            (0.0, -90.0, 0.0, 0.0),
            (0.0, 90.0, 0.0, 0.0),
            (45.0, -90.0, 550.0, 0.0),
            (-45.0, 90.0, 0.0, 0.0),
            (0.0, -90.0, 300.0, 0.0),
            (0.0, 90.0, 0.0, 0.0),
            (0.0, 0.0, 60.0, 0.0),
        ],
        tool_xyz=(0.0, 0.0, 44.0),
        tool_rpy=(0.0, 0.0, 0.0),
    ),
    dict(
        name="ys100_mdh",
        mdh=True,
        # given as (alpha_{i-1}, a_{i-1}, d_i, offset_i); stored as (a, alpha, d, off)
        dh=[
            (0.0, 0.0, 480.0, 0.0),
            (320.0, 90.0, 0.0, 90.0),
            (870.0, 0.0, 0.0, 0.0),
            (200.0, 90.0, 1030.0, 0.0),
            (0.0, -90.0, 0.0, 0.0),
            (0.0, 90.0, 185.0, 0.0),
        ],
        tool_xyz=(200.0, 50.0, 500.0),
        tool_rpy=(10.0, 20.0, 30.0),
    ),
]


# ---------------------------------------------------------------- helpers
def rx(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def ry(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, 0, s, 0], [0, 1, 0, 0], [-s, 0, c, 0], [0, 0, 0, 1.0]])


def rz(t):
    c, s = np.cos(t), np.sin(t)
    return np.array([[c, -s, 0, 0], [s, c, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1.0]])


def tr(x, y, z):
    m = np.eye(4)
    m[:3, 3] = (x, y, z)
    return m


def tool_matrix_np(xyz_mm, rpy_deg):
    r, p, y = np.deg2rad(rpy_deg)
    return tr(*xyz_mm) @ rz(y) @ ry(p) @ rx(r)


# ---------------------------------------------------------------- oracle 1: rtb
def rtb_robot(spec):
    links = []
    for a, alpha, d, off in spec["dh"]:
        kw = dict(a=a / 1000.0, alpha=np.deg2rad(alpha), d=d / 1000.0, offset=np.deg2rad(off))
        links.append(rtb.RevoluteMDH(**kw) if spec["mdh"] else rtb.RevoluteDH(**kw))
    robot = rtb.DHRobot(links, name=spec["name"])
    xyz_m = np.asarray(spec["tool_xyz"]) / 1000.0
    rpy = spec["tool_rpy"]
    # Built from elementary rotations so the composition order is explicit.
    robot.tool = SE3.Trans(*xyz_m) * SE3.Rz(rpy[2], unit="deg") * SE3.Ry(rpy[1], unit="deg") * SE3.Rx(rpy[0], unit="deg")
    # Sanity: spatialmath's RPY (default order 'zyx') is the same thing.
    alt = SE3.Trans(*xyz_m) * SE3.RPY(rpy, unit="deg", order="zyx")
    assert np.allclose(robot.tool.A, alt.A, atol=1e-15, rtol=0), "SE3.RPY mismatch"
    assert robot.mdh == (1 if spec["mdh"] else 0)
    return robot


def rtb_fk_mm(robot, q_deg):
    T = np.array(robot.fkine(np.deg2rad(q_deg)).A, dtype=float)
    T[:3, 3] *= 1000.0
    return T


# ---------------------------------------------------------------- oracle 2: numpy chain
def numpy_fk_mm(spec, q_deg):
    T = np.eye(4)
    for (a, alpha, d, off), q in zip(spec["dh"], q_deg):
        th = np.deg2rad(q + off)
        al = np.deg2rad(alpha)
        if spec["mdh"]:
            T = T @ rx(al) @ tr(a, 0, 0) @ rz(th) @ tr(0, 0, d)
        else:
            T = T @ rz(th) @ tr(0, 0, d) @ tr(a, 0, 0) @ rx(al)
    return T @ tool_matrix_np(spec["tool_xyz"], spec["tool_rpy"])


# ---------------------------------------------------------------- oracle 3: pybotics
def pybotics_robot(spec):
    """pybotics only has MDH links: MDHLink(alpha, a, theta, d) = Rx Tx Rz Tz.

    A standard-DH chain prod_i Rz(th_i)Tz(d_i)Tx(a_i)Rx(al_i) regroups exactly
    (Tx and Rx commute) into MDH links (al_{i-1}, a_{i-1}, th_i, d_i) with
    al_0 = a_0 = 0, followed by a trailing Tx(a_n)Rx(al_n) that is folded into
    the pybotics tool matrix.
    """
    dh = spec["dh"]
    rows = []
    if spec["mdh"]:
        for a, alpha, d, off in dh:
            rows.append([np.deg2rad(alpha), a, np.deg2rad(off), d])
        pre_tool = np.eye(4)
    else:
        prev_a, prev_alpha = 0.0, 0.0
        for a, alpha, d, off in dh:
            rows.append([np.deg2rad(prev_alpha), prev_a, np.deg2rad(off), d])
            prev_a, prev_alpha = a, alpha
        pre_tool = rx(np.deg2rad(prev_alpha)) @ tr(prev_a, 0, 0)
    chain = MDHKinematicChain(np.array(rows, dtype=float))
    r, p, y = np.deg2rad(spec["tool_rpy"])
    # pybotics' own ZYX euler builder: transl * Rz * Ry * Rx
    tool = pybotics.geometry.vector_2_matrix([*spec["tool_xyz"], y, p, r], "zyx")
    robot = PbRobot(chain, tool=PbTool(matrix=pre_tool @ tool))
    return robot


def pybotics_fk_mm(robot, q_deg):
    return np.asarray(robot.fk(np.deg2rad(q_deg)), dtype=float)


# ---------------------------------------------------------------- main
def clean(x):
    x = float(x)
    return 0.0 if x == 0.0 else x  # no "-0.0" in the JSON


def main():
    repo = Path(__file__).resolve().parents[2]
    outdir = repo / "core" / "tests" / "golden"
    v_rtb = version("roboticstoolbox-python")
    v_pb = version("pybotics")
    v_sm = version("spatialmath-python")
    v_np = version("numpy")
    source = f"roboticstoolbox-python {v_rtb} (cross-checked with pybotics {v_pb})"

    outputs = {}
    for idx, spec in enumerate(ROBOTS):
        n = len(spec["dh"])
        seed = BASE_SEED + idx
        rng = np.random.default_rng(seed)
        qs = [np.zeros(n)]
        qs += [np.round(rng.uniform(-Q_LIM_DEG, Q_LIM_DEG, n), Q_DECIMALS) for _ in range(N_RANDOM)]

        robot = rtb_robot(spec)
        pbr = pybotics_robot(spec)
        samples = []
        worst = 0.0
        for q in qs:
            T = rtb_fk_mm(robot, q)
            T_np = numpy_fk_mm(spec, q)
            T_pb = pybotics_fk_mm(pbr, q)
            for other, lbl in ((T_np, "numpy chain"), (T_pb, "pybotics")):
                err = np.max(np.abs(T - other))
                worst = max(worst, err)
                if not err <= TOL:
                    sys.exit(f"FAIL {spec['name']} q={q.tolist()}: rtb vs {lbl} differ by {err:.3e}\n{T}\n{other}")
            # orthonormality sanity
            R = T[:3, :3]
            if np.max(np.abs(R @ R.T - np.eye(3))) > 1e-12 or abs(np.linalg.det(R) - 1) > 1e-12:
                sys.exit(f"FAIL {spec['name']}: non-orthonormal rotation")
            samples.append(
                {
                    "q_deg": [clean(v) for v in q],
                    "T": [[clean(v) for v in row] for row in T[:3]] + [[0.0, 0.0, 0.0, 1.0]],
                }
            )
        print(f"{spec['name']}: {len(samples)} samples, max |rtb - cross-check| = {worst:.2e}")

        doc = {
            "source": source,
            "generated_by": "scripts/golden/make_fk_golden.py",
            "versions": {
                "roboticstoolbox-python": v_rtb,
                "pybotics": v_pb,
                "spatialmath-python": v_sm,
                "numpy": v_np,
            },
            "units": "lengths in mm, angles in degrees",
            "convention": CONV_MDH if spec["mdh"] else CONV_DH,
            "theta_convention": THETA_CONV,
            "tool_convention": TOOL_CONV,
            "tolerance_cross_check": TOL,
            "seed": seed,
            "sampling": f"sample 0: q = 0; then {N_RANDOM} x numpy.random.default_rng(seed).uniform(-{Q_LIM_DEG:g}, {Q_LIM_DEG:g}, n) rounded to {Q_DECIMALS} decimals",
            "dh": [
                {"a_mm": clean(a), "alpha_deg": clean(al), "d_mm": clean(d), "theta_offset_deg": clean(o)}
                for a, al, d, o in spec["dh"]
            ],
            "tool": {"xyz_mm": [clean(v) for v in spec["tool_xyz"]], "rpy_deg": [clean(v) for v in spec["tool_rpy"]]},
            "samples": samples,
        }
        if spec["mdh"]:
            doc["dh_note"] = "row i holds alpha_{i-1}, a_{i-1} (previous-axis common normal), d_i, theta_offset_i"
        outputs[outdir / f"fk_{spec['name']}.json"] = doc

    outdir.mkdir(parents=True, exist_ok=True)
    for path, doc in outputs.items():
        path.write_text(json.dumps(doc, indent=1) + "\n")
        print(f"wrote {path.relative_to(repo)}")


if __name__ == "__main__":
    main()

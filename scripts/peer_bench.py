"""Peer benchmark: robocal against Python references on the same data.

    scripts/peer_bench.sh                 (one command: venv, release build, this script)
    python scripts/peer_bench.py --robocal target/release/robocal

KM (kinematic calibration, least squares on all geometric parameters) on the
real UR5 laser-tracker grid (1000 poses), validated on its 20 random poses:
  - reference A: pybotics' kinematic chain (the UR5's standard DH regrouped
    into pybotics' modified DH exactly), fitted with scipy.optimize
    least_squares (LM); forward kinematics pose by pose, as pybotics does;
  - reference B: the same model with vectorised numpy forward kinematics and
    scipy least_squares (LM) — the fastest plain-Python reference;
  - robocal: `robocal bench km` (registration, identifiability, KM).
Accuracy is the mean position error on the 20 validation poses; time is the
median wall time of a whole fit.

IK on the nominal UR5 (robocal's preset geometry), 1000 poses of random joint
configurations: roboticstoolbox-python's C++ `ik_LM` called on a prebuilt ETS
(`robot.ets().ik_LM`), against `robocal bench ik`, both at the same tolerance
(position 1e-4 mm, orientation 1e-7 rad). Every solution of both solvers is
checked with roboticstoolbox's forward kinematics.

Times run on one core if the caller pins the process (`taskset -c 0`).
Prints a table of ratios and writes target/peer-bench.json.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

import numpy as np
from scipy.optimize import least_squares

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)
DATA = os.path.join(ROOT, "..", "shared", "data", "ur5-wam-laser-tracker", "UR5")

# UR5 standard DH (mm, deg), as robocal's `ur5` preset and the data's README.
A = np.array([0.0, -425.0, -392.25, 0.0, 0.0, 0.0])
D = np.array([89.159, 0.0, 0.0, 109.15, 94.65, 82.3])
ALPHA = np.radians([90.0, 0.0, 0.0, 90.0, -90.0, 0.0])


def load(path):
    """Joints (rad) and measured positions (mm; measured = target + dif)."""
    raw = np.genfromtxt(path, delimiter=",", names=True)
    q = np.radians(np.stack([raw[f"joint_{i}"] for i in range(1, 7)], axis=1))
    p = np.stack([raw[c + "_t"] + raw[c + "_dif"] for c in "xyz"], axis=1)
    return q, p


# ---------------------------------------------------------------- vectorised

def fk_std(q, a, d, alpha, theta, tool):
    """Positions (N×3, mm) of the standard DH chain with a tool offset."""
    n = q.shape[0]
    T = np.broadcast_to(np.eye(4), (n, 4, 4)).copy()
    for i in range(6):
        th = q[:, i] + theta[i]
        ct, st = np.cos(th), np.sin(th)
        ca, sa = np.cos(alpha[i]), np.sin(alpha[i])
        L = np.zeros((n, 4, 4))
        L[:, 0, 0], L[:, 0, 1], L[:, 0, 2], L[:, 0, 3] = ct, -st * ca, st * sa, a[i] * ct
        L[:, 1, 0], L[:, 1, 1], L[:, 1, 2], L[:, 1, 3] = st, ct * ca, -ct * sa, a[i] * st
        L[:, 2, 1], L[:, 2, 2], L[:, 2, 3] = sa, ca, d[i]
        L[:, 3, 3] = 1.0
        T = T @ L
    return (T[:, :3, :3] @ tool + T[:, :3, 3])


def unpack(x):
    da, dd, dal, dth = x[0:6], x[6:12], x[12:18], x[18:24]
    tool = x[24:27]
    base_t, base_r = x[27:30], x[30:33]
    return A + da, D + dd, ALPHA + dal, dth, tool, base_t, base_r


def rot(r):
    from scipy.spatial.transform import Rotation
    return Rotation.from_rotvec(r).as_matrix()


def residual_vec(x, q, p):
    a, d, al, th, tool, bt, br = unpack(x)
    pred = fk_std(q, a, d, al, th, tool) @ rot(br).T + bt
    return (pred - p).ravel()


def x0():
    x = np.zeros(33)
    x[24:27] = [0.0, 0.0, 31.0]  # nominal TCP offset of the data (README)
    return x


def fit_vectorised(q, p):
    return least_squares(residual_vec, x0(), args=(q, p), method="lm", x_scale="jac").x


# ----------------------------------------------------------------- pybotics

def pybotics_robot():
    from pybotics.kinematic_chain import MDHKinematicChain
    from pybotics.robot import Robot
    from pybotics.tool import Tool
    # Standard DH regrouped exactly: Tx(a)Rx(alpha) = Rx(alpha)Tx(a), so MDH row i
    # takes (alpha_{i-1}, a_{i-1}) of standard row i-1 and (theta_i, d_i).
    rows = []
    for i in range(6):
        al, a = (ALPHA[i - 1], A[i - 1]) if i > 0 else (0.0, 0.0)
        rows.append([al, a, 0.0, D[i]])
    robot = Robot(MDHKinematicChain(np.array(rows)), tool=Tool())
    robot.joint_limits = np.array([[-2 * np.pi] * 6, [2 * np.pi] * 6])
    return robot


def fit_pybotics(q, p):
    robot = pybotics_robot()
    nominal = robot.kinematic_chain.vector.copy()
    # Parameters: 24 MDH values, tool position, base translation and rotation.

    def residual(x):
        robot.kinematic_chain.vector = nominal + x[:24]
        robot.tool.position = x[24:27]
        R, t = rot(x[30:33]), x[27:30]
        pred = np.array([robot.fk(qi)[:3, 3] for qi in q])
        return (pred @ R.T + t - p).ravel()

    x = np.zeros(33)
    x[24:27] = [0.0, 0.0, 31.0]
    res = least_squares(residual, x, method="lm", x_scale="jac")

    def predict(qs):
        robot.kinematic_chain.vector = nominal + res.x[:24]
        robot.tool.position = res.x[24:27]
        R, t = rot(res.x[30:33]), res.x[27:30]
        return np.array([robot.fk(qi)[:3, 3] for qi in qs]) @ R.T + t

    return predict


def timed(f, repeat):
    times, out = [], None
    for _ in range(repeat):
        t = time.perf_counter()
        out = f()
        times.append(time.perf_counter() - t)
    return out, float(np.median(times))


def km_bench(robocal, repeat):
    grid = os.path.join(DATA, "3D_UR5_uncalibrated_grid_cleaned.csv")
    rand = os.path.join(DATA, "3D_UR5_uncalibrated_random_cleaned.csv")
    qi, pi = load(grid)
    qv, pv = load(rand)
    out = {}
    x, t = timed(lambda: fit_vectorised(qi, pi), repeat)
    err = np.linalg.norm(residual_vec(x, qv, pv).reshape(-1, 3), axis=1)
    out["scipy_vectorised"] = {"validation_mean_mm": float(err.mean()), "time_s": t}
    predict, t = timed(lambda: fit_pybotics(qi, pi), 1)
    err = np.linalg.norm(predict(qv) - pv, axis=1)
    out["pybotics_scipy"] = {"validation_mean_mm": float(err.mean()), "time_s": t}
    r = json.loads(subprocess.check_output([
        robocal, "bench", "km", "--model", "ur5", "--identify", grid, "--validate", rand,
        "--repeat", str(max(repeat, 10))]))
    out["robocal"] = {"validation_mean_mm": r["validation_mean_mm"], "time_s": r["time_ms_median"] / 1e3,
                      "converged": r["converged"]}
    return out


def ik_bench(robocal, n, seed):
    import roboticstoolbox as rtb
    from spatialmath import SE3
    links = [rtb.RevoluteDH(d=D[i] / 1e3, a=A[i] / 1e3, alpha=ALPHA[i]) for i in range(6)]
    robot = rtb.DHRobot(links, name="ur5-preset")
    ets = robot.ets()
    rng = np.random.default_rng(seed)
    qs = rng.uniform(-np.pi, np.pi, size=(n, 6))
    Ts = [ets.eval(q) for q in qs]
    tmp = tempfile.mkdtemp()
    targets = os.path.join(tmp, "targets.csv")
    with open(targets, "w") as f:
        f.write("x,y,z,qw,qx,qy,qz\n")
        for T in Ts:
            qwxyz = SE3(T, check=False).UnitQuaternion().vec
            f.write(",".join(f"{v:.17g}" for v in [*(T[:3, 3] * 1e3), *qwxyz]) + "\n")
    tol_mm, tol_rad = 1e-4, 1e-7
    # ik_LM's tol bounds E = 0.5 eᵀe (e in m and rad); this E is met when the
    # position error is tol_mm and the rotation error tol_rad.
    tol = 0.5 * ((tol_mm * 1e-3) ** 2 + tol_rad ** 2)

    def check(q, T):
        Tq = ets.eval(q)
        dp = np.linalg.norm(Tq[:3, 3] - T[:3, 3]) * 1e3
        c = (np.trace(Tq[:3, :3].T @ T[:3, :3]) - 1) / 2
        return dp, float(np.arccos(np.clip(c, -1, 1)))

    # Initial guesses drawn from a seeded generator (ik_LM draws its own
    # random restarts after the first search).
    q0s = rng.uniform(-np.pi, np.pi, size=(n, 6))
    for T, q0 in zip(Ts[:20], q0s):  # warm-up
        ets.ik_LM(T, q0=q0, tol=tol)
    t = time.perf_counter()
    sols = [ets.ik_LM(T, q0=q0, tol=tol, ilimit=100, slimit=100) for T, q0 in zip(Ts, q0s)]
    rtb_us = (time.perf_counter() - t) / n * 1e6
    ok = [check(s[0], T) for s, T in zip(sols, Ts) if s[1]]
    rtb = {"solve_rate": len(ok) / n, "time_us_mean": rtb_us,
           "max_position_error_mm": max(o[0] for o in ok), "max_orientation_error_rad": max(o[1] for o in ok)}
    joints = os.path.join(tmp, "joints.csv")
    r = json.loads(subprocess.check_output([
        robocal, "bench", "ik", "--model", "ur5", "--targets", targets, "--repeat", "5",
        "--position-tolerance-mm", str(tol_mm), "--orientation-tolerance-rad", str(tol_rad),
        "--joints-out", joints]))
    ours = []
    for line, T in zip(open(joints), Ts):
        v = [float(x) for x in line.split(",")]
        if v[0] == 1:
            ours.append(check(np.array(v[1:]), T))
    robo = {"solve_rate": r["solve_rate"], "time_us_mean": r["time_us_mean"], "time_us_median": r["time_us_median"],
            "max_position_error_mm": max(o[0] for o in ours), "max_orientation_error_rad": max(o[1] for o in ours)}
    return {"targets": n, "tolerance": {"position_mm": tol_mm, "orientation_rad": tol_rad},
            "roboticstoolbox_ik_LM": rtb, "robocal": robo}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--robocal", default=os.path.join(ROOT, "target", "release", "robocal"))
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--ik-targets", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--only", choices=["km", "ik"], help="run one half only")
    a = ap.parse_args()
    out = {}
    if a.only != "ik":
        km = out["km"] = km_bench(a.robocal, a.repeat)
        r = km["robocal"]
        print("KM on the real UR5 grid (1000 poses), validated on 20 random poses")
        print(f"{'':24}{'val. mean mm':>14}{'time':>12}{'robocal faster':>16}{'accuracy ratio':>16}")
        for name in ("pybotics_scipy", "scipy_vectorised", "robocal"):
            v = km[name]
            print(f"{name:24}{v['validation_mean_mm']:14.4f}{v['time_s'] * 1e3:10.1f}ms"
                  f"{v['time_s'] / r['time_s']:15.0f}x{v['validation_mean_mm'] / r['validation_mean_mm']:16.4f}",
                  flush=True)
    if a.only == "km":
        return write(out)
    ik = out["ik"] = ik_bench(a.robocal, a.ik_targets, a.seed)
    print(f"\nIK on the nominal UR5, {ik['targets']} random poses, tolerance 1e-4 mm / 1e-7 rad")
    print(f"{'':24}{'solve rate':>12}{'max pos mm':>12}{'max rot rad':>13}{'mean time':>12}")
    for name in ("roboticstoolbox_ik_LM", "robocal"):
        v = ik[name]
        print(f"{name:24}{v['solve_rate']:12.3f}{v['max_position_error_mm']:12.2e}"
              f"{v['max_orientation_error_rad']:13.2e}{v['time_us_mean']:10.2f}us")
    ratio = ik["roboticstoolbox_ik_LM"]["time_us_mean"] / ik["robocal"]["time_us_mean"]
    print(f"robocal IK is {ratio:.1f}x the C++ ik_LM in-process (mean time per target)")
    out["ik_speed_ratio"] = ratio
    return write(out)


def write(out):
    path = os.path.join(ROOT, "target", f"peer-bench.json")
    with open(path, "w") as f:
        json.dump(out, f, indent=2)
    print(f"\nwritten {path}")


if __name__ == "__main__":
    sys.exit(main())

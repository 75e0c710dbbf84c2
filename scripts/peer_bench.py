"""Peer benchmark: robocal against Python references on the same data.

    scripts/peer_bench.sh                 (one command: venv, release build, this script)
    python scripts/peer_bench.py --robocal target/release/robocal

KM (kinematic calibration, least squares on the identifiable geometric
parameters) on the real UR5 laser-tracker grid (1000 poses), validated on its
20 random poses:
  - reference: the UR5's standard DH with vectorised numpy forward kinematics,
    fitted with scipy.optimize.least_squares (LM) on 25 parameters: a, alpha,
    theta offset of joints 1-5, d of joints 4 and 5, the tool position, and the
    base frame's translation and tilt (rotations about x and y) — d1, d2, d3,
    a6, alpha6, d6, theta6 and the base's rotation about z depend on these;
  - robocal: `robocal bench km` (registration, identifiability by SVD, KM).
Accuracy is the mean position error on the 20 validation poses; time is the
median wall time of a whole fit: over --repeat runs for scipy (default 3, a
fit takes seconds), over at least 30 for robocal (a fit takes milliseconds,
and a median of few runs moves with the machine's noise).

IK on the nominal UR5 (robocal's preset geometry), 1000 poses of random joint
configurations: roboticstoolbox-python's C++ `ik_LM` called on a prebuilt ETS
(`robot.ets().ik_LM`), against `robocal bench ik`, both at the same tolerance
(position 1e-4 mm, orientation 1e-7 rad). Every solution of both solvers is
checked with roboticstoolbox's forward kinematics.

KM on a simulated YS100 (the thesis's §7.4 robot: Table 7.1 geometric errors,
Table 7.2 compliance, 110 kg payload, 0.01 mm noise, tracker frame 2.5 m
away), 50 identification and 30 validation poses from `robocal simulate`:
  - reference: the YS100's modified DH (Craig, as `robocal export --format
    mdh-csv` prints it) with vectorised numpy forward kinematics, fitted with
    scipy.optimize.least_squares (LM) on the geometric parameters that are not
    exactly redundant: a, alpha, d, theta offset of joints 2-5 (d2 dropped:
    axes 2 and 3 are parallel, Hayati's beta of joint 3 instead), a, alpha of
    joint 6, the tool position and the base frame's full pose (it absorbs
    joint 1's parameters; d6 and theta6 fold into the tool);
  - robocal: `robocal bench km`.
Neither models compliance here (KM), so both carry the same gravity error.

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
DATA = os.path.join(ROOT, "data", "ur5-wam-laser-tracker", "UR5")

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


# Free parameters (indices into a, d, alpha, theta offset: 6 each) and the tool.
FREE_A, FREE_D, FREE_AL, FREE_TH = [0, 1, 2, 3, 4], [3, 4], [0, 1, 2, 3, 4], [0, 1, 2, 3, 4]
N_CHAIN = len(FREE_A) + len(FREE_D) + len(FREE_AL) + len(FREE_TH) + 3
N_FREE = N_CHAIN + 5  # + base translation (3) and tilt about x, y (2)


def unpack(x):
    a, d, al, th = A.copy(), D.copy(), ALPHA.copy(), np.zeros(6)
    k = 0
    for arr, idx in ((a, FREE_A), (d, FREE_D), (al, FREE_AL), (th, FREE_TH)):
        arr[idx] += x[k:k + len(idx)]
        k += len(idx)
    return a, d, al, th, x[k:k + 3]


def residual_vec(x, q, p):
    from scipy.spatial.transform import Rotation
    a, d, al, th, tool = unpack(x)
    base_r = Rotation.from_rotvec([x[N_CHAIN + 3], x[N_CHAIN + 4], 0.0]).as_matrix()
    return (fk_std(q, a, d, al, th, tool) @ base_r.T + x[N_CHAIN:N_CHAIN + 3] - p).ravel()


def x0():
    x = np.zeros(N_FREE)
    x[N_CHAIN - 3:N_CHAIN] = [0.0, 0.0, 31.0]  # nominal TCP offset of the data (README)
    return x


def fit_vectorised(q, p):
    return least_squares(residual_vec, x0(), args=(q, p), method="lm", x_scale="jac").x


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
    out["scipy_least_squares"] = {"validation_mean_mm": float(err.mean()), "time_s": t}
    r = json.loads(subprocess.check_output([
        robocal, "bench", "km", "--model", "ur5", "--identify", grid, "--validate", rand,
        "--repeat", str(max(repeat, 30))]))
    out["robocal"] = {"validation_mean_mm": r["validation_mean_mm"], "time_s": r["time_ms_median"] / 1e3,
                      "converged": r["converged"]}
    return out


# YS100 modified DH (mm, deg) as `robocal export --model ys100 --format mdh-csv`.
YS_A = np.array([0.0, 320.0, 870.0, 200.0, 0.0, 0.0])
YS_ALPHA = np.radians([0.0, 90.0, 0.0, 90.0, -90.0, 90.0])
YS_D = np.array([0.0, 0.0, 0.0, 1030.0, 0.0, 185.0])
YS_BASE_Z = 480.0
YS_TOOL = np.array([200.0, 50.0, 500.0])
# Free: a, alpha of joints 2-6; d of joints 3-5; theta of joints 2-5; beta 3.
YS_FREE_A, YS_FREE_AL = [1, 2, 3, 4, 5], [1, 2, 3, 4, 5]
YS_FREE_D, YS_FREE_TH = [2, 3, 4], [1, 2, 3, 4]
YS_N_CHAIN = len(YS_FREE_A) + len(YS_FREE_AL) + len(YS_FREE_D) + len(YS_FREE_TH) + 1 + 3


def fk_mdh(q, a, alpha, d, theta, beta, tool):
    """Positions (N×3, mm) of the modified DH chain Rx(α)·Tx(a)·Ry(β)·Tz(d)·Rz(θ)."""
    n = q.shape[0]
    T = np.broadcast_to(np.eye(4), (n, 4, 4)).copy()
    for i in range(6):
        ca, sa = np.cos(alpha[i]), np.sin(alpha[i])
        cb, sb = np.cos(beta[i]), np.sin(beta[i])
        X = np.array([[1, 0, 0, a[i]], [0, ca, -sa, 0], [0, sa, ca, 0], [0, 0, 0, 1.0]])
        B = np.array([[cb, 0, sb, 0], [0, 1, 0, 0], [-sb, 0, cb, 0], [0, 0, 0, 1.0]])
        fixed = X @ B
        fixed[:3, 3] += fixed[:3, 2] * d[i]
        th = q[:, i] + theta[i]
        ct, st = np.cos(th), np.sin(th)
        Z = np.zeros((n, 4, 4))
        Z[:, 0, 0], Z[:, 0, 1], Z[:, 1, 0], Z[:, 1, 1] = ct, -st, st, ct
        Z[:, 2, 2], Z[:, 3, 3] = 1.0, 1.0
        T = T @ (fixed @ Z)
    return T[:, :3, :3] @ tool + T[:, :3, 3]


def ys_residual(x, q, p):
    from scipy.spatial.transform import Rotation
    a, al, d, th, beta = YS_A.copy(), YS_ALPHA.copy(), YS_D.copy(), np.zeros(6), np.zeros(6)
    k = 0
    for arr, idx in ((a, YS_FREE_A), (al, YS_FREE_AL), (d, YS_FREE_D), (th, YS_FREE_TH)):
        arr[idx] += x[k:k + len(idx)]
        k += len(idx)
    beta[2] = x[k]
    tool = YS_TOOL + x[k + 1:k + 4]
    base_r = Rotation.from_rotvec(x[YS_N_CHAIN + 3:YS_N_CHAIN + 6]).as_matrix()
    base_t = np.array([0.0, 0.0, YS_BASE_Z]) + x[YS_N_CHAIN:YS_N_CHAIN + 3]
    return (fk_mdh(q, a, al, d, th, beta, tool) @ base_r.T + base_t - p).ravel()


def load_canonical(path):
    """Joints (rad) and positions (mm) of a canonical measurement CSV."""
    with open(path) as f:
        lines = [l for l in f if l.strip() and not l.lstrip().startswith("#")]
    raw = np.genfromtxt(lines, delimiter=",", names=True)
    q = np.radians(np.stack([raw[f"q{i}"] for i in range(1, 7)], axis=1))
    return q, np.stack([raw[c] for c in "xyz"], axis=1)


def fit_ys(q, p):
    """KM on the tracker data: the base frame starts from a closed-form
    (Kabsch) registration of the nominal positions, as a tracker user would."""
    nominal = ys_residual(np.zeros(YS_N_CHAIN + 6), q, np.zeros_like(p)).reshape(-1, 3)
    cn, cp = nominal.mean(axis=0), p.mean(axis=0)
    u, _, vt = np.linalg.svd((nominal - cn).T @ (p - cp))
    dsign = np.sign(np.linalg.det(vt.T @ u.T))
    r = vt.T @ np.diag([1.0, 1.0, dsign]) @ u.T
    from scipy.spatial.transform import Rotation
    x0 = np.zeros(YS_N_CHAIN + 6)
    x0[YS_N_CHAIN + 3:] = Rotation.from_matrix(r).as_rotvec()
    # p ≈ R·(fk + base_z) + t: the base translation in the fitted form.
    x0[YS_N_CHAIN:YS_N_CHAIN + 3] = cp - r @ cn + r @ np.array([0.0, 0.0, YS_BASE_Z]) - np.array([0.0, 0.0, YS_BASE_Z])
    return least_squares(ys_residual, x0, args=(q, p), method="lm", x_scale="jac").x


def km_ys100_bench(robocal, repeat):
    work = tempfile.mkdtemp(prefix="robocal-peer-")
    files = {}
    for name, seed, n in (("ident", 1, 50), ("valid", 2, 30)):
        path = os.path.join(work, f"{name}.csv")
        subprocess.check_call([
            robocal, "simulate", "--preset", "ys100", "--poses", str(n), "--seed", str(seed),
            "--tracker", "1,-2,30,2500,-1000,400", "--out", path],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        files[name] = path
    qi, pi = load_canonical(files["ident"])
    qv, pv = load_canonical(files["valid"])
    x, t = timed(lambda: fit_ys(qi, pi), repeat)
    err = np.linalg.norm(ys_residual(x, qv, pv).reshape(-1, 3), axis=1)
    out = {"scipy_least_squares": {"validation_mean_mm": float(err.mean()), "time_s": t}}
    r = json.loads(subprocess.check_output([
        robocal, "bench", "km", "--model", "ys100", "--identify", files["ident"],
        "--validate", files["valid"], "--repeat", str(max(repeat, 30))]))
    out["robocal"] = {"validation_mean_mm": r["validation_mean_mm"], "time_s": r["time_ms_median"] / 1e3,
                      "converged": r["converged"]}
    return out


def print_km(title, km):
    r = km["robocal"]
    print(title)
    print(f"{'':24}{'val. mean mm':>14}{'time':>12}{'robocal faster':>16}{'accuracy ratio':>16}")
    for name in ("scipy_least_squares", "robocal"):
        v = km[name]
        print(f"{name:24}{v['validation_mean_mm']:14.4f}{v['time_s'] * 1e3:10.1f}ms"
              f"{v['time_s'] / r['time_s']:15.0f}x{v['validation_mean_mm'] / r['validation_mean_mm']:16.4f}",
              flush=True)


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
    # roboticstoolbox answers an IKSolution (q, success, ...); older numpy
    # builds of it answered a plain tuple.
    def unpack(s):
        return (s.q, bool(s.success)) if hasattr(s, "success") else (s[0], bool(s[1]))

    ok = [check(q, T) for (q, good), T in ((unpack(s), T) for s, T in zip(sols, Ts)) if good]
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
    ap.add_argument("--only", choices=["km", "km-ys100", "ik"], help="run one part only")
    a = ap.parse_args()
    out = {}
    if a.only in (None, "km"):
        out["km"] = km_bench(a.robocal, a.repeat)
        print_km("KM on the real UR5 grid (1000 poses), validated on 20 random poses", out["km"])
    if a.only in (None, "km-ys100"):
        out["km_ys100"] = km_ys100_bench(a.robocal, a.repeat)
        print_km("\nKM on a simulated YS100 (50 poses), validated on 30 other poses", out["km_ys100"])
    if a.only in ("km", "km-ys100"):
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

#!/usr/bin/env python3
"""Per-joint angle error maps on the real UR5 data, outside robocal (numpy + scipy).

    python3 -m venv /tmp/jm && /tmp/jm/bin/pip install numpy scipy
    /tmp/jm/bin/python scripts/joint_map_study.py

Fits a KM-like geometric calibration (standard DH errors per link, Hayati twists
on the parallel joints 2-3, base and tool offsets) on the 1000 grid poses, then
per-joint Fourier maps Δθ_i = Σ_k a_ik cos(k q_i) + b_ik sin(k q_i), linear in
their coefficients through joint i's Jacobian column, fitted with a ridge
penalty either after the geometry or jointly with its linearisation. Prints the
position-error statistics (mm) on the grid and on the 20 random poses the fit
never saw. A reference for robocal's own joint-map method, not part of it.
"""
import os
import numpy as np
from scipy.optimize import least_squares

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
D = os.path.join(ROOT, "data", "ur5-wam-laser-tracker", "UR5")


def load(name):
    a = np.genfromtxt(os.path.join(D, name), delimiter=",", skip_header=1)
    return np.radians(a[:, 7:13]), a[:, 1:4] + a[:, 4:7]  # measured = x_t + dif


A0 = np.array([0, -425, -392.25, 0, 0, 0.0])
D0 = np.array([89.159, 0, 0, 109.15, 94.65, 82.3])
AL0 = np.radians([90, 0, 0, 90, -90, 0.0])
TOOL = np.array([0, 0.09, 31.0])


def rot_zyx(r):
    cx, sx, cy, sy, cz, sz = np.cos(r[0]), np.sin(r[0]), np.cos(r[1]), np.sin(r[1]), np.cos(r[2]), np.sin(r[2])
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx


def fk(q, x):
    """TCP positions [mm]; x: per link (dθ, dd, da, dα, β) ×6, base (x, y, z, rx, ry, rz), tool (3)."""
    n = len(q)
    base = np.eye(4)
    base[:3, :3] = rot_zyx(x[33:36])
    base[:3, 3] = x[30:33]
    t = np.tile(base, (n, 1, 1))
    for i in range(6):
        dth, dd, da, dal, be = x[5 * i:5 * i + 5]
        th = q[:, i] + dth
        c, s = np.cos(th), np.sin(th)
        al = AL0[i] + dal
        ca, sa = np.cos(al), np.sin(al)
        a, d = A0[i] + da, D0[i] + dd
        m = np.zeros((n, 4, 4))
        m[:, 0, 0], m[:, 0, 1], m[:, 0, 2], m[:, 0, 3] = c, -s * ca, s * sa, a * c
        m[:, 1, 0], m[:, 1, 1], m[:, 1, 2], m[:, 1, 3] = s, c * ca, -c * sa, a * s
        m[:, 2, 1], m[:, 2, 2], m[:, 2, 3], m[:, 3, 3] = sa, ca, d, 1
        cb, sb = np.cos(be), np.sin(be)
        hy = np.array([[cb, 0, sb, 0], [0, 1, 0, 0], [-sb, 0, cb, 0], [0, 0, 0, 1]])
        t = t @ m @ hy
    return t[:, :3, :3] @ (TOOL + x[36:39]) + t[:, :3, 3]


MASK = np.ones(39, bool)
for i in range(6):
    if i not in (1, 2):
        MASK[5 * i + 4] = False  # Hayati twist only on the parallel joints 2, 3
MASK[[5 * 1 + 1, 5 * 2 + 1, 32, 35]] = False  # their d, base z and rz (dependent)


def full(xm):
    x = np.zeros(39)
    x[MASK] = xm
    return x


def stats(e):
    n = np.linalg.norm(e, axis=1)
    return f"mean {n.mean():.4f} max {n.max():.4f}"


def columns(q, x, which, h):
    out = []
    for i in which:
        xp, xm = x.copy(), x.copy()
        xp[i] += h
        xm[i] -= h
        out.append((fk(q, xp) - fk(q, xm)) / (2 * h))
    return np.stack(out, axis=2)  # n × 3 × len(which)


def maps_design(q, x, k):
    jt = columns(q, x, [5 * i for i in range(6)], 1e-7)
    ks = np.arange(1, k + 1)
    cols = []
    for i in range(6):
        b = np.concatenate([np.cos(np.outer(q[:, i], ks)), np.sin(np.outer(q[:, i], ks))], axis=1)
        cols.append(jt[:, :, i][:, :, None] * b[:, None, :])
    return np.concatenate(cols, axis=2).reshape(len(q) * 3, -1)


def ridge(a, b, penalised, lam):
    sc = np.linalg.norm(a, axis=0)
    sc[sc == 0] = 1
    p = np.where(penalised, lam, 0.0) / sc ** 2
    an = a / sc
    return np.linalg.solve(an.T @ an + np.diag(p) + 1e-9 * np.eye(len(sc)), an.T @ b) / sc


def main():
    qg, pg = load("3D_UR5_uncalibrated_grid_cleaned.csv")
    qr, pr = load("3D_UR5_uncalibrated_random_cleaned.csv")
    fit = least_squares(lambda xm: (fk(qg, full(xm)) - pg).ravel(), np.zeros(MASK.sum()), x_scale="jac")
    x = full(fit.x)
    eg, er = pg - fk(qg, x), pr - fk(qr, x)
    print("nominal  random", stats(pr - fk(qr, np.zeros(39))))
    print("geometry grid", stats(eg), "| random", stats(er))
    geo = np.where(MASK)[0]
    gg = columns(qg, x, geo, 1e-6).transpose(0, 1, 2).reshape(len(qg) * 3, -1)
    gr = columns(qr, x, geo, 1e-6).reshape(len(qr) * 3, -1)
    for k in (6, 20, 40, 60):
        mg, mr = maps_design(qg, x, k), maps_design(qr, x, k)
        for lam in (1e-2, 1.0, 1e2):
            c = ridge(mg, eg.ravel(), np.ones(mg.shape[1], bool), lam)
            after = f"after:  grid {stats(eg - (mg @ c).reshape(-1, 3))} | random {stats(er - (mr @ c).reshape(-1, 3))}"
            a = np.hstack([gg, mg])
            pen = np.r_[np.zeros(gg.shape[1], bool), np.ones(mg.shape[1], bool)]
            c = ridge(a, eg.ravel(), pen, lam)
            ar = np.hstack([gr, mr])
            joint = f"jointly: grid {stats(eg - (a @ c).reshape(-1, 3))} | random {stats(er - (ar @ c).reshape(-1, 3))}"
            print(f"K={k:2d} ridge={lam:g}  {after}  ||  {joint}")


if __name__ == "__main__":
    main()

"""Rotations for scripts/console_check.py, which makes 6-D readings with
seeded noise: 3x3 matrices as lists of rows, angles in degrees, fixed-axis
XYZ `rx, ry, rz` meaning R = Rz(rz)·Ry(ry)·Rx(rx) (the measurement files'
convention) and intrinsic XYZ meaning R = Rx·Ry·Rz. Python 3 standard
library only.
"""
import math


def matmul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def rotation_rpy(rpy_deg):
    """R = Rz(rz)·Ry(ry)·Rx(rx), fixed-axis XYZ degrees (the measurement files' convention)."""
    a, b, c = (math.radians(v) for v in rpy_deg)
    rx = [[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]]
    ry = [[math.cos(b), 0, math.sin(b)], [0, 1, 0], [-math.sin(b), 0, math.cos(b)]]
    rz = [[math.cos(c), -math.sin(c), 0], [math.sin(c), math.cos(c), 0], [0, 0, 1]]
    return matmul(rz, matmul(ry, rx))


def rotation(vector_deg):
    """The rotation by the vector's length about its direction (Rodrigues)."""
    v = [math.radians(x) for x in vector_deg]
    angle = math.sqrt(sum(x * x for x in v))
    if angle == 0.0:
        return [[1.0 if i == j else 0.0 for j in range(3)] for i in range(3)]
    k = [x / angle for x in v]
    kx = [[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]]
    kk = matmul(kx, kx)
    return [[(1.0 if i == j else 0.0) + math.sin(angle) * kx[i][j] + (1 - math.cos(angle)) * kk[i][j]
             for j in range(3)] for i in range(3)]


def fixed_xyz(r):
    """rx, ry, rz [deg] of R = Rz·Ry·Rx (away from ry = ±90°)."""
    return [math.degrees(math.atan2(r[2][1], r[2][2])),
            math.degrees(math.asin(max(-1.0, min(1.0, -r[2][0])))),
            math.degrees(math.atan2(r[1][0], r[0][0]))]


def intrinsic_xyz(r):
    """rx, ry, rz [deg] about the moving axes: R = Rx·Ry·Rz (away from ry = ±90°)."""
    return [math.degrees(math.atan2(-r[1][2], r[2][2])),
            math.degrees(math.asin(max(-1.0, min(1.0, r[0][2])))),
            math.degrees(math.atan2(-r[0][1], r[0][0]))]


def rotation_angle(a, b):
    """The angle between two rotations [deg]."""
    trace = sum(sum(a[k][i] * b[k][i] for k in range(3)) for i in range(3))
    return math.degrees(math.acos(max(-1.0, min(1.0, (trace - 1.0) / 2.0))))

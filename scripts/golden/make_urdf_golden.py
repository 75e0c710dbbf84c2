#!/usr/bin/env python3
"""Golden forward kinematics of robocal's URDF export, from an outside implementation.

Loads core/tests/golden/ur5_km.urdf (written by
`robocal export --model core/tests/golden/ur5_km_calibrated.json --format urdf`, the UR5
calibrated by KM on the real laser-tracker grid) with pinocchio (PyPI package `pin`),
and writes core/tests/golden/urdf_fk_ur5_km.json: 40 joint vectors (controller readings,
degrees, q = 0 first, then uniform in [-170, 170] from a fixed numpy seed, rounded to
6 decimals) with the pose of the `tcp` frame in the root link `cell` (translation in
mm, rotation matrix). core/tests/export.rs compares robocal's geometric FK with it.

Rerun (not part of the Rust build):

    python3 -m venv /tmp/pin && /tmp/pin/bin/pip install pin==4.1.0 numpy
    /tmp/pin/bin/python scripts/golden/make_urdf_golden.py
"""
from __future__ import annotations

import json
from importlib.metadata import version
from pathlib import Path

import numpy as np
import pinocchio as pin

ROOT = Path(__file__).resolve().parents[2]
URDF = ROOT / "core" / "tests" / "golden" / "ur5_km.urdf"
OUT = ROOT / "core" / "tests" / "golden" / "urdf_fk_ur5_km.json"
SEED = 20261122
N_RANDOM = 39


def main() -> None:
    model = pin.buildModelFromUrdf(str(URDF))
    data = model.createData()
    tcp = model.getFrameId("tcp")
    names = [model.names[i] for i in range(1, model.njoints)]
    assert names == [f"joint_{k}" for k in range(1, 7)], names
    rng = np.random.default_rng(SEED)
    qs = [np.zeros(6)] + [np.round(rng.uniform(-170.0, 170.0, 6), 6) for _ in range(N_RANDOM)]
    samples = []
    for q_deg in qs:
        q = np.radians(q_deg)
        pin.forwardKinematics(model, data, q)
        pin.updateFramePlacements(model, data)
        m = data.oMf[tcp]
        samples.append(
            {
                "q_ctrl_deg": [float(v) for v in q_deg],
                "xyz_mm": [float(v) * 1e3 for v in m.translation],
                "rotation": [[float(v) for v in row] for row in m.rotation],
            }
        )
    doc = {
        "source": "pinocchio buildModelFromUrdf + forwardKinematics + updateFramePlacements, frame `tcp` in root link `cell`",
        "urdf": "core/tests/golden/ur5_km.urdf",
        "versions": {"pin": version("pin"), "numpy": np.__version__},
        "samples": samples,
    }
    OUT.write_text(json.dumps(doc, indent=1) + "\n")
    print(f"wrote {len(samples)} samples to {OUT}")


if __name__ == "__main__":
    main()

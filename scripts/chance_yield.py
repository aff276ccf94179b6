#!/usr/bin/env python3
"""What AWCC accepts from signals that share no bubble (docs/validation.md,
"Rule (d): a yield above chance"; awcc::chance_data_yield): for each scene,
the record's own tip pair against its leading tip with the trailing tip of
another seed's record, 20 s at 200 kHz, Np 10 unless the scene says
otherwise. Needs the Python module (scripts/build builds it).

Usage: PYTHONPATH=build/python /usr/bin/python3 scripts/chance_yield.py
"""
import pdp

SCENES = {
    "base case": {},
    "base case, dy 3 mm": {"dy": "3mm"},
    "1 mm bubbles, dx 5 mm, dy 2 mm": {"bubble_diameter": "1mm", "dx": "5mm", "dy": "2mm"},
    "c 0.02, 2 mm bubbles": {"void_fraction": 0.02, "bubble_diameter": "2mm"},
    "foreign control run 52": {"velocity": "31.7m/s", "tu": 0.043, "time_scale": "21ms", "void_fraction": 0.31,
                               "bubble_diameter": "1.3mm", "dx": "6.9mm", "dy": "1.9mm"},
}


def accepted(result):
    a = result.awcc
    return f"{a.windows_accepted} of {a.windows_total} ({100 * a.windows_accepted / max(1, a.windows_total):.3f} %)"


for name, fields in SCENES.items():
    scene = {"duration": "20s", "fs": "200kHz", **fields}
    own = pdp.synth(scene, seed=1)
    other = pdp.synth(scene, seed=2)
    dx = float(own.scene.dx)
    lead = own.signals[:, 0].copy()
    pair = pdp.process(lead, own.signals[:, 1].copy(), fs=own.fs, dx=dx, np=10, method="awcc")
    unrelated = pdp.process(lead, other.signals[:, 1].copy(), fs=own.fs, dx=dx, np=10, method="awcc")
    print(f"{name}: own pair {accepted(pair)}; unrelated tips {accepted(unrelated)}")

"""The real stepped-spillway profile (Felder's dc157 recordings, step edge 10)
processed, bias-corrected and plotted with the pdp Python module and its
plotting layer (the figures of pdp report).
Usage: /usr/bin/python3 profile.py DATA_DIR [OUTPUT.png]"""
import sys
from pathlib import Path

import pdp
from pdp import plotting

data = Path(sys.argv[1])
files = sorted(data.glob("dc157_*.dat"))
y = [0.002, 0.008, 0.014, 0.020, 0.026, 0.032, 0.038, 0.044, 0.050, 0.054]  # m above the pseudo-bottom
model = Path(__file__).resolve().parents[1] / "model" / "awcc.qrf"
r = pdp.process(files, fs=20e3, dx="7.15mm", positions=y[:len(files)], correct=model)

# c with 95 % intervals; FSCC, AWCC (95 %) and the corrected median (80 and 95 % bands) of u
fig, ((ax_c, ax_u),) = plotting.figure(width=10, height=4.2, cols=2, margins=(0.62, 0.5, 0.12, 0.3))
plotting.profile_void_fraction(r.profile, ax=ax_c)
plotting.profile_velocity(r.profile, ax=ax_u)
fig.savefig(sys.argv[2] if len(sys.argv) > 2 else "profile.png", dpi=120)
for row in r.profile:
    print(f"{row.position * 1e3:5.1f} mm  c = {row.tips[0].void_fraction:.3f}  u = {row.awcc.velocity or float('nan'):.2f} m/s  "
          f"{row.awcc.quality:12s} {row.correction.status}")

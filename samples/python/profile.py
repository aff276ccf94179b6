"""The real stepped-spillway profile (Felder's dc157 recordings, step edge 10)
processed, bias-corrected and plotted with the pdp Python module.
Usage: /usr/bin/python3 profile.py DATA_DIR [OUTPUT.png]"""
import sys
from pathlib import Path

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import pdp

data = Path(sys.argv[1])
files = sorted(data.glob("dc157_*.dat"))
y = [0.002, 0.008, 0.014, 0.020, 0.026, 0.032, 0.038, 0.044, 0.050, 0.054]  # m above the pseudo-bottom
model = Path(__file__).resolve().parents[1] / "model" / "awcc.qrf"
r = pdp.process(files, fs=20e3, dx="7.15mm", positions=y[:len(files)], correct=model)

fig, (ax_c, ax_u) = plt.subplots(1, 2, sharey=True, figsize=(8, 4))
ax_c.plot([row.tips[0].void_fraction for row in r.profile], y, "o-")
ax_c.set(xlabel="void fraction c", ylabel="y (m)")
u = [row.awcc.velocity if row.awcc.status == "ok" else None for row in r.profile]
ax_u.plot(u, y, "s", label="AWCC (measured)")
fixed = [(row.correction.velocity.quantiles, row.position) for row in r.profile if row.correction.status == "corrected"]
for q, pos in fixed:  # the 95 % interval of the true mean velocity
    ax_u.plot([q["0.025"], q["0.975"]], [pos, pos], "k-")
ax_u.plot([q["0.5"] for q, _ in fixed], [p for _, p in fixed], "kd", label="corrected (median, 95 %)")
ax_u.set(xlabel="u (m/s)")
ax_u.legend()
fig.savefig(sys.argv[2] if len(sys.argv) > 2 else "profile.png", dpi=120)
for row in r.profile:
    print(f"{row.position * 1e3:5.1f} mm  c = {row.tips[0].void_fraction:.3f}  u = {row.awcc.velocity or float('nan'):.2f} m/s  "
          f"{row.awcc.quality:12s} {row.correction.status}")

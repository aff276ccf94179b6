#!/usr/bin/python3
"""The sub-sample peak study's figure (docs/figures/subsample-phase.png):
mean and spread of each estimator's lag error against the true lag's
sub-sample phase, per sampling rate, from build/bench/subsample_study --out.

    /usr/bin/python3 scripts/subsample_figure.py windows.csv docs/figures/subsample-phase.png
"""
import sys

import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

if len(sys.argv) != 3:
    sys.exit("usage: subsample_figure.py WINDOWS_CSV PNG")
try:
    w = pd.read_csv(sys.argv[1])
except (OSError, pd.errors.ParserError) as e:
    sys.exit(f"subsample_figure.py: cannot read {sys.argv[1]}: {e}")
need = {"fs", "phase", "method", "error", "lag_reference"}
if not need <= set(w.columns):
    sys.exit(f"subsample_figure.py: {sys.argv[1]} lacks the columns {sorted(need - set(w.columns))}: "
             "not a file of subsample_study --out")
rates = sorted(w.fs.unique())
methods = ["none", "parabolic", "gaussian", "triangle", "centroid"]
fig, axes = plt.subplots(1, len(rates), figsize=(4 * len(rates), 3.6), sharey=True)
edges = np.linspace(-0.5, 0.5, 11)
mid = 0.5 * (edges[1:] + edges[:-1])
for ax, fs in zip(axes, rates):
    at = w[w.fs == fs]
    for m in methods:
        s = at[at.method == m]
        b = np.digitize(s.phase, edges) - 1
        mean = [s.error[b == i].mean() for i in range(10)]
        ax.plot(mid, mean, marker="o", ms=3, label=m)
    ax.axhline(0, color="k", lw=0.5)
    ax.set_title(f"{fs / 1e3:g} kHz (median lag {at.lag_reference.median():.0f} samples)", fontsize=9)
    ax.set_xlabel("true lag's phase (samples)")
    ax.set_ylim(-0.35, 0.35)
axes[0].set_ylabel("mean lag error (samples)")
axes[-1].legend(fontsize=7)
fig.tight_layout()
fig.savefig(sys.argv[2], dpi=110)
# By lag in samples: rms error and mean error of each estimator.
w["band"] = pd.cut(w.lag_reference, [0, 5, 10, 20, 50, 1e9], right=False,
                   labels=["under 5", "5-10", "10-20", "20-50", "50 and more"])
t = w.groupby(["band", "method"], observed=True).error.agg(["mean", lambda e: np.sqrt(np.mean(e * e)), "size"])
t.columns = ["mean error", "rms error", "windows"]
print(t.unstack("method").round(4).to_string())

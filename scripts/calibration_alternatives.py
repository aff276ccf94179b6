#!/usr/bin/env python3
"""Offline comparison of interval calibrations (scripts/calibration-alternatives,
which passes the model's offsets;
docs/history/correction-foreign-conventions.md, "The intervals'
calibration: what it can and cannot fix").

Each corrected row's Tu interval is taken back to the forest's own by
removing its group's offset (window bands 30, 100; Tu bands 0.1, 0.2, 0.3 of
the median, which calibration leaves alone). The training split's held-out
rows (held-out.csv) then calibrate it again in other ways, each a split
conformal offset Q = E_k, k = ceil((n + 1)(1 - alpha)) of its group's scores
(groups of fewer than 50 rows keep Q = 0), and every predictions file is
scored under each. Last, the ellipsoids' set against the control's same
scenes by quartile of d32 / dx.

Usage: calibration_alternatives.py OFFSETS.txt OUT_DIR
"""
import csv
import glob
import math
import os
import sys

import numpy as np

WINDOW_EDGES = [30, 100]
TU_EDGES = [0.1, 0.2, 0.3]
LEVELS = {0.8: ("0.1", "0.9", 1), 0.95: ("0.025", "0.975", 2)}


def offsets(path):
    tu = {}
    for line in open(path):
        if line.startswith("group"):
            g = int(line.split()[1].rstrip(":"))
            tu[g] = [float(x) for x in line.split("|")[1].split()[1:4]]
    return tu


def corrected_tu_rows(path):
    return [r for r in csv.DictReader(open(path)) if r["status"] == "corrected" and r["turbulence_corrected"] == "1"]


def raw_intervals(rows, level, tu_offsets):
    """Per row: group, the forest's own interval (lo, hi), the truth, the shipped offset."""
    lo_q, hi_q, k = LEVELS[level]
    out = []
    for r in rows:
        median = float(r["corrected_turbulence_intensity_q0.5"])
        w = sum(int(r["windows_accepted"]) >= e for e in WINDOW_EDGES)
        g = w * (len(TU_EDGES) + 1) + sum(median >= e for e in TU_EDGES)
        q = tu_offsets[g][k]
        out.append((g, float(r["corrected_turbulence_intensity_q" + lo_q]) + q,
                    float(r["corrected_turbulence_intensity_q" + hi_q]) - q,
                    float(r["true_turbulence_intensity"]), q, float(r["duration"])))
    return np.array(out)


def conformal(scores, alpha):
    n = len(scores)
    k = math.ceil((n + 1) * (1 - alpha))
    return np.sort(scores)[min(k, n) - 1]


def main(offsets_path, out):
    tu_offsets = offsets(offsets_path)
    files = [os.path.join(out, "held-out.csv")] + sorted(glob.glob(os.path.join(out, "predictions-*.csv")))
    sets = {os.path.basename(f): corrected_tu_rows(f) for f in files}
    for level in LEVELS:
        alpha = 1 - level
        cal = raw_intervals(sets["held-out.csv"], level, tu_offsets)
        width = cal[:, 2] - cal[:, 1]
        width_edges = np.quantile(width, [0.2, 0.4, 0.6, 0.8])
        groupings = {
            "width quintile x Tu band": lambda a: np.searchsorted(width_edges, a[:, 2] - a[:, 1]) * 4 + (a[:, 0] % 4),
            "window x Tu x duration (100, 200 s)": lambda a: a[:, 0] * 3 + np.searchsorted([100, 200], a[:, 5]),
        }
        score = np.maximum(cal[:, 1] - cal[:, 3], cal[:, 3] - cal[:, 2])
        scaled_q = {}
        for g in np.unique(cal[:, 0]):
            s = cal[:, 0] == g
            if s.sum() >= 50:
                scaled_q[g] = conformal(score[s] / np.maximum(width[s], 1e-9), alpha)
        grouped_q = {}
        for name, group_of in groupings.items():
            groups = group_of(cal)
            grouped_q[name] = (group_of, {g: conformal(score[groups == g], alpha)
                                          for g in np.unique(groups) if (groups == g).sum() >= 50})
        print(f"\nTu {100 * level:.0f} % coverage: none | shipped | scaled by width | " + " | ".join(groupings))
        for name, rows in sets.items():
            a = raw_intervals(rows, level, tu_offsets)
            t, lo, hi = a[:, 3], a[:, 1], a[:, 2]
            cover = lambda q, scale=1.0: 100 * np.mean((t >= lo - q * scale) & (t <= hi + q * scale))
            cells = [cover(0.0), cover(a[:, 4])]
            cells.append(cover(np.array([scaled_q.get(g, 0.0) for g in a[:, 0]]), hi - lo))
            for group_of, q in grouped_q.values():
                cells.append(cover(np.array([q.get(g, 0.0) for g in group_of(a)])))
            print(f"  {name:46s} n {len(a):5d}  " + "  ".join(f"{c:5.1f}" for c in cells))
    ellipsoids(out)


def ellipsoids(out):
    load = lambda p: {r["run"]: r for r in csv.DictReader(open(p)) if r["status"] == "corrected"}
    e_rows = load(os.path.join(out, "predictions-foreign-ellipsoids.csv"))
    c_rows = load(os.path.join(out, "predictions-foreign-control.csv"))
    f = lambda r, k: float(r[k])
    inside = lambda r: f(r, "corrected_velocity_q0.1") <= f(r, "true_velocity") <= f(r, "corrected_velocity_q0.9")
    a = []
    for run in sorted(set(e_rows) & set(c_rows), key=int):
        e, c = e_rows[run], c_rows[run]
        u = f(e, "true_velocity")
        a.append((f(e, "d32") / f(e, "dx"), f(e, "velocity") / u - 1, f(c, "velocity") / u - 1,
                  f(e, "corrected_velocity_q0.5") / u - 1, f(c, "corrected_velocity_q0.5") / u - 1,
                  (f(e, "corrected_velocity_q0.9") - f(e, "corrected_velocity_q0.1")) / u,
                  (f(c, "corrected_velocity_q0.9") - f(c, "corrected_velocity_q0.1")) / u,
                  inside(e), inside(c), f(e, "d32") / f(c, "d32")))
    a = np.array(a, dtype=float)
    print(f"\nellipsoids against control, {len(a)} runs both correct: d32 / dx band, runs, raw u median error e / c, "
          "corrected, 80 % width, 80 % coverage, d32 e / c")
    q = np.quantile(a[:, 0], [0, 0.25, 0.5, 0.75, 1])
    for lo, hi in zip(q[:-1], q[1:]):
        s = a[(a[:, 0] >= lo) & (a[:, 0] <= hi)]
        m = lambda j: 100 * np.median(s[:, j])
        print(f"  {lo:.3g}-{hi:.3g}: {len(s)}  {m(1):+.2f} / {m(2):+.2f} %  {m(3):+.2f} / {m(4):+.2f} %  "
              f"{m(5):.1f} / {m(6):.1f} %  {100 * s[:, 7].mean():.0f} / {100 * s[:, 8].mean():.0f} %  "
              f"{np.median(s[:, 9]):.3f}")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])

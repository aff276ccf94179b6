#!/usr/bin/env python3
"""The tables of docs/validation.md's trust rules (c) and (d) and of the
foreign sets on corrected rows, from one model's predictions of the
conventions campaign's test sets (the predictions-*.csv that
scripts/train-conventions-model writes, pdp score --predictions) and the
campaign's sweep CSVs (for each run's formed windows, which the predictions
do not hold).

Prints, over the scored runs of own-test, long's held-out records and the ten
foreign sets:
  - the rows at a lag of one sample (dx fs / u below 1.5) per set, their
    corrected and raw u median |error| against the others' (rule (c));
  - u's errors and coverage by data yield (accepted / formed windows), and
    the rows below 0.1 % against the others (rule (d));
  - each foreign set's scores on its corrected rows only (Tu on the rows
    whose Tu is corrected too: not those of rule (e));
  - Tu's errors and coverage by d32 / dx on the corrected rows, and the
    rows rule (e) holds back (d32 / dx above 10) per set.

Usage: trust_tables.py MODEL_OUT_DIR CAMPAIGN_DIR
  (MODEL_OUT_DIR: scripts/train-conventions-model's OUT_DIR; CAMPAIGN_DIR:
  samples/model/conventions/runs)
"""
import sys
from pathlib import Path

import numpy as np
import pandas as pd

FOREIGN = ["control", "poisson-time", "equal-space", "poisson-space", "euler", "overlap", "ellipsoids",
           "unweighted", "all", "lab-corners", "lab-corners-control"]
# Scored in the foreign sets' table only: the tables over every set (rules
# (c)-(e), by d32 / dx) are of the sets before it.
TABLE_ONLY = ["foreign-lab-corners-control"]
LEAST_RESOLVED_LAG = 1.5  # awcc::least_resolved_lag_samples
CHANCE_YIELD = 0.001      # awcc::chance_data_yield
LARGEST_TU_SIZE_RATIO = 10.0  # correction::largest_tu_size_ratio


def load(out, campaign):
    sets = [("own-test", out / "predictions-own.csv", campaign / "own-test.csv"),
            ("long", out / "predictions-long-held-out.csv", out / "long-held-out.csv")]
    sets += [(f"foreign-{s}", out / f"predictions-foreign-{s}.csv", campaign / f"foreign-{s}.csv") for s in FOREIGN]
    rows = []
    for name, pred, sweep in sets:
        p = pd.read_csv(pred)
        # One study per file, so a run number names one run.
        formed = pd.read_csv(sweep, usecols=["run", "awcc_windows_total"]).drop_duplicates("run")
        m = p.merge(formed, on="run", how="left")
        m["set"] = name
        rows.append(m)
    d = pd.concat(rows, ignore_index=True)
    d["yield"] = d.windows_accepted / d.awcc_windows_total
    # Rule (e): written by pdp score since the rule; before it, the same test on d32 / dx.
    if "turbulence_corrected" not in d:
        d["turbulence_corrected"] = ((d.status == "corrected") & ~(d.d32 / d.dx > LARGEST_TU_SIZE_RATIO)).astype(int)
    d["lag"] = d.dx * d.fs / d.velocity
    d["u_err"] = d["corrected_velocity_q0.5"] / d.true_velocity - 1
    d["u_raw"] = d.velocity / d.true_velocity - 1
    d["tu_err"] = d["corrected_turbulence_intensity_q0.5"] - d.true_turbulence_intensity
    for q, lo, hi in [("u", "corrected_velocity", "true_velocity"),
                      ("tu", "corrected_turbulence_intensity", "true_turbulence_intensity")]:
        d[f"{q}80"] = (d[f"{lo}_q0.1"] <= d[hi]) & (d[hi] <= d[f"{lo}_q0.9"])
        d[f"{q}95"] = (d[f"{lo}_q0.025"] <= d[hi]) & (d[hi] <= d[f"{lo}_q0.975"])
    return d


def pct(x):
    return f"{100 * x:.1f} %"


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    every = load(Path(sys.argv[1]), Path(sys.argv[2]))
    d = every[~every.set.isin(TABLE_ONLY)]

    print("## Rule (c): a lag of one sample, by set")
    for name, s in d.groupby("set"):
        one = s.lag < LEAST_RESOLVED_LAG
        if one.any():
            print(f"{name}: {one.sum()} of {len(s)}; corrected u median |err| {pct(s.u_err[one].abs().median())} "
                  f"(raw {pct(s.u_raw[one].abs().median())}, 80 % coverage {pct(s.u80[one].mean())}) against "
                  f"{pct(s.u_err[~one].abs().median())}")
        else:
            print(f"{name}: none of {len(s)}")

    print("\n## Rule (d): u by data yield")
    bins = [0, 0.0002, 0.0005, 0.001, 0.002, 0.003, 0.005, 0.01, 1.01]
    g = d.groupby(pd.cut(d["yield"], bins), observed=True)
    for band, s in g:
        print(f"{band}: {len(s)} runs; raw {pct(s.u_raw.abs().median())}, corrected {pct(s.u_err.abs().median())}, "
              f"p90 {pct(s.u_err.abs().quantile(0.9))}; coverage {pct(s.u80.mean())} / {pct(s.u95.mean())}")
    chance = d["yield"] < CHANCE_YIELD
    for label, s in [("below 0.1 %", d[chance]), ("the others", d[~chance])]:
        print(f"{label}: {len(s)} runs; raw {pct(s.u_raw.abs().median())}, corrected {pct(s.u_err.abs().median())} "
              f"(p90 {pct(s.u_err.abs().quantile(0.9))}, 95 % coverage {pct(s.u95.mean())}, "
              f"Tu mean error {s.tu_err.mean():+.4f})")

    print("\n## The foreign sets, corrected rows only")
    print("set | u median abs | u mean | Tu median abs | Tu mean | u 80 / 95 % | Tu 80 / 95 % | corrected")
    for name in FOREIGN:
        s = every[every.set == f"foreign-{name}"]
        c = s[s.status == "corrected"]
        t = s[s.turbulence_corrected == 1]
        print(f"{name} | {100 * c.u_err.abs().median():.2f} % | {100 * c.u_err.mean():+.2f} % | {t.tu_err.abs().median():.4f} | "
              f"{t.tu_err.mean():+.4f} | {100 * c.u80.mean():.1f} / {100 * c.u95.mean():.1f} | "
              f"{100 * t.tu80.mean():.1f} / {100 * t.tu95.mean():.1f} | {len(c)} of {len(s)} | Tu {len(t)}")

    print("\n## Tu by d32 / dx, corrected rows")
    c = d[d.status == "corrected"]
    for band, s in c.groupby(pd.cut(c.d32 / c.dx, [0, 0.3, 1, 3, 5, 7, 10, 14, 20, 30, np.inf]), observed=True):
        print(f"{band}: {len(s)} rows; Tu mean {s.tu_err.mean():+.4f}, median {s.tu_err.median():+.4f}, "
              f"median abs {s.tu_err.abs().median():.4f}; coverage {pct(s.tu80.mean())} / {pct(s.tu95.mean())}; "
              f"u median abs {pct(s.u_err.abs().median())}, u coverage {pct(s.u80.mean())} / {pct(s.u95.mean())}")

    print("\n## Rule (e): corrected rows whose Tu is held back (d32 / dx above 10), by set")
    for name, s in c.groupby("set"):
        held = s.turbulence_corrected == 0
        print(f"{name}: {held.sum()} of {len(s)}")
    held = c[c.turbulence_corrected == 0]
    kept = c[c.turbulence_corrected == 1]
    for label, s in [("held back", held), ("the others", kept)]:
        print(f"{label}: {len(s)} rows; Tu mean {s.tu_err.mean():+.4f}, median abs {s.tu_err.abs().median():.4f}, "
              f"coverage {pct(s.tu80.mean())} / {pct(s.tu95.mean())}; u median abs {pct(s.u_err.abs().median())}, "
              f"coverage {pct(s.u80.mean())} / {pct(s.u95.mean())}")


if __name__ == "__main__":
    main()

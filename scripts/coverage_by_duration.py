#!/usr/bin/env python3
"""Coverage of the corrected intervals by record length (pdp score
--predictions files): per band of duration, the rows corrected, the median
|u / u_true - 1| and the mean error of the corrected median, the same for Tu
(absolute; rows whose Tu is corrected), and the 80 / 95 % coverage of u and
Tu, with the binomial standard error of the 80 % coverage,
sqrt(p (1 - p) / n). docs/history/correction-foreign-conventions.md,
"The model of the complete campaign, shipped" (its coverage by record
length), and "The intervals' calibration: what it can and cannot fix".

Usage: coverage_by_duration.py [--edges 300,600,900,1200,1500] NAME PREDICTIONS.csv [NAME PREDICTIONS.csv ...]
"""
import csv
import math
import statistics
import sys


def load(path):
    rows = []
    reader = csv.DictReader(open(path))
    missing = {"status", "duration", "true_velocity", "corrected_velocity_q0.5"} - set(reader.fieldnames or [])
    if missing:
        sys.exit(f"{path}: not a pdp score --predictions file with durations (no column {', '.join(sorted(missing))})")
    for r in reader:
        if r["status"] != "corrected":
            continue
        if not r["duration"]:
            sys.exit(f"{path}: run {r.get('run', '?')} has no duration; this table needs every row's record length")
        q = lambda name: float(r[name])
        tu_ok = r.get("turbulence_corrected", "1") == "1"
        rows.append({
            "duration": q("duration"),
            "u": q("true_velocity"),
            "u_med": q("corrected_velocity_q0.5"),
            "u80": q("corrected_velocity_q0.1") <= q("true_velocity") <= q("corrected_velocity_q0.9"),
            "u95": q("corrected_velocity_q0.025") <= q("true_velocity") <= q("corrected_velocity_q0.975"),
            "tu_ok": tu_ok,
            "tu": q("true_turbulence_intensity"),
            "tu_med": q("corrected_turbulence_intensity_q0.5") if tu_ok else math.nan,
            "tu80": q("corrected_turbulence_intensity_q0.1") <= q("true_turbulence_intensity")
            <= q("corrected_turbulence_intensity_q0.9"),
            "tu95": q("corrected_turbulence_intensity_q0.025") <= q("true_turbulence_intensity")
            <= q("corrected_turbulence_intensity_q0.975"),
        })
    return rows


def line(label, rows):
    if not rows:
        return f"| {label} | 0 | | | | | | |"
    n = len(rows)
    u_err = [r["u_med"] / r["u"] - 1 for r in rows]
    tu_rows = [r for r in rows if r["tu_ok"]]
    tu_err = [r["tu_med"] - r["tu"] for r in tu_rows]
    cov = lambda key, rs: 100.0 * sum(r[key] for r in rs) / len(rs) if rs else math.nan
    se = lambda p, m: 100.0 * math.sqrt(p / 100 * (1 - p / 100) / m) if m else math.nan
    u80, tu80 = cov("u80", rows), cov("tu80", tu_rows)
    return (f"| {label} | {n} | {100 * statistics.median(map(abs, u_err)):.2f} % | {100 * statistics.fmean(u_err):+.2f} % | "
            f"{statistics.median(map(abs, tu_err)):.4f} | {statistics.fmean(tu_err):+.4f} | "
            f"{u80:.1f} ± {se(u80, n):.1f} / {cov('u95', rows):.1f} | "
            f"{tu80:.1f} ± {se(tu80, len(tu_rows)):.1f} / {cov('tu95', tu_rows):.1f} ({len(tu_rows)}) |")


def main(argv):
    edges = [300.0, 600.0, 900.0, 1200.0, 1500.0]
    if argv and argv[0] == "--edges":
        edges = [float(x) for x in argv[1].split(",")]
        argv = argv[2:]
    if not argv or len(argv) % 2:
        sys.exit(__doc__)
    loaded = [(name, load(path)) for name, path in zip(argv[0::2], argv[1::2])]  # every file checked first
    print("| model | duration | rows | u median abs | u mean error | Tu median abs | Tu mean error | u 80 / 95 % | Tu 80 / 95 % |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, rows in loaded:
        bounds = [0.0] + edges + [math.inf]
        for lo, hi in zip(bounds[:-1], bounds[1:]):
            band = [r for r in rows if lo <= r["duration"] < hi]
            if not band:
                continue
            label = f"{lo:,.0f}-{hi:,.0f} s" if math.isfinite(hi) else f"{lo:,.0f} s+"
            print(f"| {name} " + line(label, band))
        print(f"| {name} " + line("all", rows))


if __name__ == "__main__":
    main(sys.argv[1:])

#!/usr/bin/env python3
"""Issue 51's must-show table: the correction's scores set by set, one row per
set and model, from pdp score --predictions files, with each target checked.

Per row, over the runs the model corrected: median |u / u_true - 1| raw ->
corrected, the corrected median's mean u error, its Tu mean error
(absolute), the mean u error in each band of true Tu (0-0.1, 0.1-0.2,
0.2-0.3, 0.3-0.4), the coverage of the 80 and 95 % intervals, and over all
the set's runs the AWCC Tu of exactly zero (the whole-sample collapse).
A target given to a set is checked and marked: u mean (|mean u error| <=
1 %), tu mean (|Tu mean error| <= 0.01 or <= 0.005), u median (median
|u error| <= 1.1 % or 1.5 %), bands (|mean u error| <= 1 % in every band of
10 runs or more), coverage (no interval under its nominal level by more
than 2 points), no zero Tu. A band of fewer than 10 runs is shown in
parentheses and not checked: its mean is not a measurement.

Usage: must_show.py SET MODEL PREDICTIONS.csv[@SELECTION] TARGETS [SET MODEL ... TARGETS ...]
  SELECTION keeps some runs: conditions joined by commas on duration (s),
  fs (Hz), lag (AWCC's, samples) or windows, with =, >= or <=, e.g.
  @duration=60 (one record length of a grid) or @fs<=40000,lag>=5
  TARGETS: comma-separated names from: u-mean, tu-mean-0.01, tu-mean-0.005,
  u-median-1.1, u-median-1.5, bands, coverage, no-zero-tu; or "-" (none)
"""
import csv
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from score_comparison import rows  # noqa: E402  (one reader of a predictions file)

TU_BANDS = [(0.0, 0.1), (0.1, 0.2), (0.2, 0.3), (0.3, 0.4)]
TARGETS = {"u-mean", "tu-mean-0.01", "tu-mean-0.005", "u-median-1.1", "u-median-1.5", "bands", "coverage",
           "no-zero-tu"}


# A selection after the file name: conditions joined by commas, each a
# band quantity of score_comparison.rows() (duration s, fs Hz, lag samples,
# windows) compared with = (to 1e-9), >= or <=.
def selector(text, path):
    tests = []
    for cond in filter(None, text.split(",")):
        for op in (">=", "<=", "="):
            key, found, value = cond.partition(op)
            if found:
                break
        if not found or key not in ("duration", "fs", "lag", "windows"):
            sys.exit(f"{path}@{text}: a condition is duration|fs|lag|windows followed by =, >= or <= and a number")
        v = float(value)
        tests.append((key, op, v))

    def keep(band_of):
        for key, op, v in tests:
            x = band_of[key]
            if not (abs(x - v) <= 1e-9 * max(1.0, abs(v)) if op == "=" else x >= v if op == ">=" else x <= v):
                return False
        return True
    return keep


def zero_tu_runs(path, keep):
    """Runs whose AWCC Tu is exactly zero, among all the file's rows selected."""
    n = 0
    for r in csv.DictReader(open(path)):
        try:
            band_of = {"duration": float(r["duration"]), "fs": float(r["fs"]), "windows": float(r["windows_accepted"]),
                       "lag": float(r["fs"]) * float(r["dx"]) / float(r["velocity"])}
            tu = float(r["turbulence_intensity"])
        except (ValueError, ZeroDivisionError):
            continue
        n += tu == 0.0 and keep(band_of)
    return n


def mark(ok):
    return "" if ok is None else (" ✓" if ok else " ✗")


def row(set_name, model, path, targets):
    path, _, selection = path.partition("@")
    keep = selector(selection, path)
    rs = [r for r in rows(path) if keep(r["band_of"])]
    if not rs:
        return f"| {set_name} | {model} | 0 | - | - | - | - | - | - | - | - | - |", [f"{set_name} {model}: no run corrected"]
    failed = []

    def check(name, ok):
        if name in targets and not ok:
            failed.append(f"{set_name} ({model}): {name}")
        return mark(ok) if name in targets else ""

    med_raw = 100 * statistics.median(abs(r["raw_u_err"]) for r in rs)
    med = 100 * statistics.median(abs(r["u_err"]) for r in rs)
    mean_u = 100 * statistics.fmean(r["u_err"] for r in rs)
    mean_tu = statistics.fmean(r["tu_err"] for r in rs)
    median_limit = 1.1 if "u-median-1.1" in targets else 1.5
    median_mark = check("u-median-1.1" if "u-median-1.1" in targets else "u-median-1.5", med <= median_limit)
    tu_limit = 0.005 if "tu-mean-0.005" in targets else 0.01
    tu_mark = check("tu-mean-0.005" if "tu-mean-0.005" in targets else "tu-mean-0.01", abs(mean_tu) <= tu_limit)
    bands = []
    bands_ok = True
    for lo, hi in TU_BANDS:
        b = [r["u_err"] for r in rs if lo <= r["band_of"]["true Tu"] < hi]
        if not b:
            bands.append("-")
        elif len(b) < 10:
            bands.append(f"({100 * statistics.fmean(b):+.2f})")
        else:
            m = 100 * statistics.fmean(b)
            bands_ok &= abs(m) <= 1.0
            bands.append(f"{m:+.2f}")
    bands_cell = " / ".join(bands) + check("bands", bands_ok)
    cov = {k: 100 * statistics.fmean(r[k] for r in rs) for k in ("u80", "u95", "tu80", "tu95")}
    cov_ok = cov["u80"] >= 78 and cov["u95"] >= 93 and cov["tu80"] >= 78 and cov["tu95"] >= 93
    zeros = zero_tu_runs(path, keep)
    line = (f"| {set_name} | {model} | {len(rs)} | {med_raw:.2f} -> {med:.2f}{median_mark} | "
            f"{mean_u:+.2f}{check('u-mean', abs(mean_u) <= 1.0)} | {mean_tu:+.4f}{tu_mark} | {bands_cell} | "
            f"{cov['u80']:.0f} / {cov['u95']:.0f} | {cov['tu80']:.0f} / {cov['tu95']:.0f}{check('coverage', cov_ok)} | "
            f"{zeros}{check('no-zero-tu', zeros == 0)} |")
    return line, failed


def main():
    args = sys.argv[1:]
    if not args or len(args) % 4:
        sys.exit(__doc__.split("\n\n")[-1])
    print("| set | model | runs corrected | u median abs err % (raw -> corr) | u mean err % | Tu mean err | "
          "u mean err % by true Tu 0-0.1 / 0.1-0.2 / 0.2-0.3 / 0.3-0.4 | u coverage 80 / 95 % | "
          "Tu coverage 80 / 95 % | AWCC Tu = 0 |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    failures = []
    for i in range(0, len(args), 4):
        set_name, model, path, targets = args[i:i + 4]
        wanted = set() if targets == "-" else set(targets.split(","))
        unknown = wanted - TARGETS
        if unknown:
            sys.exit(f"unknown target {', '.join(sorted(unknown))}: give some of {', '.join(sorted(TARGETS))}")
        line, failed = row(set_name, model, path, wanted)
        print(line)
        failures += failed
    print()
    print("targets missed: " + ("; ".join(failures) if failures else "none"))


if __name__ == "__main__":
    main()

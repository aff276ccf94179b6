#!/usr/bin/env python3
"""Which arrival rule a real record's bubbles follow, from AWCC's weighting gap
g = u_unweighted / u_duration_weighted - 1
(docs/history/correction-foreign-conventions.md, "Which arrival rule the
real bubbles follow").

When bubbles are spaced along the flow, a window of Np bubbles lasts less
when the flow is fast, so the unweighted mean of the windows' velocities
exceeds the duration-weighted one: g is about the variance of the windows'
velocities over the mean squared (Tu_w^2, less the part that is measurement
noise). When arrivals are set in time, a window's length does not follow its
velocity and g is about 0. This compares the real rows' g with the
campaign's runs of mixed conventions under the same conditions (AWCC Tu,
accepted windows and T_u / T_W in the ranges below, fs at most FS_MAX), by
arrival rule.

Usage: arrival_gap.py WEIGHTED.csv UNWEIGHTED.csv SWEEP.csv [SWEEP.csv ...]
  WEIGHTED.csv, UNWEIGHTED.csv: pdp process --csv of the same recordings with
  --weighting duration and --weighting none; SWEEP.csv: pdp sweep CSVs with the
  columns awcc_velocity_unweighted, awcc_time_scale_ratio and arrival (the
  mixed-convention sweeps).
"""
import csv
import statistics
import sys

TU_RANGE = (0.1, 0.2)        # AWCC's (duration-weighted) Tu of the rows compared
WINDOWS_RANGE = (100, 1000)  # accepted windows: g's noise falls with their number
FS_MAX = 60e3                # the real recordings' 20 kHz and its neighbours
# AWCC's T_u / T_W: where the flow's time scale is short against a window, the
# windows average over many eddies, their velocities scatter mostly by
# measurement noise and g shrinks whatever the arrival rule; the real rows
# are at 0.24-0.38.
RATIO_RANGE = (0.15, 0.6)


def number(row, name):
    try:
        return float(row[name])
    except (KeyError, ValueError):
        return None


def comparable(tu, windows, ratio):
    return None not in (tu, windows, ratio) and TU_RANGE[0] <= tu < TU_RANGE[1] \
        and WINDOWS_RANGE[0] <= windows <= WINDOWS_RANGE[1] and RATIO_RANGE[0] <= ratio < RATIO_RANGE[1]


def reader(path):
    try:
        return csv.DictReader(open(path))
    except OSError as e:
        sys.exit(f"{path}: {e.strerror}")


def main():
    if len(sys.argv) < 4:
        sys.exit(__doc__.split("\n\n")[-1])
    weighted_path, unweighted_path, sweeps = sys.argv[1], sys.argv[2], sys.argv[3:]
    real = []
    weighted = list(reader(weighted_path))
    unweighted = list(reader(unweighted_path))
    if [r.get("file") for r in weighted] != [r.get("file") for r in unweighted]:
        sys.exit(f"{weighted_path}, {unweighted_path}: not the same recordings in the same order")
    for path, rows, weighting in ((weighted_path, weighted, "duration"), (unweighted_path, unweighted, "none")):
        if any(r.get("awcc_weighting") != weighting for r in rows):
            sys.exit(f"{path}: not processed with --weighting {weighting} (its column awcc_weighting)")
    for w, u in zip(weighted, unweighted):
        uw, uu = number(w, "awcc_velocity"), number(u, "awcc_velocity")
        tu, windows = number(w, "awcc_turbulence_intensity"), number(w, "awcc_windows_accepted")
        ratio = number(w, "awcc_time_scale_ratio")
        if uw is None or uu is None:
            continue
        real.append((w.get("position") or w.get("file"), uu / uw - 1, tu, windows, ratio,
                     comparable(tu, windows, ratio)))
    by_rule = {"in time": [], "along the flow": []}
    for path in sweeps:
        rows = reader(path)
        if not {"awcc_velocity_unweighted", "awcc_time_scale_ratio", "arrival", "fs"} <= set(rows.fieldnames or []):
            sys.exit(f"{path}: no columns awcc_velocity_unweighted, awcc_time_scale_ratio, arrival and fs: "
                     "not a pdp sweep CSV of generator version 2 with the time-scale ratio")
        for r in rows:
            if r.get("awcc_weighting", "duration") != "duration":
                continue
            uw, uu = number(r, "awcc_velocity"), number(r, "awcc_velocity_unweighted")
            tu, windows, fs = number(r, "awcc_turbulence_intensity"), number(r, "awcc_windows_accepted"), number(r, "fs")
            ratio = number(r, "awcc_time_scale_ratio")
            if uw is None or uu is None or fs is None or fs > FS_MAX or not comparable(tu, windows, ratio):
                continue
            by_rule["in time" if r["arrival"].endswith("time") else "along the flow"].append(uu / uw - 1)
    print("| real row | g | AWCC Tu | accepted windows | T_u / T_W | compared |")
    print("|---|---|---|---|---|---|")
    for name, g, tu, windows, ratio, ok in real:
        shown = "" if ratio is None else f"{ratio:.2f}"
        print(f"| {name} | {g:+.4f} | {tu:.3f} | {windows:.0f} | {shown} | {'yes' if ok else 'no'} |")
    largest = max((g for _, g, _, _, _, ok in real if ok), default=None)
    if largest is None:
        sys.exit(f"\n{weighted_path}: no row with AWCC Tu {TU_RANGE[0]}-{TU_RANGE[1]}, {WINDOWS_RANGE[0]}-"
                 f"{WINDOWS_RANGE[1]} accepted windows and T_u / T_W {RATIO_RANGE[0]}-{RATIO_RANGE[1]}: "
                 "too few windows to tell the arrival rule (record longer)")
    print(f"\nCampaign runs with AWCC Tu {TU_RANGE[0]}-{TU_RANGE[1]}, {WINDOWS_RANGE[0]}-{WINDOWS_RANGE[1]} "
          f"accepted windows, T_u / T_W {RATIO_RANGE[0]}-{RATIO_RANGE[1]}, fs up to {FS_MAX / 1e3:.0f} kHz:\n")
    print("| arrivals | runs | median g | 5-95 % of g | share at or below the real rows' largest g |")
    print("|---|---|---|---|---|")
    for rule, gs in by_rule.items():
        if len(gs) < 20:
            print(f"| {rule} | {len(gs)} | too few runs | | |")
            continue
        q = statistics.quantiles(gs, n=20)
        share = f"{100 * sum(g <= largest for g in gs) / len(gs):.1f} %"
        print(f"| {rule} | {len(gs)} | {statistics.median(gs):+.4f} | {q[0]:+.4f} to {q[-1]:+.4f} | {share} |")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""How often AWCC's weighting-gap flag (arrivals_along_flow, METHOD 7 (d))
fires, by band of accepted windows, on pdp sweep CSVs: on the sets whose
bubbles arrive spaced along the flow (the stress sets) the share is the
flag's catch rate; on sets with arrivals in time it is its false alarms.

A run is flagged when the 95 % interval of its gap g lies above the
allowance kappa Tu^2 (awcc/weighting_gap.hpp, which owns kappa: read from
there). Where the interval's half-width exceeds the gap arrivals along the
flow give (about 0.9 Tu^2 where windows are shorter than the time scale,
weighting_gap.hpp), the flag cannot tell the rules apart: the column
"half-width / Tu^2" (median) says where that is.

Usage: gap_catch.py NAME SWEEP.csv [NAME SWEEP.csv ...]
"""
import csv
import os
import re
import statistics
import sys

HEADER = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "libawcc", "include", "awcc",
                      "weighting_gap.hpp")
BANDS = [(10, 30, "10-29"), (30, 100, "30-99"), (100, 300, "100-299"), (300, float("inf"), "300+")]


def allowance_factor():
    m = re.search(r"time_arrival_gap_allowance\s*=\s*([0-9.eE+-]+)\s*;", open(HEADER).read())
    if not m:
        sys.exit(f"{HEADER}: no time_arrival_gap_allowance: the rule moved; update gap_catch.py")
    return float(m.group(1))


def runs(path):
    out = []
    for r in csv.DictReader(open(path)):
        try:
            w = float(r["awcc_windows_accepted"])
            tu = float(r["awcc_turbulence_intensity"])
            lo, hi = float(r["awcc_weighting_gap_ci95_lower"]), float(r["awcc_weighting_gap_ci95_upper"])
        except (KeyError, ValueError):
            continue
        if w < 10 or not all(map(lambda x: x == x, (tu, lo, hi))) or tu <= 0:
            continue
        out.append((w, tu, lo, hi))
    return out


def main():
    args = sys.argv[1:]
    if not args or len(args) % 2:
        sys.exit(__doc__.split("\n\n")[-1])
    kappa = allowance_factor()
    print(f"kappa = {kappa} (awcc/weighting_gap.hpp)\n")
    print("| set | accepted windows | runs | flagged | share | half-width / Tu^2 (median) |")
    print("|---|---|---|---|---|---|")
    for i in range(0, len(args), 2):
        name, path = args[i], args[i + 1]
        rs = runs(path)
        for lo_w, hi_w, label in BANDS + [(10, float("inf"), "all")]:
            band = [r for r in rs if lo_w <= r[0] < hi_w]
            if not band:
                continue
            flagged = sum(1 for w, tu, lo, hi in band if lo > kappa * tu * tu)
            half = statistics.median((hi - lo) / 2 / (tu * tu) for w, tu, lo, hi in band)
            print(f"| {name} | {label} | {len(band)} | {flagged} | {100 * flagged / len(band):.1f} % | {half:.2f} |")


if __name__ == "__main__":
    main()

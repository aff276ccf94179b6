#!/usr/bin/env python3
"""The real profile corrected by two models, row by row (issue 51's
must-show: every row corrected or explained, its change stated): for each
recording the raw AWCC velocity each processing gave, the corrected median
velocity with its 95 % interval and the corrected Tu, the forest that
corrected it and the status, or the reason it was not corrected; FSCC's
velocity beside them as the independent check.

Usage: real_profile_change.py OLD_NAME OLD.csv NEW_NAME NEW.csv
  each CSV from pdp process ... --correct MODEL --csv FILE
"""
import csv
import os
import sys


def table(path):
    try:
        return {os.path.basename(r["file"]): r for r in csv.DictReader(open(path))}
    except OSError as e:
        sys.exit(f"{path}: {e.strerror}")


def cell(r):
    if r.get("correction_forest", "") in ("", "none") or r.get("corrected_velocity_q0.5", "") in ("", "nan"):
        return f"not corrected: {r.get('correction_reason', '') or r.get('correction_status', '')}", "-"
    u = (f"{float(r['corrected_velocity_q0.5']):.3f} ({float(r['corrected_velocity_q0.025']):.3f}-"
         f"{float(r['corrected_velocity_q0.975']):.3f}) {r['correction_forest']}")
    tu = r.get("corrected_turbulence_intensity_q0.5", "")
    return u, (f"{float(tu):.3f}" if tu not in ("", "nan") else "-")


def number(r, key):
    v = r.get(key, "")
    return f"{float(v):.3f}" if v not in ("", "nan") else "-"


def main():
    if len(sys.argv) != 5:
        sys.exit(__doc__.split("\n\n")[-1])
    old_name, old, new_name, new = sys.argv[1], table(sys.argv[2]), sys.argv[3], table(sys.argv[4])
    print(f"| file | FSCC u | AWCC u {old_name} -> {new_name} | corrected u (95 %) {old_name} | "
          f"corrected u (95 %) {new_name} | change of the median | corrected Tu {old_name} -> {new_name} |")
    print("|---|---|---|---|---|---|---|")
    for name in sorted(set(old) | set(new)):
        a, b = old.get(name), new.get(name)
        if a is None or b is None:
            print(f"| {name} | in one file only | | | | | |")
            continue
        ua, ta = cell(a)
        ub, tb = cell(b)
        change = "-"
        try:
            change = f"{100 * (float(b['corrected_velocity_q0.5']) / float(a['corrected_velocity_q0.5']) - 1):+.1f} %"
        except (KeyError, ValueError, ZeroDivisionError):
            pass
        print(f"| {name} | {number(b, 'fscc_velocity')} | {number(a, 'awcc_velocity')} -> "
              f"{number(b, 'awcc_velocity')} | {ua} | {ub} | {change} | {ta} -> {tb} |")


if __name__ == "__main__":
    main()

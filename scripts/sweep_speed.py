#!/usr/bin/env python3
"""Runs per core-hour of a pdp sweep CSV, from its rows' own synthesis and
processing seconds (docs/performance.md, issue 32's Monte Carlo table).
Usage: sweep_speed.py SWEEP.csv ...
"""
import csv, statistics as st, sys
for n in sys.argv[1:]:
    rows = list(csv.DictReader(open(n)))
    s = [float(r["seconds_synth"]) for r in rows if r["seconds_synth"]]
    p = [float(r["seconds_process"]) for r in rows if r["seconds_process"]]
    tot = sum(s) + sum(p)
    print(f"{n}: {len(rows)} runs, mean synthesis {st.mean(s):.3f} s, mean processing {st.mean(p):.3f} s, "
          f"run {tot/len(rows):.3f} s, {3600*len(rows)/tot:.0f} runs per core-hour, failed {sum(1 for r in rows if not r['seconds_synth'])}")

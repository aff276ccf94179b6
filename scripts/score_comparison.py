#!/usr/bin/env python3
"""One model's scores on two sets of runs (pdp score --predictions), side by side
with their standard errors and the difference in units of them: whether the
model scores the same on both (e.g. runs of generator versions 1 and 2 from
one sweep definition, docs/validation.md "Generator version 2").

Scores over the corrected rows: median |u / u_true - 1| and mean u error of
the corrected median, the same for Tu (absolute), and the coverage of the 80
and 95 % intervals. Standard errors by the bootstrap (2,000 resamples of the
rows, seed 0); coverage's is also sqrt(p (1 - p) / n). The two sets are
independent, so z = (b - a) / sqrt(se_a^2 + se_b^2).

With --paired the two files are two models' predictions of the same runs
(candidate models, docs/history/correction-foreign-conventions.md "The time
scale: a feature the record carries"): only the rows both
corrected are scored (a row is a run and its weighting), and the standard
error is that of the difference, from resampling the rows as pairs, so the
runs' own spread cancels. --bands adds the paired medians and coverages band
by band (accepted windows, sampling rate, true Tu, record length: the bands
of pdp score's report), for "no band worse than today's".

Usage: score_comparison.py [--paired [--bands]] NAME_A PREDICTIONS_A.csv NAME_B PREDICTIONS_B.csv
"""
import csv
import math
import random
import statistics
import sys


NEEDED = ["run", "status", "velocity", "turbulence_intensity", "dx", "true_velocity", "true_turbulence_intensity", "windows_accepted", "fs", "duration"] + [
    f"corrected_{q}_q{p}" for q in ("velocity", "turbulence_intensity") for p in ("0.025", "0.1", "0.5", "0.9", "0.975")]


def rows(path):
    out = []
    seen = {}
    try:
        reader = csv.DictReader(open(path))
        missing = [c for c in NEEDED if c not in (reader.fieldnames or [])]
    except OSError as e:
        sys.exit(f"{path}: {e.strerror}")
    if missing:
        sys.exit(f"{path}: no column {', '.join(missing)}: not a pdp score --predictions file "
                 "(write one with pdp score -m MODEL SWEEP.csv --predictions FILE)")
    for r in reader:
        # A row's key: its run, its weighting and which of the rows with
        # those it is (held-out runs of several sweeps share run numbers;
        # two models trained on the same sweeps list them in one order).
        run = (r["run"], r.get("awcc_unweighted", ""))
        seen[run] = seen.get(run, 0) + 1
        if r["status"] != "corrected":
            continue
        q = lambda name: float(r[name])
        u, tu = q("true_velocity"), q("true_turbulence_intensity")
        out.append({
            "key": run + (seen[run],),
            "band_of": {"windows": q("windows_accepted"), "fs": q("fs"), "true Tu": tu,
                        "duration": q("duration"),
                        # AWCC's lag in samples, from what it measured
                        "lag": q("fs") * q("dx") / q("velocity")},
            "truth": (r["true_velocity"], r["true_turbulence_intensity"]),
            "raw_u_err": q("velocity") / u - 1.0,
            "raw_tu_err": q("turbulence_intensity") - tu,
            "u_err": q("corrected_velocity_q0.5") / u - 1.0,
            "tu_err": q("corrected_turbulence_intensity_q0.5") - tu,
            "u80": q("corrected_velocity_q0.1") <= u <= q("corrected_velocity_q0.9"),
            "u95": q("corrected_velocity_q0.025") <= u <= q("corrected_velocity_q0.975"),
            "tu80": q("corrected_turbulence_intensity_q0.1") <= tu <= q("corrected_turbulence_intensity_q0.9"),
            "tu95": q("corrected_turbulence_intensity_q0.025") <= tu <= q("corrected_turbulence_intensity_q0.975"),
        })
    return out


SCORES = [
    ("u median abs error (%)", lambda rs: 100 * statistics.median(abs(r["u_err"]) for r in rs)),
    ("u mean error (%)", lambda rs: 100 * statistics.fmean(r["u_err"] for r in rs)),
    ("Tu median abs error", lambda rs: statistics.median(abs(r["tu_err"]) for r in rs)),
    ("Tu mean error", lambda rs: statistics.fmean(r["tu_err"] for r in rs)),
    ("u 80 % coverage (%)", lambda rs: 100 * statistics.fmean(r["u80"] for r in rs)),
    ("u 95 % coverage (%)", lambda rs: 100 * statistics.fmean(r["u95"] for r in rs)),
    ("Tu 80 % coverage (%)", lambda rs: 100 * statistics.fmean(r["tu80"] for r in rs)),
    ("Tu 95 % coverage (%)", lambda rs: 100 * statistics.fmean(r["tu95"] for r in rs)),
]


def bootstrap_se(rs, f, rng, n=2000):
    values = [f([rs[rng.randrange(len(rs))] for _ in rs]) for _ in range(n)]
    return statistics.stdev(values)


def common_rows(a, b):
    """The rows both files corrected, as two lists in one order."""
    a_by = {r["key"]: r for r in a}
    b_by = {r["key"]: r for r in b}
    keys = sorted(set(a_by) & set(b_by))
    if any(a_by[k]["truth"] != b_by[k]["truth"] for k in keys):
        sys.exit("--paired: the two files' rows are not the same runs (their truths differ)")
    return [a_by[k] for k in keys], [b_by[k] for k in keys]


def paired_difference(pa, pb, f, rng, resamples):
    """Score f on both, and the standard error of b - a from resampling the pairs."""
    diffs = []
    for _ in range(resamples):
        idx = [rng.randrange(len(pa)) for _ in pa]
        diffs.append(f([pb[i] for i in idx]) - f([pa[i] for i in idx]))
    return f(pa), f(pb), statistics.stdev(diffs)


def paired(a_name, a, b_name, b):
    pa, pb = common_rows(a, b)
    rng = random.Random(0)
    print(f"rows both corrected: {len(pa)} (of {len(a)} and {len(b)})\n")
    print(f"| score | {a_name} | {b_name} | difference +- se | z |")
    print("|---|---|---|---|---|")
    for name, f in SCORES:
        va, vb, se = paired_difference(pa, pb, f, rng, 2000)
        digits = 4 if name.startswith("Tu m") else 2
        z = (vb - va) / se if se > 0 else float("nan")
        print(f"| {name} | {va:.{digits}f} | {vb:.{digits}f} | {vb - va:+.{digits}f} +- {se:.{digits}f} | {z:+.2f} |")


# The bands of pdp score's report (libcorrection's held-out bands), by the
# quantity each is cut on; an unknown value (NaN: a peer's row) falls in none.
BANDS = [
    ("windows", "windows", [(10, 30, "10-29"), (30, 100, "30-99"), (100, math.inf, "100+")]),
    ("fs", "fs", [(0, 50e3, "0-50 kHz"), (50e3, 200e3, "50-200 kHz"), (200e3, math.inf, "200 kHz+")]),
    ("true Tu", "true Tu", [(0, 0.1, "0-0.1"), (0.1, 0.2, "0.1-0.2"), (0.2, 0.3, "0.2-0.3"),
                            (0.3, 0.35, "0.3-0.35"), (0.35, math.inf, "0.35-0.45")]),
    ("duration", "duration", [(0, 60, "0-60 s"), (60, 300, "60-300 s"), (300, math.inf, "300 s+")]),
]

BAND_SCORES = [SCORES[0], SCORES[2], SCORES[4], SCORES[6]]


def paired_bands(a_name, a, b_name, b):
    pa_all, pb_all = common_rows(a, b)
    rng = random.Random(0)
    print(f"\nBand by band, {b_name} minus {a_name} (+- the paired bootstrap's standard error):\n")
    print("| band | rows | " + " | ".join(n for n, _ in BAND_SCORES) + " |")
    print("|---|---|" + "---|" * len(BAND_SCORES))
    for title, field, cuts in BANDS:
        for lo, hi, label in cuts:
            idx = [i for i, r in enumerate(pa_all) if lo <= r["band_of"][field] < hi]
            if len(idx) < 10:
                continue
            pa, pb = [pa_all[i] for i in idx], [pb_all[i] for i in idx]
            cells = []
            for name, f in BAND_SCORES:
                va, vb, se = paired_difference(pa, pb, f, rng, 1000)
                d = 4 if name.startswith("Tu m") else 2
                cells.append(f"{va:.{d}f} -> {vb:.{d}f} ({vb - va:+.{d}f} +- {se:.{d}f})")
            print(f"| {title} {label} | {len(pa)} | " + " | ".join(cells) + " |")


USAGE = "usage: score_comparison.py [--paired [--bands]] NAME_A PREDICTIONS_A.csv NAME_B PREDICTIONS_B.csv"


def main():
    args = sys.argv[1:]
    options = [a for a in args if a.startswith("--")]
    if options not in ([], ["--paired"], ["--paired", "--bands"]) or args[:len(options)] != options \
            or len(args) != len(options) + 4:
        sys.exit(USAGE + ("\n--bands needs --paired: bands compare two models on the same runs"
                          if "--bands" in options and "--paired" not in options else ""))
    if args and args[0] == "--paired":
        bands = len(args) > 1 and args[1] == "--bands"
        a_name, a_path, b_name, b_path = args[2:6] if bands else args[1:5]
        a, b = rows(a_path), rows(b_path)
        paired(a_name, a, b_name, b)
        if bands:
            paired_bands(a_name, a, b_name, b)
        return
    a_name, a_path, b_name, b_path = args[0:4]
    a, b = rows(a_path), rows(b_path)
    rng = random.Random(0)
    print(f"| score | {a_name} ({len(a)} rows) | {b_name} ({len(b)} rows) | z |")
    print("|---|---|---|---|")
    worst = 0.0
    for name, f in SCORES:
        va, vb = f(a), f(b)
        sa, sb = bootstrap_se(a, f, rng), bootstrap_se(b, f, rng)
        z = (vb - va) / math.hypot(sa, sb)
        worst = max(worst, abs(z))
        digits = 4 if name.startswith("Tu m") else 2
        print(f"| {name} | {va:.{digits}f} +- {sa:.{digits}f} | {vb:.{digits}f} +- {sb:.{digits}f} | {z:+.2f} |")
    print(f"\nlargest |z|: {worst:.2f}")


if __name__ == "__main__":
    main()

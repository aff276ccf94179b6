#!/usr/bin/env python3
"""Compares two generator versions' sweeps point by point (scripts/generator-comparison).

Each point of a study (its grid values) has 10 runs per build; the runs of
the two builds share their seeds but not their streams, so they are
independent samples of the same statistics if the generator change keeps
them. For every quantity the difference of the means is divided by its
standard error sqrt(s_b^2 / n_b + s_a^2 / n_a): Student t with about 18
degrees of freedom when nothing shifted (P(|t| > 2) = 0.061, P(|t| > 3) =
0.0077). The studies share their seed, so a scene that several studies hold
(the base case is a point of every study; fs and Np change no truth) gives
the same runs in each: such a comparison is counted once. 4 is the bound
used (a two-sided Bonferroni bound at 5 % over some 200 comparisons, for t
with 18 degrees of freedom, is 3.9).

Usage: generator_comparison.py OUT_DIR (holds before-NAME.csv, after-NAME.csv, studies/NAME.toml)
"""
import csv
import math
import pathlib
import sys
import tomllib

QUANTITIES = [
    ("awcc_velocity_error", "AWCC u error", 100.0, "%"),
    ("awcc_turbulence_intensity_error", "AWCC Tu error", 100.0, "%"),
    ("fscc_velocity_error", "FSCC u error", 100.0, "%"),
    ("windows_share", "windows accepted", 100.0, "%"),
    ("truth_void_fraction", "realised c", 1.0, ""),
    ("truth_count_rate", "realised F", 1.0, "1/s"),
]
BOUND = 4.0


def value(row, key):
    if key == "windows_share":
        a, t = row.get("awcc_windows_accepted", ""), row.get("awcc_windows_total", "")
        return float(a) / float(t) if a and t and float(t) > 0 else None
    v = row.get(key, "")
    return float(v) if v not in ("", None) else None


def stats(xs):
    n = len(xs)
    if n < 2:
        return n, float("nan"), float("nan")
    m = sum(xs) / n
    s2 = sum((x - m) ** 2 for x in xs) / (n - 1)
    return n, m, math.sqrt(s2 / n)


def points(path, keys):
    groups = {}
    with open(path, newline="") as f:
        for row in csv.DictReader(f):
            point = tuple(row[k.replace("-", "_")] for k in keys)
            groups.setdefault(point, []).append(row)
    return groups


def sort_key(point):
    def number(x):
        try:
            return (0, float(x), "")
        except ValueError:
            return (1, 0.0, x)
    return [number(x) for x in point]


def main():
    out = pathlib.Path(sys.argv[1])
    lines = ["| study | point | quantity | before (mean +- SE, n) | after (mean +- SE, n) | z |", "|---|---|---|---|---|---|"]
    zs = []
    seen = set()
    for study in sorted((out / "studies").glob("*.toml")):
        name = study.stem
        keys = list(tomllib.loads(study.read_text())["grid"].keys())
        before = points(out / f"before-{name}.csv", keys)
        after = points(out / f"after-{name}.csv", keys)
        for point in sorted(before, key=sort_key):
            label = ", ".join(f"{k} {v}" for k, v in zip(keys, point))
            for key, title, scale, unit in QUANTITIES:
                b = [v for v in (value(r, key) for r in before[point]) if v is not None]
                a = [v for v in (value(r, key) for r in after.get(point, [])) if v is not None]
                nb, mb, sb = stats(b)
                na, ma, sa = stats(a)
                se = math.hypot(sb, sa)
                z = (ma - mb) / se if se > 0 else (0.0 if ma == mb else float("nan"))
                same_runs = (key, tuple(sorted(b)), tuple(sorted(a)))
                if not math.isnan(z) and same_runs not in seen:
                    seen.add(same_runs)
                    zs.append((abs(z), name, label, title))
                fmt = "{:+.2f}" if unit == "%" else "{:.4g}"
                cell = lambda n, m, s: f"{fmt.format(scale * m)} +- {scale * s:.2g} ({n})" if n >= 2 else f"n/a ({n})"
                lines.append(f"| {name} | {label} | {title} | {cell(nb, mb, sb)} | {cell(na, ma, sa)} | {z:+.2f} |")
    (out / "comparison.md").write_text("\n".join(lines) + "\n")
    zs.sort(reverse=True)
    beyond = [z for z in zs if z[0] > BOUND]
    print(f"{len(zs)} distinct comparisons; |z| > 2: {sum(z[0] > 2 for z in zs)} (expected about {0.061 * len(zs):.0f}); "
          f"|z| > 3: {sum(z[0] > 3 for z in zs)} (expected about {0.0077 * len(zs):.1f}); largest:")
    for z in zs[:5]:
        print(f"  {z[0]:.2f}  {z[1]}: {z[2]}: {z[3]}")
    print(f"table: {out / 'comparison.md'}")
    return 1 if beyond else 0


if __name__ == "__main__":
    sys.exit(main())

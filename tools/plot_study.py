#!/usr/bin/python3
"""Figures from pdp's study CSVs (Debian's python3 with matplotlib).

  plot_study.py bench BENCH.csv OUT.png
      error against run time: |velocity error| and |Tu error| of every method
      and setting, log-log, one colour per method.
  plot_study.py sweep RUNS.csv PARAMETER OUT.png [--title TEXT]
      the relative errors of the AWCC and FSCC mean velocity and of the AWCC
      turbulence intensity against one swept parameter (a CSV column), as
      means with 95 % intervals (Student t) over the repetitions.
  plot_study.py windows RUNS.csv OUT.png
      AWCC windows kept against the parameter-free truth: accepted fraction
      against the true turbulence intensity.
  plot_study.py correction PREDICTIONS.csv OUT.png
      held-out runs of pdp train --predictions: measured (raw AWCC) and
      corrected median against the truth, velocity and turbulence intensity,
      with the corrected 80 % intervals.
  plot_study.py learning LEARNING.csv OUT.png
      held-out scores of pdp train --learning-curve against training runs.

Every figure carries the command line that made it in its footer.
"""
import csv
import math
import os
import sys
from collections import defaultdict

# One plotting layer: the style, palette, Student t and footer are pdp.plotting's
# (python/pdp/plotting.py), imported as a plain file so no compiled module is needed.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python", "pdp"))
import plotting  # noqa: E402
from plotting import number, t975  # noqa: E402


def subplots(rows=1, cols=1, figsize=(7, 4.5)):
    fig, axes = plotting.figure(width=figsize[0], height=figsize[1], rows=rows, cols=cols)
    if rows == 1 and cols == 1:
        return fig, axes[0][0]
    if rows == 1 or cols == 1:
        return fig, [a for row in axes for a in row]
    return fig, axes


def footer(fig):
    plotting.footer(fig, "made by: " + " ".join(["tools/plot_study.py"] + sys.argv[1:]))


def bench(path, out):
    rows = list(csv.DictReader(open(path)))
    if not rows:
        raise SystemExit(f"{path}: no rows")
    fig, axes = subplots(1, 2, figsize=(11, 4.5))
    methods = sorted({r["method"] for r in rows})
    colours = {m: plotting.PALETTE[i % len(plotting.PALETTE)] for i, m in enumerate(methods)}
    for ax, column, label in ((axes[0], "velocity_error", "|mean velocity error|"),
                              (axes[1], "turbulence_intensity_error", "|turbulence intensity error|")):
        for m in methods:
            xs, ys = [], []
            for r in rows:
                e, t = number(r[column]), number(r["seconds"])
                if r["method"] == m and e is not None and t:
                    xs.append(t)
                    ys.append(max(abs(e), 1e-4))
            ax.scatter(xs, ys, label=m, color=colours[m], s=18)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("run time per record (s)")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle("Error against run time (pdp bench)")
    footer(fig)
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    fig.savefig(out, dpi=120)


def sweep(path, parameter, out, title):
    rows = list(csv.DictReader(open(path)))
    if not rows or parameter not in rows[0]:
        raise SystemExit(f"{path}: no column '{parameter}'")
    series = {"AWCC mean velocity": "awcc_velocity_error", "FSCC mean velocity": "fscc_velocity_error",
              "AWCC turbulence intensity": "awcc_turbulence_intensity_error"}
    fig, ax = subplots(figsize=(7, 4.5))
    for label, column in series.items():
        groups = defaultdict(list)
        for r in rows:
            x, e = number(r[parameter]), number(r[column])
            if x is not None and e is not None:
                groups[x].append(100.0 * e)
        xs = sorted(groups)
        means, halves = [], []
        for x in xs:
            v = groups[x]
            m = sum(v) / len(v)
            sd = math.sqrt(sum((e - m) ** 2 for e in v) / (len(v) - 1)) if len(v) > 1 else 0.0
            means.append(m)
            halves.append(t975(len(v) - 1) * sd / math.sqrt(len(v)) if len(v) > 1 else 0.0)
        ax.errorbar(xs, means, yerr=halves, marker="o", capsize=3, label=label)
    ax.axhline(0.0, color="black", linewidth=0.8)
    ax.set_xlabel(parameter)
    ax.set_ylabel("relative error (%), mean and 95 % interval")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(title or f"Error against {parameter}")
    footer(fig)
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    fig.savefig(out, dpi=120)


def windows(path, out):
    rows = list(csv.DictReader(open(path)))
    xs, ys = [], []
    for r in rows:
        a, t, tu = number(r["awcc_windows_accepted"]), number(r["awcc_windows_total"]), number(
            r["truth_turbulence_intensity"])
        if a is not None and t and tu is not None:
            xs.append(tu)
            ys.append(a / t)
    fig, ax = subplots(figsize=(7, 4.5))
    ax.scatter(xs, ys, s=10)
    ax.set_xlabel("true turbulence intensity")
    ax.set_ylabel("fraction of AWCC windows accepted")
    ax.grid(True, alpha=0.3)
    footer(fig)
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    fig.savefig(out, dpi=120)


def correction(path, out):
    rows = [r for r in csv.DictReader(open(path)) if r["in_range"] == "1"]
    if not rows:
        raise SystemExit(f"{path}: no corrected rows")
    fig, axes = subplots(2, 2, figsize=(11, 9))
    for col, (q, label) in enumerate((("velocity", "velocity"), ("turbulence_intensity", "turbulence intensity"))):
        truth = [float(r["true_" + q]) for r in rows]
        raw = [float(r[q]) for r in rows]
        med = [float(r[f"corrected_{q}_q0.5"]) for r in rows]
        lo = [float(r[f"corrected_{q}_q0.1"]) for r in rows]
        hi = [float(r[f"corrected_{q}_q0.9"]) for r in rows]
        if q == "velocity":
            # Relative to the truth: velocities span 1-50 m/s.
            raw = [a / t for a, t in zip(raw, truth)]
            med = [a / t for a, t in zip(med, truth)]
            lo = [a / t for a, t in zip(lo, truth)]
            hi = [a / t for a, t in zip(hi, truth)]
            ylabel = "estimate / true velocity"
            ref = [1.0] * len(truth)
        else:
            ylabel = "estimated turbulence intensity"
            ref = truth
        for row, (values, name) in enumerate(((raw, "raw AWCC"), (med, "corrected median"))):
            ax = axes[row][col]
            if row == 1:
                ax.vlines(truth, lo, hi, color="tab:orange", alpha=0.25, lw=0.8, label="80 % interval")
            ax.scatter(truth, values, s=6, color="tab:blue" if row == 0 else "tab:green", label=name)
            order = sorted(range(len(truth)), key=lambda i: truth[i])
            ax.plot([truth[i] for i in order], [ref[i] for i in order], color="k", lw=0.8)
            if q == "velocity":
                ax.set_xscale("log")
                ax.set_ylim(0.5, 1.5)
            err = [(v - r) for v, r in zip(values, ref)]
            rmse = math.sqrt(sum(e * e for e in err) / len(err))
            ax.set_title(f"{label}: {name} (RMSE {rmse:.3g}{' relative' if q == 'velocity' else ''})", fontsize=10)
            ax.set_xlabel(f"true {label}" + (" (m/s)" if q == "velocity" else ""))
            ax.set_ylabel(ylabel)
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=8, loc="upper right")
    footer(fig)
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    fig.savefig(out, dpi=110)


def learning(path, out):
    rows = list(csv.DictReader(open(path)))
    if not rows:
        raise SystemExit(f"{path}: no points (too few training runs)")
    n = [int(r["training_runs"]) for r in rows]
    fig, axes = subplots(1, 2, figsize=(11, 4.2))
    for ax, (key, label) in zip(axes, (("velocity", "velocity (relative)"), ("tu", "turbulence intensity"))):
        ax.plot(n, [float(r[f"{key}_pinball"]) for r in rows], "o-", label="pinball loss (quantiles)")
        ax.plot(n, [float(r[f"{key}_rmse_corrected"]) for r in rows], "s-", label="RMSE of the median")
        ax.plot(n, [float(r[f"{key}_rmse_raw"]) for r in rows], "k--", lw=0.8, label="RMSE of raw AWCC")
        ax.set_xscale("log")
        if all(float(r[f"{key}_{c}"]) > 0 for r in rows for c in ("pinball", "rmse_corrected", "rmse_raw")):
            ax.set_yscale("log")
        ax.set_xlabel("training runs")
        ax.set_title(f"held-out score: {label}", fontsize=10)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    footer(fig)
    fig.tight_layout(rect=(0, 0.03, 1, 1))
    fig.savefig(out, dpi=110)


def main(argv):
    if len(argv) >= 4 and argv[1] == "bench":
        bench(argv[2], argv[3])
    elif len(argv) >= 5 and argv[1] == "sweep":
        title = argv[argv.index("--title") + 1] if "--title" in argv else None
        sweep(argv[2], argv[3], argv[4], title)
    elif len(argv) >= 4 and argv[1] == "windows":
        windows(argv[2], argv[3])
    elif len(argv) >= 4 and argv[1] == "correction":
        correction(argv[2], argv[3])
    elif len(argv) >= 4 and argv[1] == "learning":
        learning(argv[2], argv[3])
    else:
        raise SystemExit(__doc__)


if __name__ == "__main__":
    main(sys.argv)

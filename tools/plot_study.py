#!/usr/bin/python3
"""Figures from pdp's study CSVs (Debian's python3 with matplotlib).

  plot_study.py bench BENCH.csv OUT.png
      error against cost, per scene: the RMS error over the seeds of u and of
      Tu of every method and setting against its processing cost, the Pareto
      front drawn and labelled, the goals (5 % in u, 10 % in Tu) marked; prints
      per scene the shortest record and the cheapest setting reaching each goal.
  plot_study.py bench-bias BENCH.csv OUT.png
      the duration series split into bias and spread against record length.
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
  plot_study.py design RANKED.csv OUT.png [--np N]
      pdp design's maps over (dx, dy), one row per condition: raw AWCC's u
      and Tu biases (the mechanisms) and the RMS errors ranked on, at the
      recommended candidate's Np, fs and duration (or at Np N); the maps of
      pdp design --report, drawn by its code.

Every figure carries the command line that made it in its footer.
"""
import csv
import math
import os
import statistics
import sys
from collections import defaultdict

# One plotting layer: the style, palette, Student t and footer are pdp.plotting's
# (python/pdp/plotting.py), imported as a plain file so no compiled module is needed.
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "python", "pdp"))
import plotting  # noqa: E402
from matplotlib import ticker  # noqa: E402
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


METHOD_LABELS = {
    "fscc": "FSCC",
    "awcc-intervals": "AWCC",
    "awcc-fft": "AWCC FFT",
    "awcc-raw": "AWCC raw",
    "awcc-intervals+qrf": "AWCC+QRF",
}
MARKERS = {"fscc": "s", "awcc-intervals": "o", "awcc-fft": "D", "awcc-raw": "^", "awcc-intervals+qrf": "*"}
GOALS = {"velocity": 0.05, "turbulence_intensity": 0.10}


def setting_label(s):
    """Short name of a setting: method, then what differs from Np = 10, 500 kHz."""
    parts = [METHOD_LABELS.get(s["method"], s["method"])]
    if s["method"] != "fscc" and s["np"] != 10:
        parts.append(f"Np {s['np']}")
    if s["fs"] != 500e3:
        parts.append(f"{s['fs'] / 1e3:g} kHz")
    parts.append(f"{s['duration']:g} s")
    return " ".join(parts)


def log_percent_axis(axis):
    """Ticks at 1, 2 and 5 of each decade, written as plain numbers (a range
    within one decade still gets labels)."""
    axis.set_major_locator(ticker.LogLocator(subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
    axis.set_minor_formatter(ticker.NullFormatter())


def bench_summary(rows):
    """Per scene and setting (method, Np, fs, duration): over the seeds, the
    relative errors' RMS, mean (bias) and standard deviation (spread, n - 1),
    the median cost, and how many seeds gave a value. RMS^2 = bias^2 +
    spread^2 (n - 1)/n, so a bias that does not shrink with the record length
    shows as an RMS floor."""
    groups = defaultdict(list)
    for r in rows:
        key = (r["scene"], r["method"], int(r["np"]), float(r["fs"]), float(r["duration"]))
        groups[key].append(r)
    out = []
    for (scene, method, np_, fs, duration), rs in groups.items():
        s = {"scene": scene, "method": method, "np": np_, "fs": fs, "duration": duration, "seeds": len(rs),
             "cost": statistics.median(float(r["seconds"]) for r in rs)}
        for q in ("velocity", "turbulence_intensity"):
            e = [number(r[q + "_error"]) for r in rs]
            e = [x for x in e if x is not None]
            s[q + "_n"] = len(e)
            if e:
                s[q + "_rms"] = math.sqrt(sum(x * x for x in e) / len(e))
                s[q + "_bias"] = sum(e) / len(e)
                s[q + "_spread"] = statistics.stdev(e) if len(e) > 1 else 0.0
        out.append(s)
    return out


def complete(s, q):
    """A setting counts only when every seed gave a value."""
    return s.get(q + "_n", 0) == s["seeds"] and s["seeds"] > 0


def pareto_front(settings, q):
    """The settings no other beats in both cost and RMS error, cheapest first."""
    front, best = [], math.inf
    for s in sorted((s for s in settings if complete(s, q)), key=lambda s: (s["cost"], s[q + "_rms"])):
        if s[q + "_rms"] < best:
            front.append(s)
            best = s[q + "_rms"]
    return front


def decision(settings, q):
    """The shortest record that reaches the goal (any method), and the cheapest
    setting that does; None when none does."""
    ok = [s for s in settings if complete(s, q) and s[q + "_rms"] <= GOALS[q]]
    if not ok:
        return None
    shortest = min(ok, key=lambda s: (s["duration"], s["cost"]))
    cheapest = min(ok, key=lambda s: (s["cost"], s["duration"]))
    return shortest, cheapest


def bench_table(summary, scenes):
    lines = ["| scene | u: RMS <= 5 %: shortest record | u: cheapest | Tu: RMS <= 10 %: shortest record | Tu: cheapest |",
             "|---|---|---|---|---|"]
    for scene in scenes:
        cells = [scene]
        for q in ("velocity", "turbulence_intensity"):
            d = decision([s for s in summary if s["scene"] == scene], q)
            if d is None:
                cells += ["none reaches it", "none"]
                continue
            for s in d:
                cells.append(f"{setting_label(s)} ({100 * s[q + '_rms']:.1f} %, {s['cost']:.3g} s)")
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def bench(path, out):
    rows = list(csv.DictReader(open(path)))
    if not rows:
        raise SystemExit(f"{path}: no rows")
    summary = bench_summary(rows)
    scenes = list(dict.fromkeys(r["scene"] for r in rows))
    methods = [m for m in METHOD_LABELS if any(s["method"] == m for s in summary)]
    colours = {m: plotting.PALETTE[i % len(plotting.PALETTE)] for i, m in enumerate(methods)}
    seeds = max(s["seeds"] for s in summary)
    fig, axes = plotting.figure(width=10.5, height=2.6 * len(scenes) + 0.6, rows=len(scenes), cols=2,
                                margins=(0.75, 0.6, 0.15, 0.35))
    for i, scene in enumerate(scenes):
        mine = [s for s in summary if s["scene"] == scene]
        for j, (q, name) in enumerate((("velocity", "mean velocity"), ("turbulence_intensity", "Tu"))):
            ax = axes[i][j]
            for m in methods:
                pts = [s for s in mine if s["method"] == m and complete(s, q)]
                ax.scatter([s["cost"] for s in pts], [100 * s[q + "_rms"] for s in pts], marker=MARKERS[m],
                           color=colours[m], s=22, label=METHOD_LABELS[m], alpha=0.85, linewidths=0)
            front = pareto_front(mine, q)
            if front:
                ax.step([s["cost"] for s in front], [100 * s[q + "_rms"] for s in front], where="post",
                        color=plotting.BLACK, lw=1.0, ls="--", label="Pareto front")
                for s in front:
                    ax.annotate(setting_label(s), (s["cost"], 100 * s[q + "_rms"]), fontsize=6,
                                xytext=(3, 3), textcoords="offset points")
            ax.axhline(100 * GOALS[q], color=plotting.VERMILION, lw=0.8, ls=":")
            ax.set_xscale("log")
            ax.set_yscale("log")
            log_percent_axis(ax.yaxis)
            ax.set_title(f"{scene}: {name}, RMS error over {seeds} seeds", fontsize=9)
            ax.set_ylabel(f"RMS error of {'u' if q == 'velocity' else 'Tu'} (%)")
            if i == len(scenes) - 1:
                ax.set_xlabel("processing cost per record (CPU s)")
            ax.grid(True, which="major", alpha=0.3)
    axes[0][0].legend(fontsize=7, loc="upper right")
    footer(fig)
    fig.savefig(out, dpi=110)
    print(bench_table(summary, scenes))


def bench_bias(path, out):
    """Bias and spread of the duration series (500 kHz, Np = 10) against the
    record length, per scene: the spread falls as 1/sqrt(T), the bias stays."""
    summary = bench_summary(list(csv.DictReader(open(path))))
    scenes = list(dict.fromkeys(s["scene"] for s in summary))
    fig, axes = plotting.figure(width=10.5, height=2.4 * len(scenes) + 0.6, rows=len(scenes), cols=2,
                                margins=(0.75, 0.6, 0.15, 0.35))
    for i, scene in enumerate(scenes):
        for j, (q, name) in enumerate((("velocity", "u"), ("turbulence_intensity", "Tu"))):
            ax = axes[i][j]
            for k, m in enumerate(("awcc-intervals", "fscc", "awcc-intervals+qrf")):
                pts = sorted((s for s in summary if s["scene"] == scene and s["method"] == m and s["fs"] == 500e3
                              and s["np"] in (0, 10) and complete(s, q)), key=lambda s: s["duration"])
                if not pts:
                    continue
                c = plotting.PALETTE[k]
                d = [s["duration"] for s in pts]
                ax.plot(d, [100 * abs(s[q + "_bias"]) for s in pts], "-o", color=c, ms=3,
                        label=f"{METHOD_LABELS[m]} |bias|")
                ax.plot(d, [100 * s[q + "_spread"] for s in pts], "--s", color=c, ms=3,
                        label=f"{METHOD_LABELS[m]} spread")
                if m == "awcc-intervals":
                    ref = pts[0][q + "_spread"] * 100
                    ax.plot(d, [ref * math.sqrt(d[0] / x) for x in d], ":", color=plotting.BLACK, lw=0.8,
                            label="1/sqrt(T)")
            ax.set_xscale("log")
            ax.set_yscale("log")
            log_percent_axis(ax.yaxis)
            ax.set_title(f"{scene}: {name}", fontsize=9)
            ax.set_ylabel("error (%)")
            if i == len(scenes) - 1:
                ax.set_xlabel("record duration (s)")
            ax.grid(True, which="major", alpha=0.3)
    axes[0][1].legend(fontsize=6, ncol=2)
    footer(fig)
    fig.savefig(out, dpi=110)


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


def design(path, out, np_=None):
    import matplotlib
    import design_report as page  # python/pdp/design_report.py, beside plotting
    candidates, conditions, _ = page.read_ranked(path)
    best = candidates[0]
    setting = ((np_ if np_ is not None else best.np),) + best.setting[1:]
    at = {c.geometry: c for c in candidates if c.setting == setting}
    if not at:
        raise SystemExit(f"{path}: no candidate at Np {setting[0]}")
    currents = [c for c in candidates if c.current]
    layout = page.Layout([c.geometry for c in candidates], currents[0].geometry if currents else None)
    first = next(c for c in candidates if c.setting == setting)  # the best at this setting
    marks = [("recommended", first.geometry)] + ([("current", currents[0].geometry)] if currents else [])
    order = [2, 3, 0, 1]  # the biases (mechanisms) first, then what is ranked on
    with matplotlib.rc_context(page.MAP_FONTS):
        height = 2.8 * len(conditions) + 0.7
        fig, axes = plotting.figure(width=3.3 * 4 + 0.6, height=height, rows=len(conditions), cols=4)
        for i, name in enumerate(conditions):
            for j, q in enumerate(order):
                column, title, diverging = page.MAP_QUANTITIES[q]
                values = {}
                for g in layout.geometries:
                    v = at[g].conditions.get(name, {}).get(column) if g in at else None
                    values[g] = None if v is None else 100 * v
                cmap = matplotlib.colormaps[page.DIVERGING_MAP if diverging else page.SEQUENTIAL_MAP]
                norm = page._norm(list(values.values()), diverging)
                ax = axes[i][j]
                mesh, _ = page._map(ax, layout, values, norm, cmap, diverging, marks, fontsize=6.5)
                ax.set_title(f"{name}: {title} (%)")
                fig.colorbar(mesh, ax=ax, fraction=0.05, pad=0.03)
        fig.subplots_adjust(wspace=0.55, hspace=0.5, top=1 - 0.6 / height, bottom=0.55 / height, left=0.05,
                            right=0.97)
        fig.suptitle(f"Np {setting[0]}, {setting[1] / 1e3:g} kHz, {setting[2]:g} s; box: the best geometry at this "
                     f"Np{', dashed: the current probe' if currents else ''}", fontsize=9)
    footer(fig)
    fig.savefig(out, dpi=110)


def main(argv):
    if len(argv) >= 4 and argv[1] == "bench":
        bench(argv[2], argv[3])
    elif len(argv) >= 4 and argv[1] == "bench-bias":
        bench_bias(argv[2], argv[3])
    elif len(argv) >= 5 and argv[1] == "sweep":
        title = argv[argv.index("--title") + 1] if "--title" in argv else None
        sweep(argv[2], argv[3], argv[4], title)
    elif len(argv) >= 4 and argv[1] == "windows":
        windows(argv[2], argv[3])
    elif len(argv) >= 4 and argv[1] == "correction":
        correction(argv[2], argv[3])
    elif len(argv) >= 4 and argv[1] == "learning":
        learning(argv[2], argv[3])
    elif len(argv) >= 4 and argv[1] == "design":
        design(argv[2], argv[3], int(argv[argv.index("--np") + 1]) if "--np" in argv else None)
    else:
        raise SystemExit(__doc__)


if __name__ == "__main__":
    main(sys.argv)

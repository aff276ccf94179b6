#!/usr/bin/env python3
"""Would features the sweeps do not record today see the convention switches
that the correction's forest cannot (issue 51's block, option 4;
docs/validation.md, "Features that would see the switches")?

The foreign sets share their scenes, so a scene can be synthesised under each
switch and compared with spheres whose chords are the same. For each of the
foreign control's first N scenes (60 s at 500 kHz, binary signals), five
variants:
  A  the control: spheres of d_b, overlap avoided
  B  ellipsoids of aspect 0.6 (the ellipsoids set)
  C  spheres of d_b * 0.6^(2/3): the along-flow extent of B, so the same chords
  D  overlap allowed (the overlap set)
  E  spheres with overlap avoided whose mean chord is D's (d_b scaled by D's
     mean chord over A's)
and candidate features from the two tips' signals: the arrival structure
(the share of water gaps shorter than a quarter of the mean air chord, the
gaps' coefficient of variation), the chords' skewness (their CV is among
the stand-ins below), the two tips (the share of leading-tip bubbles seen
by the trailing tip at dx/u, the count and chord ratios) and FSCC's
correlation maximum r12 (a feature of the `+fscc` forests already).

A candidate helps only where it moves with the switch beyond what the
features the forest has already explain. So each candidate is fitted on the
reference runs (A, C, E of every scene: spheres, overlap avoided) by a ridge
regression on those features (log c, log count rate, log mean chord length,
chord CV, Tu, log dx, dy, log u; linear, or with their products), leaving
the scene out, and the switch's runs' residuals are given in units of the
reference's residual sd (their mean less the reference's), with the share
above the reference's median residual (0.5 = no separation) and the paired
t of switch minus control.

Usage: switch_features.py measure N OUT.json [PDP]   (about 30 s a scene beside a campaign)
       switch_features.py analyse OUT.json [--quadratic] [--with-r12]
"""
import csv
import json
import os
import subprocess
import sys
import tempfile
import wave

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CONTROL = os.path.join(REPO, "samples/model/time-prior/runs/foreign-control.csv")
FS, DURATION = 5e5, 60.0


def synth(pdp, row, workdir, **changes):
    options = {"velocity": f"{row['velocity']}m/s", "tu": row["tu"], "tu-y": row["tu_y"], "tu-z": row["tu_z"],
               "time-scale": f"{row['time_scale']}s", "void-fraction": row["void_fraction"],
               "bubble-diameter": f"{row['bubble_diameter']}m", "dx": f"{row['dx']}m", "dy": f"{row['dy']}m",
               "rho-xz": row["rho_xz"], "seed": row["seed"], "fs": "500kHz", "duration": f"{DURATION:g}s"}
    options.update(changes)
    path = os.path.join(workdir, "scene.wav")
    command = ["nice", "-n", "10", pdp, "--log-level", "warn", "synth", "-q", "-o", path]
    for key, value in options.items():
        command += [f"--{key}", str(value)]
    subprocess.run(command, check=True)
    with wave.open(path) as w:
        x = np.frombuffer(w.readframes(w.getnframes()), dtype=np.int16).reshape(-1, w.getnchannels())
    os.remove(path)
    return x[:, 0] > 0, x[:, 1] > 0


def chords(air):
    step = np.diff(air.astype(np.int8))
    start, end = np.flatnonzero(step == 1) + 1, np.flatnonzero(step == -1) + 1
    if len(end) and len(start) and end[0] < start[0]:
        end = end[1:]
    n = min(len(start), len(end))
    return start[:n], end[:n]


def features(lead, trail, lag):
    s, e = chords(lead)
    s2, e2 = chords(trail)
    chord = (e - s).astype(float)
    gap = (s[1:] - e[:-1]).astype(float)
    # Seen by the trailing tip: one of its chords overlaps the leading chord
    # moved by the lag, give or take half of it.
    first = np.searchsorted(e2, s + 0.5 * lag)
    seen = (first < len(s2)) & (s2[np.minimum(first, len(s2) - 1)] < e + 1.5 * lag)
    x, y = lead - lead.mean(), trail - trail.mean()
    # Circular correlation: the wrap touches lags within 3 transits of a
    # 30-million-sample record, a negligible share.
    cc = np.fft.irfft(np.conj(np.fft.rfft(x)) * np.fft.rfft(y), n=len(x))[: int(3 * lag) + 2]
    return dict(n=len(s), mean_chord=chord.mean(), chord_cv=chord.std() / chord.mean(),
                chord_skew=((chord - chord.mean()) ** 3).mean() / chord.std() ** 3,
                short_gap=(gap < 0.25 * chord.mean()).mean(), gap_cv=gap.std() / gap.mean(),
                seen_by_trail=seen.mean(), count_ratio=len(s2) / len(s),
                chord_ratio=(e2 - s2).mean() / chord.mean(), r12=cc.max() / (len(x) * x.std() * y.std()))


def measure(n, out, pdp):
    rows = list(csv.DictReader(open(CONTROL)))
    if not 3 <= n <= len(rows):
        sys.exit(f"switch_features.py: N = {n}: give 3 to {len(rows)} scenes (the rows of {CONTROL}); "
                 "the analysis leaves one scene out of a fit on the others")
    rows = rows[:n]
    results = []
    with tempfile.TemporaryDirectory() as workdir:
        for row in rows:
            d_b = float(row["bubble_diameter"])
            lag = float(row["dx"]) / float(row["velocity"]) * FS
            v = {"A": features(*synth(pdp, row, workdir), lag),
                 "B": features(*synth(pdp, row, workdir, **{"aspect-ratio": 0.6}), lag),
                 "C": features(*synth(pdp, row, workdir, **{"bubble-diameter": f"{d_b * 0.6 ** (2 / 3)}m"}), lag),
                 "D": features(*synth(pdp, row, workdir, overlap="allow"), lag)}
            scale = v["D"]["mean_chord"] / v["A"]["mean_chord"]
            v["E"] = features(*synth(pdp, row, workdir, **{"bubble-diameter": f"{d_b * scale}m"}), lag)
            results.append({"run": row["run"], "variants": v})
            print(f"scene {row['run']}: {len(results)} of {len(rows)}", file=sys.stderr, flush=True)
    tmp = out + ".tmp"
    json.dump(results, open(tmp, "w"))
    os.replace(tmp, out)


def analyse(path, quadratic, with_r12):
    results = json.load(open(path))
    scenes = {r["run"]: r for r in csv.DictReader(open(CONTROL))}

    def predictors(run, v):
        s = scenes[run]
        u = float(s["velocity"])
        c = v["n"] * v["mean_chord"] / (DURATION * FS)
        x = np.array([np.log(c), np.log(v["n"] / DURATION), np.log(v["mean_chord"] / FS * u), v["chord_cv"],
                      float(s["tu"]), np.log(float(s["dx"])), float(s["dy"]) * 1e3, np.log(u)]
                     + ([v["r12"]] if with_r12 else []))
        return np.concatenate([x, np.outer(x, x)[np.triu_indices(len(x))]]) if quadratic else x

    print(f"{len(results)} scenes; reference fit {'quadratic' if quadratic else 'linear'}"
          f"{', r12 among the predictors' if with_r12 else ''}")
    print("candidate | ref. residual sd | ellipsoids: mean (sd units), share above ref. median, paired t"
          " | overlap: the same")
    for name in ["short_gap", "gap_cv", "chord_skew", "seen_by_trail", "count_ratio", "chord_ratio", "r12"]:
        if with_r12 and name == "r12":
            continue
        residuals = []
        for i, r in enumerate(results):
            train = [(predictors(q["run"], q["variants"][t]), q["variants"][t][name])
                     for j, q in enumerate(results) if j != i for t in "ACE"]
            X = np.array([a for a, _ in train])
            y = np.array([b for _, b in train])
            mu, sd = X.mean(0), X.std(0) + 1e-12
            Z = np.column_stack([np.ones(len(X)), (X - mu) / sd])
            beta = np.linalg.solve(Z.T @ Z + np.eye(Z.shape[1]), Z.T @ y)
            fit = {t: np.concatenate([[1.0], (predictors(r["run"], r["variants"][t]) - mu) / sd]) @ beta
                   for t in "ABCDE"}
            residuals.append({t: r["variants"][t][name] - fit[t] for t in "ABCDE"})
        reference = np.array([e[t] for e in residuals for t in "ACE"])
        s0 = reference.std()
        line = f"{name} | {s0:.4g}"
        for t in "BD":
            e = np.array([x[t] for x in residuals])
            paired = np.array([x[t] - x["A"] for x in residuals])
            t_paired = paired.mean() / paired.std(ddof=1) * np.sqrt(len(paired))
            line += f" | {(e.mean() - reference.mean()) / s0:+.2f}, {np.mean(e > np.median(reference)):.2f}, {t_paired:+.1f}"
        print(line)


if __name__ == "__main__":
    if len(sys.argv) >= 4 and sys.argv[1] == "measure":
        measure(int(sys.argv[2]), sys.argv[3], sys.argv[4] if len(sys.argv) > 4 else os.path.join(REPO, "build/tools/pdp"))
    elif len(sys.argv) >= 3 and sys.argv[1] == "analyse":
        analyse(sys.argv[2], "--quadratic" in sys.argv, "--with-r12" in sys.argv)
    else:
        sys.exit(__doc__)

"""pdp report's profile quantities (issue 31, METHOD 12): the flow figures
and table, and the bubble-size figures.

A profile crossing c = 0.9 (twelve binary recordings of random air and water
runs, c = 0.08 i at y = 5 i mm, the trailing tip seeing each interface a
jittered lag later: u grows with y) gives every quantity; the report draws
both air-concentration curves and the power law with the D', D_0, N, u90 and
Y90 pdp process wrote, and its table holds the JSON's values. The curves are
checked against the C++ fit independently of the figure code's own
reading: the rms of c_i - c(y_i) over the fitted rows is the residual the
C++ wrote, to rounding (a mistyped K' or exponent moves it by far more). The
real profile (c <= 0.21) has no Y90: no curve, the reason written on the
figure and in the table. The size figures are tested on hand-made `sizes`
objects that follow docs/output.md's schema."""

import json
import os
import math
import re

import numpy as np
import pytest
from pdp import plotting, report

from conftest import MODEL, made
from test_legends import check_legends
from test_report import Page

# 2 s a recording, runs of 20 samples: about 2000 bubbles, AWCC of quality ok from c = 0.3 (FSCC below)
FS, SAMPLES, RUN = 40000, 80000, 20.0


def write_recording(path, c, lag, rng):
    """Binary leading and trailing tips: geometric runs of mean RUN samples
    for the less frequent phase; the trailing tip sees each interface lag
    samples later, 15 % jitter."""
    mean_air = RUN if c < 0.5 else RUN * c / 0.5
    mean_water = mean_air * (1 - c) / c
    lengths, states, total, air = [], [], 0, bool(rng.integers(2))
    while total < SAMPLES + 200:
        lengths.append(int(rng.geometric(1 / (mean_air if air else mean_water))))
        states.append(int(air))
        total += lengths[-1]
        air = not air
    edges = np.concatenate([[0], np.cumsum(lengths)])
    shifted = np.maximum.accumulate(edges[:-1] + np.round(lag * (1 + 0.15 * rng.standard_normal(len(lengths))))
                                    .astype(int))
    trail = np.zeros(total + 400, dtype=int)
    for k, s in enumerate(states):
        trail[shifted[k]:shifted[k + 1] if k + 1 < len(shifted) else None] = s
    lead = np.repeat(states, lengths)[100:100 + SAMPLES]
    np.savetxt(path, np.column_stack([np.arange(SAMPLES) / FS, lead, trail[100:100 + SAMPLES]]),
               fmt=["%.6f", "%d", "%d"], delimiter=",", header="time,lead,trail", comments="")


@pytest.fixture(scope="module")
def crossing(tmp_path_factory):
    """The profile crossing 0.9, processed with a discharge, and its report (no per-position detail)."""
    d = tmp_path_factory.mktemp("crossing")
    rng = np.random.default_rng(7)
    for i in range(1, 13):
        write_recording(d / f"r{i:02d}.csv", 0.08 * i if i < 12 else 0.97, 30 * i ** (-1 / 6), rng)
    positions = ",".join(f"{5 * i}mm" for i in range(1, 13))
    made("process", *sorted(p.name for p in d.glob("r*.csv")), "--dx", "5mm", "--positions", positions,
         "--discharge", "0.45m2/s", "--flow-draws", "400", "--json", "profile.json", cwd=d)
    made("report", "profile.json", "-o", "report.html", "--no-detail", cwd=d)
    data = json.loads((d / "profile.json").read_text())
    assert data["flow"]["status"] == "ok", data["flow"]["reason"]
    return d, data


@pytest.fixture(scope="module")
def real_profile(tmp_path_factory, real_files):
    d = tmp_path_factory.mktemp("real-flow")
    positions = ",".join(f"{p}mm" for p in (2, 8, 14, 20, 26, 32, 38, 44, 50, 54))
    made("process", *real_files, "--fs", "20kHz", "--dx", "7.15mm", "--positions", positions, "--json",
         d / "profile.json")
    made("report", d / "profile.json", "-o", d / "report.html", "--no-detail")
    return d, json.loads((d / "profile.json").read_text())


def fitted(flow):
    """The rows the fits take: 0 < y <= Y90, as awcc/profile_flow.hpp says."""
    y90 = flow["y90"]["value"]
    return [r for r in flow["rows"] if 0 < r["position"] <= y90]


def test_the_curves_are_the_fits_pdp_process_made(crossing):
    _, data = crossing
    flow = data["flow"]
    y90, rows = flow["y90"]["value"], fitted(flow)
    assert len(rows) == flow["smooth_chute"]["points"] == flow["stepped_chute"]["points"] >= 10
    y = np.array([r["position"] for r in rows])
    c = np.array([r["void_fraction"] for r in rows])
    for key, _, _, model, _, _ in plotting.CONCENTRATION_MODELS:
        fit = flow[key]
        assert model(y90, fit["value"], y90) == pytest.approx(0.9, abs=1e-12), key  # the constraint c(Y90) = 0.9
        rms = math.sqrt(np.mean((c - model(y, fit["value"], y90)) ** 2))
        # The C++ sums the same terms in the same order: equal to rounding.
        assert rms == pytest.approx(fit["residual"], rel=1e-9), key
        # A curve of a D 1 % off would be another fit: its residual differs visibly.
        assert math.sqrt(np.mean((c - model(y, 1.01 * fit["value"], y90)) ** 2)) > fit["residual"] * (1 + 1e-4)
        # K' as the JSON writes it: the argument at y = 0 is K' (smooth) or K' + (-1/3)^3 / (3 D_0) (stepped).
        at_invert = fit["k_prime"] - (1 / (81 * fit["value"]) if key == "stepped_chute" else 0.0)
        assert model(0.0, fit["value"], y90) == pytest.approx(1 - math.tanh(at_invert) ** 2, rel=1e-12), key
    law = flow["power_law"]
    with_u = [r for r in rows if r["velocity"] is not None]
    assert len(with_u) == law["points"]
    yu = np.array([r["position"] for r in with_u])
    u = np.array([r["velocity"] for r in with_u])
    rms = math.sqrt(np.mean((np.log(u) - np.log(plotting.power_law_u(yu, law["n"]["value"], law["u90"]["value"],
                                                                          y90))) ** 2))
    assert rms == pytest.approx(law["residual"], rel=1e-9)
    assert plotting.power_law_u(y90, 4.0, 3.0, y90) == 3.0


def line_data(ax):
    """The curves: lines of more than two points that are not a series of points with error bars."""
    points = {id(line) for c in ax.containers for line in (c.lines[0], *c.lines[1])}  # the points and caps
    return [(line.get_xdata(), line.get_ydata(), line.get_label()) for line in ax.lines
            if len(line.get_xdata()) > 2 and id(line) not in points]


def test_the_concentration_figure_draws_both_fits_with_bands_and_the_depths(crossing):
    _, data = crossing
    flow = data["flow"]
    fig = plotting.flow_concentration(data["profile"], flow)
    ax = fig.axes[0]
    y90 = flow["y90"]["value"]
    curves = line_data(ax)
    assert len(curves) == 2
    for (x, y_mm, label), (key, symbol, _, model, _, _) in zip(curves, plotting.CONCENTRATION_MODELS):
        assert np.allclose(x, model(np.asarray(y_mm) / 1e3, flow[key]["value"], y90), rtol=0, atol=1e-12)
        assert max(y_mm) == pytest.approx(1e3 * y90)  # drawn where fitted
        assert f"{symbol} = {flow[key]['value']:.3g}" in label
    bands = [c for c in ax.collections if type(c).__name__ == "PolyCollection"]
    assert len(bands) == 2
    for band, (key, _, _, model, _, _) in zip(bands, plotting.CONCENTRATION_MODELS):
        lo, hi = flow[key]["ci95"]
        xs = band.get_paths()[0].vertices[:, 0]
        # The band's edges are the curve at D's interval ends: its extremes lie between theirs.
        y = np.linspace(0, y90, 241)
        edges = np.concatenate([model(y, lo, y90), model(y, hi, y90)])
        assert xs.min() == pytest.approx(edges.min()) and xs.max() == pytest.approx(edges.max())
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    for name, depth in plotting.flow_depths(flow):
        lo, hi = (1e3 * b for b in depth["ci95"])
        assert f"{name} = {1e3 * depth['value']:.4g} [{lo:.4g}, {hi:.4g}] mm" in labels, (name, labels)
    assert f"C_mean = {flow['c_mean']['value']:.3g}" in ax.get_title()
    assert check_legends(fig, "crossing concentration") == 1


def test_the_velocity_figure_marks_each_source_and_draws_the_power_law(crossing):
    _, data = crossing
    flow = data["flow"]
    fig = plotting.flow_velocity(data["profile"], flow)
    ax = fig.axes[0]
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    sources = {r["velocity_source"] for r in flow["rows"]}
    assert sources == {"awcc", "fscc"}
    for source in sources:
        assert plotting.VELOCITY_SOURCES[source][0] in labels
    # Each source's points are that source's rows, at their position.
    for container in ax.containers:
        label = container.get_label()
        source = next((s for s, v in plotting.VELOCITY_SOURCES.items() if v[0] == label), None)
        if source is None:
            continue
        x, y = container.lines[0].get_data()
        expected = [(r["velocity"], 1e3 * r["position"]) for r in flow["rows"] if r["velocity_source"] == source]
        assert list(zip(x, y)) == pytest.approx(expected)
    (x, y_mm, label), = [c for c in line_data(ax) if "N =" in c[2]]
    law = flow["power_law"]
    assert np.allclose(x, plotting.power_law_u(np.asarray(y_mm) / 1e3, law["n"]["value"], law["u90"]["value"],
                                               flow["y90"]["value"]), rtol=1e-12)
    assert f"N = {law['n']['value']:.3g}" in label and f"u90 = {law['u90']['value']:.3g}" in label
    assert check_legends(fig, "crossing velocity") == 1


def flow_table_rows(page_text):
    """data-quantity -> the row's data attributes and cell texts."""
    class Table(Page):
        def __init__(self, text):
            self.quantities, self._current = {}, None
            super().__init__(text)

        def handle_starttag(self, tag, attrs):
            a = dict(attrs)
            if tag == "tr" and "data-quantity" in a:
                self._current = self.quantities.setdefault(a["data-quantity"], {"attrs": a, "cells": []})
            elif tag == "td" and self._current is not None:
                self._current["cells"].append("")
            super().handle_starttag(tag, attrs)

        def handle_endtag(self, tag):
            if tag == "tr":
                self._current = None
            super().handle_endtag(tag)

        def handle_data(self, data):
            if self._current is not None and self._current["cells"]:
                self._current["cells"][-1] += data
            super().handle_data(data)
    return Table(page_text)


def check_flow_table(text, flow):
    """Every quantity is a row whose value, interval and residual are the
    JSON's exactly (data attributes) and shown to 4 digits in its unit; a
    missing value or interval shows the JSON's reason."""
    page = flow_table_rows(text)
    pointers = ["/y90"] + [f"/levels/{k}" for k in range(len(flow["levels"]))] + \
        [p for p, *_ in report.FLOW_QUANTITIES if p != "/continuity_error" or flow["discharge"] is not None]
    assert list(page.quantities) == pointers
    for pointer, row in page.quantities.items():
        q = plotting.get(flow, *(int(t) if t.isdigit() else t for t in pointer.split("/")[1:]))
        attrs, cells = row["attrs"], row["cells"]
        name, symbol, value_text, unit, interval_text, residual_text, reason = (c.strip() for c in cells)
        assert json.loads(attrs["data-value"]) == q["value"], pointer
        assert json.loads(attrs["data-lower"]) == (q["ci95"] or [None])[0], pointer
        assert json.loads(attrs["data-upper"]) == (q["ci95"] or [None, None])[1], pointer
        scale = {"mm": 1e3, "%": 100.0}.get(unit, 1.0)
        if q["value"] is None:
            assert value_text == "\u2013" and reason == q["reason"] and len(reason) > 10, pointer
        else:
            assert float(value_text) == pytest.approx(scale * q["value"], rel=5e-4), pointer
            lo, hi = (float(v) for v in interval_text.strip("[]").split(","))
            assert (lo, hi) == pytest.approx([scale * b for b in q["ci95"]], rel=5e-4), pointer
        residual = {"/smooth_chute": lambda: flow["smooth_chute"]["residual"],
                    "/stepped_chute": lambda: flow["stepped_chute"]["residual"],
                    "/power_law/n": lambda: flow["power_law"]["residual"]}.get(pointer, lambda: None)()
        assert json.loads(attrs["data-residual"]) == residual, pointer
        if residual is not None:
            assert float(residual_text) == pytest.approx(residual, rel=5e-3)
    assert 'data-invert="' + flow["invert"] + '"' in text
    for k, r in enumerate(flow["rows"]):
        assert f'data-flow-row="{k}" data-source="{r["velocity_source"] or ""}"' in text
    for note in flow["notes"]:
        assert note in text


def test_the_table_holds_the_jsons_quantities(crossing):
    d, data = crossing
    text = (d / "report.html").read_text()
    check_flow_table(text, data["flow"])
    assert 'data-status="ok"' in text and "q = 0.45 m\u00b2/s" in text
    for key, _, _ in plotting.FLOW_FIGURES:
        assert f'data-figure="{key}"' in text


def test_the_real_profile_has_no_y90_and_says_why_on_figure_and_table(real_profile):
    d, data = real_profile
    flow = data["flow"]
    assert flow["y90"]["value"] is None
    text = (d / "report.html").read_text()
    check_flow_table(text, flow)
    assert "No discharge given" in text  # and no continuity row (check_flow_table)
    for make, what in ((plotting.flow_concentration, "No Y90: no fitted curves"),
                       (plotting.flow_velocity, "No power law (N, u90): no Y90")):
        fig = make(data["profile"], flow)
        assert line_data(fig.axes[0]) == []  # points only: no curve, no band
        assert not any(type(c).__name__ == "PolyCollection" for c in fig.axes[0].collections)
        written = "\n".join(t.get_text() for t in fig.texts).replace("\n  ", " ")
        assert what in written and flow["y90"]["reason"] in written, written
        check_legends(fig, f"real {make.__name__}")
    # Every measured row is a point of the concentration figure, at its interval.
    fig = plotting.flow_concentration(data["profile"], flow)
    (points,) = fig.axes[0].containers
    x, y = points.lines[0].get_data()
    assert list(zip(x, y)) == pytest.approx([(r["void_fraction"], 1e3 * r["position"]) for r in flow["rows"]])
    for segment, row in zip(points.lines[2][0].get_segments(), data["profile"]):
        assert [segment[0][0], segment[1][0]] == pytest.approx(row["tips"][0]["void_fraction_ci95"])


def test_each_velocity_has_the_interval_of_its_source(real_files, tmp_path):
    """The corrected real profile: its rows' velocities are the corrected
    AWCC medians (a row without AWCC, FSCC's own; a row whose corrected
    interval excludes FSCC's, its uncorrected velocity: METHOD 12 as
    docs/validation.md decides it); each point's bar is its source's
    interval: the AWCC forest's 2.5 and 97.5 % quantiles, AWCC's or FSCC's
    95 % interval."""
    positions = ",".join(f"{p}mm" for p in (2, 8, 14, 20, 26, 32, 38, 44, 50, 54))
    made("process", *real_files, "--fs", "20kHz", "--dx", "7.15mm", "--positions", positions, "--correct", MODEL,
         "--json", tmp_path / "profile.json")
    data = json.loads((tmp_path / "profile.json").read_text())
    flow, rows = data["flow"], data["profile"]
    assert {r["velocity_source"] for r in flow["rows"]} == {"corrected awcc", "awcc", "fscc"}
    # The 8 mm row's corrected median (1.636 m/s, 10 windows) excludes FSCC's 2.509: FSCC's is taken, and said.
    (row_8mm,) = [f for f in flow["rows"] if f["position"] == pytest.approx(0.008)]
    assert row_8mm["velocity_source"] == "fscc" and row_8mm["velocity"] == pytest.approx(2.509, abs=1e-3)
    assert any(n.startswith("dc157_02.dat: the corrected AWCC velocity 1.636 m/s") for n in flow["notes"]), flow["notes"]
    ax = plotting.flow_velocity(rows, flow).axes[0]
    checked = 0
    for container in ax.containers:
        source = next((s for s, v in plotting.VELOCITY_SOURCES.items() if v[0] == container.get_label()), None)
        if source is None:
            continue
        mine = [(r, f) for r, f in zip(rows, flow["rows"]) if f["velocity_source"] == source]
        for segment, (row, f) in zip(container.lines[2][0].get_segments(), mine):
            expected = [row["correction"]["velocity"]["quantiles"][p] for p in ("0.025", "0.975")] \
                if source == "corrected awcc" else row[source]["velocity_ci95"]
            assert row["position"] == f["position"] and [segment[0][0], segment[1][0]] == pytest.approx(expected)
            checked += 1
    assert checked == len(flow["rows"])


def test_a_json_without_flow_says_why(tmp_path, real_files):
    made("process", *real_files[:2], "--fs", "20kHz", "--dx", "7.15mm", "--json", tmp_path / "p.json")
    made("report", tmp_path / "p.json", "-o", tmp_path / "r.html", "--no-detail")
    text = (tmp_path / "r.html").read_text()
    assert 'data-status="absent"' in text and "need two or more recordings with their positions" in text
    assert "flow-concentration" not in text


# --- bubble sizes: hand-made `sizes` objects following docs/output.md -------------------


def lognormal_sizes(median, sigma, d32_flux, status="ok", reason=None, bins=24):
    """A `sizes` object with a log-normal n(D) on bins equal in ln D (the
    schema of docs/output.md); without a distribution for the other statuses."""
    absent = {"median": None, "d10": None, "d20": None, "d30": None, "d32": None, "iterations": None, "bins": None}
    common = {"status": status, "reason": reason, "dispersed_phase": "bubbles", "chords_given": 4000,
              "chords_used": 3900, "chords_by_velocity": {"bubble": 0, "window": 3500, "record": 400, "none": 100},
              "record_velocity_source": "awcc", "mean_chord": 0.8 * median, "floor_chord_samples": 4.2,
              "d32_chords": 1.2 * median, "d32_flux": d32_flux}
    if status not in plotting.SIZES_WITH_VALUES:
        return dict(common, **absent)
    edges = np.exp(np.linspace(math.log(median) - 3 * sigma, math.log(median) + 3 * sigma, bins + 1))
    centres = np.sqrt(edges[:-1] * edges[1:])
    density = np.exp(-0.5 * (np.log(centres / median) / sigma) ** 2) / centres
    density /= (density * np.diff(edges)).sum()
    w = density * np.diff(edges)
    moment = [float((w * centres ** k).sum()) for k in range(4)]
    return dict(common, median=median, d10=moment[1], d20=math.sqrt(moment[2]), d30=moment[3] ** (1 / 3),
                d32=moment[3] / moment[2], iterations=180,
                bins={"edges": edges.tolist(), "diameters": centres.tolist(), "density": density.tolist(),
                      "cumulative": np.concatenate([[0.0], np.cumsum(w)]).tolist()})


@pytest.fixture()
def sized(real_profile):
    """The real profile's rows, each with a hand-made `sizes`: row 0 too few
    chords, row 5 not converged, the rest log-normal."""
    _, data = real_profile
    rows = json.loads(json.dumps(data["profile"]))
    for i, r in enumerate(rows):
        if i == 0:
            r["sizes"] = lognormal_sizes(1e-3, 0.5, None, "too_few_chords",
                                         "150 usable chords (fewer than size-chords-min, 200)")
        elif i == 5:
            r["sizes"] = lognormal_sizes(1.7e-3, 0.5, 2.4e-3, "not_converged",
                                         "the EM stopped at its iteration limit (500)")
        else:
            r["sizes"] = lognormal_sizes(1e-3 + 1.5e-4 * i, 0.45, r["tips"][0]["sauter_diameter"])
    return rows


def test_each_positions_size_distribution_is_drawn_and_the_others_say_why(sized):
    fig = plotting.profile_size_distributions(sized)
    ax = fig.axes[0]
    curves = [(line.get_xdata(), line.get_ydata(), line.get_linestyle()) for line in ax.lines
              if len(line.get_xdata())]
    with_values = [r for r in sized if r["sizes"]["status"] in plotting.SIZES_WITH_VALUES]
    assert len(curves) == len(with_values) == 9
    for (x, y, style), r in zip(curves, with_values):  # in increasing position: the rows' order here
        assert np.array_equal(x, 1e3 * np.asarray(r["sizes"]["bins"]["diameters"]))
        assert np.array_equal(y, 1e-3 * np.asarray(r["sizes"]["bins"]["density"]))
        assert style == ("-" if r["sizes"]["status"] == "ok" else ":")
    written = "\n".join(t.get_text() for t in fig.texts).replace("\n  ", " ")
    assert "y = 2 mm: too_few_chords: 150 usable chords" in written
    assert "y = 32 mm: not_converged: the EM stopped" in written
    assert "y = 8 mm" not in written
    assert check_legends(fig, "size distributions") == 1


def test_d32_of_the_distribution_is_drawn_against_the_flux_estimate(sized):
    fig = plotting.profile_size_d32(sized)
    ax = fig.axes[0]
    series = {c.get_label(): list(zip(*c.lines[0].get_data())) for c in ax.containers}
    y = [1e3 * r["position"] for r in sized]

    def expected(value):
        return [(1e3 * v if v is not None else math.nan, yi) for v, yi in zip(map(value, sized), y)]

    def same(a, b):
        return len(a) == len(b) and all((math.isnan(p[0]) and math.isnan(q[0])) or p == pytest.approx(q)
                                        for p, q in zip(a, b))
    assert same(series["d32 of the size distribution n(D)"],
                expected(lambda r: r["sizes"]["d32"] if r["sizes"]["status"] == "ok" else None))
    assert same(series["1.5 u c / F (flux, spheres)"], expected(lambda r: r["sizes"]["d32_flux"]))
    assert same(series["d32, EM not converged (doubtful)"],
                expected(lambda r: r["sizes"]["d32"] if r["sizes"]["status"] == "not_converged" else None))
    assert check_legends(fig, "size d32") == 1


def test_the_report_draws_the_size_figures_when_a_row_has_sizes(sized, real_profile, tmp_path):
    d, data = real_profile
    data = dict(data, profile=sized)
    (tmp_path / "sized.json").write_text(json.dumps(data))
    made("report", tmp_path / "sized.json", "-o", tmp_path / "r.html", "--no-detail")
    text = (tmp_path / "r.html").read_text()
    for key in ("size-distributions", "size-d32"):
        assert f'data-figure="{key}"' in text
    bare = dict(data, profile=[{k: v for k, v in r.items() if k != "sizes"} for r in data["profile"]])
    (tmp_path / "bare.json").write_text(json.dumps(bare))
    made("report", tmp_path / "bare.json", "-o", tmp_path / "bare.html", "--no-detail")
    bare_text = (tmp_path / "bare.html").read_text()
    for key in ("size-distributions", "size-d32"):
        assert f'data-figure="{key}"' not in bare_text  # rows without sizes: no size figure


def test_a_profile_without_a_distribution_has_one_note_for_the_size_figures(real_profile, tmp_path):
    # The real recordings at 20 kHz: every position coarse_sampling (issue 53:
    # an empty panel and the same four-line note ten times, twice).
    d, data = real_profile
    assert all(r["sizes"]["status"] == "coarse_sampling" for r in data["profile"])
    (tmp_path / "real.json").write_text(json.dumps(data))
    made("report", tmp_path / "real.json", "-o", tmp_path / "r.html", "--no-detail")
    text = (tmp_path / "r.html").read_text()
    for key in ("size-distributions", "size-d32"):
        assert f'data-figure="{key}"' not in text
    notes = re.findall(r'<p class="figure-note"[^>]*data-figure-note="size-distributions">([^<]*)</p>', text)
    assert len(notes) == 1, notes
    assert notes[0].count("coarse_sampling") == 1, notes[0]
    assert notes[0].startswith("Bubble size distributions: none to draw. y = "), notes[0]


def test_the_report_shows_recordings_relative_to_the_json(real_profile, real_files):
    # real_files are absolute paths (issue 53: the table's file row showed
    # them wrapped); the report shows them from the JSON's folder.
    d, data = real_profile
    text = (d / "report.html").read_text()
    absolute = os.path.abspath(real_files[0])
    assert os.path.isabs(data["profile"][0]["file"]) or os.path.isabs(data["provenance"]["inputs"][0]["file"])
    # Shown relative (the data-value attribute and the command line keep what was written).
    assert ">" + absolute not in text
    assert ">" + os.path.relpath(absolute, d) + "<" in text

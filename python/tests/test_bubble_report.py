"""pdp report for recordings processed bubble by bubble (issue 30): a
profile of two four-tip recordings (the clean scene, quality ok, and pdp's
base case with the sample's four tips, 3 mm bubbles at c = 0.25 too dense to
pair, whose vectors are flagged multi_tip_doubtful) and a two-tip
recording with event detection (flagged events_disagree: Kramer's pairing is
biased on the synthetic base case). The page holds the mean-vector profile
figure and each position's bubble panels, drawn from the recording's
per-bubble table; each title states the quality and flag; a doubtful mean is
drawn hollow and grey, never as trusted; no legend covers data."""

import json

import matplotlib
import numpy as np
import pdp
import pytest
from pdp import plotting, report

from conftest import SOURCE, made
from test_legends import check_legends
from test_report import Page

CLEAN = """velocity = "2m/s"
tu = 0.05
tu-y = 0.025
tu-z = 0.025
time-scale = "1s"
void-fraction = 0.05
bubble-diameter = "8mm"
tips = [["0mm", "0mm", "0mm"], ["2mm", "0mm", "0mm"], ["2mm", "1mm", "0mm"], ["2mm", "0mm", "1mm"]]
fs = "200kHz"
duration = "20s"
seed = 11
"""


@pytest.fixture(scope="module")
def folder(tmp_path_factory):
    d = tmp_path_factory.mktemp("bubbles")
    (d / "clean.toml").write_text(CLEAN)
    made("synth", "-q", "--config", "clean.toml", "-o", "clean.h5", cwd=d)
    # The base case (synth::Scene's defaults) with the four-tip sample's tips:
    # too dense to pair, the few vectors accepted carry a caution.
    (d / "dense.toml").write_text('tips = [["0mm", "0mm", "0mm"], ["5mm", "0mm", "0mm"], ["5mm", "1.5mm", "0mm"], '
                                  '["5mm", "0mm", "1.5mm"]]\nduration = "4s"\n')
    made("synth", "-q", "--config", "dense.toml", "-o", "four.h5", cwd=d)
    made("synth", "-q", "--duration", "10s", "--dx", "5mm", "-o", "two.flac", cwd=d)
    made("process", "clean.h5", "four.h5", "--positions", "10mm,20mm", "--json", "four.json", cwd=d)
    made("process", "two.flac", "--dx", "5mm", "--method", "events", "--json", "two.json", cwd=d)
    return d


def rows_and_details(path):
    data = json.loads(path.read_text())
    rows = data.get("profile", [data])
    options = report.process_options(data.get("provenance") or {}, pdp)
    details = []
    for i, row in enumerate(rows):
        detail, why = report.detail_for(i, row, data, str(path.parent), pdp, options)
        assert detail is not None, why
        details.append(detail)
    return rows, details


def test_the_four_tip_report_holds_the_vector_figure_and_bubble_panels(folder):
    rows, _ = rows_and_details(folder / "four.json")
    # The scenes are what the test needs: one trusted, one doubtful.
    assert [r["multi_tip"]["quality"] for r in rows] == ["ok", "low"]
    assert "multi_tip_doubtful" not in rows[0]["flags"] and "multi_tip_doubtful" in rows[1]["flags"]
    text = report.build(str(folder / "four.json"))
    page = Page(text)
    assert page.figures == [key for key, _, _ in plotting.PROFILE_FIGURES] + \
        ["multi-tip-vector", "size-distributions", "size-d32"] + \
        [key for key, _, _ in plotting.FLOW_FIGURES]  # two positions: a profile's flow; every row has its sizes
    for i in range(2):
        for key, _ in plotting.POSITION_PANELS + plotting.BUBBLE_PANELS["multi_tip"]:
            assert f"p{i}-{key}" in page.gids, (i, key)
        assert f"p{i}-events-velocity" not in page.gids
    positions = text.split('id="position-')[1:]
    # The summary and the panels' titles state the quality and the flag.
    assert 'data-bubble-quality="multi-tip">ok<' in positions[0] and "flag <code>" not in positions[0]
    assert 'data-bubble-quality="multi-tip">low<' in positions[1]
    assert "flag <code>multi_tip_doubtful</code>" in positions[1]
    assert positions[0].count("quality ok") == 3 and "multi_tip_doubtful" not in positions[0]
    assert positions[1].count("quality low, flag multi_tip_doubtful") == 3
    # Drawn from the recording, not a note that the table is missing.
    assert "per-bubble table not available" not in text


def component_markers(fig, panel):
    """The mean vector's three points in a panel: (face colour, edge colour)."""
    ax = fig.axes[panel]
    points = [line for line in ax.lines if line.get_marker() == "o" and len(line.get_xdata()) == 1]
    assert len(points) == 3, [line.get_label() for line in ax.lines]
    return [(line.get_markerfacecolor(), matplotlib.colors.to_hex(line.get_markeredgecolor())) for line in points]


def histogram_total(ax):
    """The bubbles a histogram panel counts: its bars, and those its legend says are outside."""
    shown = sum(p.get_height() for p in ax.patches)
    outside = [t.get_text() for t in ax.get_legend().get_texts() if "outside not shown" in t.get_text()]
    return int(shown) + (int(outside[0].split("(")[1].split()[0]) if outside else 0)


def test_a_doubtful_vector_is_drawn_hollow_and_grey(folder):
    rows, details = rows_and_details(folder / "four.json")
    figures = [plotting.position_figure(r, d) for r, d in zip(rows, details)]
    trusted, doubtful = (component_markers(f, 9) for f in figures)
    assert all(face != "none" and edge == plotting.BLUE.lower() for face, edge in trusted)
    assert all(face == "none" and edge == plotting.GREY.lower() for face, edge in doubtful)
    # The mean-vector panel's u_x agrees with the JSON's and its interval.
    ax = figures[0].axes[9]
    x = [line for line in ax.lines if line.get_marker() == "o"][0]
    assert x.get_ydata()[0] == rows[0]["multi_tip"]["velocity"][0]
    # The histogram counts the solved bubbles of the recording's table.
    assert histogram_total(figures[0].axes[10]) == rows[0]["multi_tip"]["bubbles_accepted"]


def test_the_event_detection_report_marks_fscc_and_awcc(folder):
    rows, details = rows_and_details(folder / "two.json")
    row, detail = rows[0], details[0]
    assert "events_disagree" in row["flags"]
    fig = plotting.position_figure(row, detail)
    assert "quality low, flag events_disagree" in fig.axes[9].get_title()
    labels = [t.get_text() for t in fig.axes[10].get_legend().get_texts()]
    assert any(t.startswith("FSCC ") for t in labels) and any(t.startswith("AWCC ") for t in labels)
    assert any(t.startswith(f"{row['events']['bubbles_paired']} paired bubbles") for t in labels)
    assert any("(doubtful)" in t for t in labels)  # the flagged mean
    assert histogram_total(fig.axes[10]) == row["events"]["bubbles_paired"]
    page = Page(report.build(str(folder / "two.json")))
    for key, _ in plotting.BUBBLE_PANELS["events"]:
        assert f"p0-{key}" in page.gids
    assert "multi-tip-vector" not in page.figures


def test_no_legend_of_the_bubble_panels_covers_data(folder):
    checked = 0
    for name in ("four.json", "two.json"):
        rows, details = rows_and_details(folder / name)
        for i, (row, detail) in enumerate(zip(rows, details)):
            with matplotlib.rc_context(plotting.POSITION_FONTS):
                checked += check_legends(plotting.position_figure(row, detail), f"{name} position {i}")
        if name == "four.json":
            checked += check_legends(plotting.profile_vector(rows), "mean-vector profile")
    assert checked >= 3 * 3 + 1


def test_a_panel_without_its_table_says_so(folder):
    rows, _ = rows_and_details(folder / "four.json")
    fig = plotting.position_figure(rows[0], {"windows": None, "correlation": None, "spectrum": None})
    texts = [t.get_text() for t in fig.axes[10].texts + fig.axes[11].texts]
    assert texts == ["per-bubble table not available: see this position's note"] * 2
    assert np.isfinite(rows[0]["multi_tip"]["velocity"]).all()

"""pdp report's legends cover no data (issue 29, case 10): every figure of the
report of the real profile and of a synthetic one, drawn with Agg as the
report draws it; each legend's window extent holds no pixel that the data
draws (points, lines, error bars, bars, steps, reference lines and the
labels written beside points), lies inside the figure, and covers no tick
label, axis label, title or other legend.

The data's pixels are found independently of how plotting.py places its
legends: the figure is drawn a second time with everything but the data
hidden (figure and axes background, spines, axes with their ticks, labels
and grid, titles, legends) on a transparent canvas, so that a pixel with
any opacity is one the data drew."""

import json

import matplotlib
import numpy as np
import pdp
from matplotlib.backends.backend_agg import FigureCanvasAgg
from pdp import plotting, report

from conftest import MODEL, made

DPI = 72  # a legend's box and the data scale alike; 72 keeps ten 3 x 3 figures quick


def legends_of(fig):
    return [(ax, ax.get_legend()) for ax in fig.axes if ax.get_legend() is not None] + [(None, g) for g in fig.legends]


def describe(ax, legend):
    where = ax.get_title() if ax is not None else "figure"
    return f"'{where}' legend ({', '.join(t.get_text() for t in legend.get_texts())})"


def data_mask(fig):
    """Pixels (rows from the top) that the data draws: everything else hidden."""
    fig.patch.set_visible(False)
    for ax in fig.axes:
        ax.patch.set_visible(False)
        for spine in ax.spines.values():
            spine.set_visible(False)
        ax.xaxis.set_visible(False)
        ax.yaxis.set_visible(False)
        for title in (ax.title, ax._left_title, ax._right_title):
            title.set_visible(False)
        if ax.get_legend() is not None:
            ax.get_legend().set_visible(False)
    for legend in fig.legends:
        legend.set_visible(False)
    for text in fig.texts:
        text.set_visible(False)
    canvas = fig.canvas
    canvas.draw()
    return np.asarray(canvas.buffer_rgba())[..., 3] > 0


def pixels_in(mask, box):
    """How many masked pixels lie inside a display box (origin bottom left);
    a pixel on its edge is left out (antialiasing touches it)."""
    height = mask.shape[0]
    x0, x1 = int(np.floor(box.x0)) + 1, int(np.ceil(box.x1)) - 1
    top, bottom = height - int(np.ceil(box.y1)) + 1, height - int(np.floor(box.y0)) - 1
    x0, top = max(x0, 0), max(top, 0)
    return int(mask[top:bottom, x0:x1].sum()) if x1 > x0 and bottom > top else 0


def check_legends(fig, name):
    """Asserts the module's promise for one figure; returns how many legends it checked."""
    fig.set_dpi(DPI)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    legends = [(ax, legend, legend.get_window_extent(renderer)) for ax, legend in legends_of(fig)]
    decorations = []
    for ax in fig.axes:
        if not ax.axison:
            continue
        for part in (ax.xaxis, ax.yaxis, ax.title):
            box = part.get_tightbbox(renderer) if part is not ax.title else part.get_window_extent(renderer)
            if box is not None and box.width > 0 and box.height > 0:
                decorations.append((ax.get_title() or "untitled", box))
    whole = fig.bbox
    for k, (ax, legend, box) in enumerate(legends):
        what = f"{name}: {describe(ax, legend)}"
        assert whole.x0 - 0.5 <= box.x0 and box.x1 <= whole.x1 + 0.5 and whole.y0 - 0.5 <= box.y0 \
            and box.y1 <= whole.y1 + 0.5, f"{what} is cut off by the figure's edge: {box} in {whole}"
        for owner, deco in decorations:
            assert not box.overlaps(deco), f"{what} covers the ticks, labels or title of '{owner}'"
        for _, other, other_box in legends[k + 1:]:
            assert not box.overlaps(other_box), f"{what} covers {describe(None, other)}"
    mask = data_mask(fig)
    for ax, legend, box in legends:
        covered = pixels_in(mask, box)
        assert covered == 0, f"{name}: {describe(ax, legend)} covers {covered} pixels of plotted data"
    return len(legends)


def check_report_figures(rows, detail_of, name, flow=None):
    checked = 0
    for key, _, make in plotting.PROFILE_FIGURES:
        checked += check_legends(make(rows), f"{name} {key}")
    for key, _, make, method in plotting.BUBBLE_PROFILE_FIGURES:
        if any(r.get(method) is not None for r in rows):
            checked += check_legends(make(rows), f"{name} {key}")
    for key, _, make in plotting.FLOW_FIGURES if flow is not None else []:
        checked += check_legends(make(rows, flow), f"{name} {key}")
    for i, row in enumerate(rows):
        detail = detail_of(i)
        with matplotlib.rc_context(plotting.POSITION_FONTS):  # as plotting.position_svg draws it
            checked += check_legends(plotting.position_figure(row, detail), f"{name} position {i}")
    return checked


def details(path):
    """The report's per-position detail: each recording processed again (report.detail_for)."""
    data = json.loads(path.read_text())
    rows = data["profile"]
    options = report.process_options(data.get("provenance") or {}, pdp)

    def detail_of(i):
        detail, why = report.detail_for(i, rows[i], data, str(path.parent), pdp, options)
        assert detail is not None, why
        return detail
    return rows, detail_of, data.get("flow")


def test_no_legend_of_the_real_report_covers_data(real_files, tmp_path):
    """The ten real recordings, corrected, as pdp process --report draws them."""
    positions = ",".join(f"{p}mm" for p in (2, 8, 14, 20, 26, 32, 38, 44, 50, 54))
    made("process", *real_files, "--fs", "20kHz", "--dx", "7.15mm", "--positions", positions, "--correct", MODEL,
         "--json", tmp_path / "profile.json")
    rows, detail_of, flow = details(tmp_path / "profile.json")
    # Seven profile figures, the two of the flow and nine panels a position, most of them with a legend.
    assert flow is not None
    assert check_report_figures(rows, detail_of, "real", flow) >= 7 + 2 + 10 * 7


def test_no_legend_of_a_synthetic_report_covers_data(tmp_path):
    """Three synthetic positions (void fraction and velocity rising away from the bed), binary signals."""
    files = []
    for i, (c, u) in enumerate(((0.05, 1.5), (0.15, 2.0), (0.3, 2.5))):
        files.append(f"scene{i}.flac")
        made("synth", "-o", tmp_path / files[-1], "--velocity", f"{u}m/s", "--void-fraction", str(c), "--duration",
             "6s", "--fs", "50kHz", "--seed", str(11 + i), "-q")
    made("process", *files, "--dx", "5mm", "--positions", "10mm,20mm,30mm", "--json", "profile.json", cwd=tmp_path)
    rows, detail_of, flow = details(tmp_path / "profile.json")
    assert flow is not None
    assert check_report_figures(rows, detail_of, "synthetic", flow) >= 7 + 2 + 3 * 6

"""pdp's one plotting layer (matplotlib): the style every figure shares, the
profile report's figures (pdp.report) and the study figures
(tools/plot_study.py).

Pure Python over matplotlib and NumPy: it does not need the compiled core,
so tools/plot_study.py imports this file on its own. Figures take the JSON
objects of docs/output.md (a recording's result, its ``structure``, ...) and
return matplotlib Figures; ``svg`` turns one into inline SVG text.

Conventions, for print and for colour-blind readers: the Okabe-Ito palette,
each series also told apart by marker or line style; positions in mm on the
vertical axis (a profile is read bottom to top); times in ms; velocities in
m/s; never metres in scientific notation; a legend covers no data (legend():
a free place inside the axes, else beneath them).
"""

import io
import math
import os
import re
import tempfile

import matplotlib
import numpy as np

matplotlib.use("Agg")
from matplotlib.backends.backend_agg import FigureCanvasAgg, RendererAgg  # noqa: E402
from matplotlib.cm import ScalarMappable  # noqa: E402
from matplotlib.collections import LineCollection, PolyCollection  # noqa: E402
from matplotlib.colors import Normalize  # noqa: E402
from matplotlib.figure import Figure  # noqa: E402
from matplotlib.font_manager import FontProperties  # noqa: E402
from matplotlib.path import Path  # noqa: E402
from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter  # noqa: E402
from matplotlib.transforms import Bbox  # noqa: E402

# Okabe & Ito (2008): distinguishable with every common colour-vision deficiency.
BLACK, ORANGE, SKY, GREEN, YELLOW, BLUE, VERMILION, PURPLE, GREY = (
    "#000000", "#E69F00", "#56B4E9", "#009E73", "#F0E442", "#0072B2", "#D55E00", "#CC79A7", "#999999")
PALETTE = [BLUE, ORANGE, GREEN, VERMILION, PURPLE, SKY, YELLOW, BLACK]
QUALITY_STYLE = {"ok": (GREEN, "o"), "low": (ORANGE, "s"), "insufficient": (VERMILION, "X"), None: (GREY, "_")}

STYLE = {
    "font.size": 9, "axes.titlesize": 9.5, "axes.labelsize": 9, "legend.fontsize": 7.5, "xtick.labelsize": 8,
    "ytick.labelsize": 8, "axes.grid": True, "grid.alpha": 0.3, "lines.linewidth": 1.3, "lines.markersize": 5,
    "axes.prop_cycle": matplotlib.cycler(color=PALETTE), "svg.fonttype": "none", "axes.formatter.useoffset": False,
    "axes.formatter.limits": (-4, 5), "figure.dpi": 100,
    # A fixed title height: matplotlib otherwise lays out every tick label again to place each title.
    "axes.titley": 1.0,
}
matplotlib.rcParams.update(STYLE)

# Student t 97.5 % quantiles for 1..30 degrees of freedom.
T975 = [0, 12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160, 2.145,
        2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056, 2.052, 2.048, 2.045,
        2.042]


def t975(df):
    return T975[df] if 0 < df <= 30 else 1.96 + 2.4 / max(df, 1)


def number(value):
    """A finite float, or None (CSV text, JSON null, NaN)."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        return None
    return v if math.isfinite(v) else None


def _gaps(values):
    """Values for a line: null and NaN become gaps."""
    return [math.nan if number(v) is None else float(v) for v in values]


def figure(width=4.6, height=3.4, rows=1, cols=1, margins=None):
    """A figure of rows x cols axes. ``margins`` (left, bottom, right, top, in
    inches) fix the layout: much faster than tight_layout or a tight bounding
    box, which lay every tick label out again (most of a report's time)."""
    fig = Figure(figsize=(width, height))
    FigureCanvasAgg(fig)  # a renderer to measure legends with (legend())
    axes = fig.subplots(rows, cols, squeeze=False)
    if margins:
        left, bottom, right, top = margins
        fig.subplots_adjust(left=left / width, bottom=bottom / height, right=1 - right / width, top=1 - top / height,
                            wspace=0.3, hspace=0.5)
    return fig, axes


PROFILE_MARGINS = (0.62, 0.5, 0.12, 0.28)


def footer(fig, text):
    fig.text(0.01, 0.003, text, fontsize=6, color=GREY)


def svg(fig, salt="pdp"):
    """The figure as inline SVG text (no XML prologue). Every element id, and
    every reference to one, is prefixed with ``salt`` + "-": figures with
    different salts share one HTML page without clashing ids (matplotlib
    numbers its groups figure_1, axes_1, ... in every figure), and the same
    figure gives the same text."""
    buf = io.StringIO()
    with matplotlib.rc_context({"svg.hashsalt": salt}):
        fig.savefig(buf, format="svg", metadata={"Date": None})
    text = buf.getvalue()
    text = text[text.index("<svg"):]
    text = re.sub(r'\bid="([^"]+)"', rf'id="{salt}-\1"', text)
    text = re.sub(r'url\(#([^)]+)\)', rf'url(#{salt}-\1)', text)
    return re.sub(r'href="#([^"]+)"', rf'href="#{salt}-\1"', text)


def note(ax, text):
    """A panel that has nothing to plot says why."""
    ax.set_axis_off()
    ax.text(0.5, 0.5, text, ha="center", va="center", wrap=True, fontsize=8, color=BLACK, transform=ax.transAxes)


def get(obj, *path):
    for key in path:
        if obj is None:
            return None
        if isinstance(key, int):
            obj = obj[key] if isinstance(obj, list) and len(obj) > key else None
        else:
            obj = obj.get(key) if isinstance(obj, dict) else None
    return obj


# --- profile figures: one value per row against position ---------------------
# Each takes the rows of a profile (pdp process JSON's "profile", or
# pdp.process(files).profile) and draws in ``ax`` when given (to compose
# figures), else in a figure of its own; it returns the figure.


def _profile_axes(ax):
    """The axes to draw a profile figure in: the caller's, or a new figure's."""
    if ax is not None:
        return ax.figure, ax
    fig, ((ax,),) = figure(margins=PROFILE_MARGINS)
    return fig, ax


def positions_mm(rows):
    """Each row's position in mm, or its number (from 1) when any row has no position."""
    missing = [i + 1 for i, r in enumerate(rows) if number(r.get("position")) is None]
    if not missing:
        return [1e3 * float(r["position"]) for r in rows], "position (mm)"
    if len(missing) == len(rows):
        return list(range(1, len(rows) + 1)), "row (no positions given)"
    return list(range(1, len(rows) + 1)), f"row (no position for row {', '.join(map(str, missing))})"


def _series(ax, y, rows, value, interval=None, scale=1.0, **style):
    """Points with horizontal error bars, joined in order of position; a row
    without a value breaks the line (a gap is not bridged). Returns how many
    rows have a value."""
    order = sorted(range(len(rows)), key=lambda i: y[i])
    xs, ys, lo, hi = [], [], [], []
    for i in order:
        v = number(value(rows[i]))
        ys.append(y[i])
        xs.append(math.nan if v is None else v * scale)
        a, b = (number(x) for x in ((interval(rows[i]) if interval else None) or (None, None)))
        lo.append(max(0.0, v * scale - a * scale) if v is not None and a is not None else 0.0)
        hi.append(max(0.0, b * scale - v * scale) if v is not None and b is not None else 0.0)
    shown = sum(1 for x in xs if not math.isnan(x))
    if shown:
        ax.errorbar(xs, ys, xerr=[lo, hi] if interval else None, capsize=2.5, **style)
    if ys:  # every row's position on the axis, drawn or not
        pad = 0.04 * (max(ys) - min(ys)) or 1.0
        ax.set_ylim(min(ys) - pad, max(ys) + pad)
    return shown


def _finish(ax, ylabel, xlabel, title, legend_size=None):
    ax.set_ylabel(ylabel)
    ax.set_xlabel(xlabel)
    ax.set_title(title)
    legend(ax, fontsize=legend_size)


# --- legends where the data is not ------------------------------------------------
# matplotlib's loc="best" takes the place that covers the fewest line
# vertices, markers ignored, and covers data when every place does; error
# bars, text beside points and arrows it does not see. Here a legend goes to
# the first place inside its axes that covers nothing drawn, measured in
# display pixels, else beneath the axes' tick labels and label, the figure
# grown to hold it.

# Each place inside the axes and the anchor (Bbox.anchored) matplotlib puts a legend there by.
_INSIDE = (("upper right", "NE"), ("upper left", "NW"), ("lower right", "SE"), ("lower left", "SW"),
           ("upper center", "N"), ("lower center", "S"), ("center right", "E"), ("center left", "W"),
           ("center", "C"))
_CLEARANCE = 3.0  # points kept free around a legend
# Text measured at one resolution is up to ~6 % taller or wider at another
# (hinting: 63 pt at 72 dpi, 68 at 100, 72 at 120 for one 6-line legend);
# the free place around a legend grows with it by this fraction of its size.
_GROWTH = 0.08


def _around(box, pad):
    """box with pad pixels and _GROWTH of its size added on every side."""
    w, h = pad + _GROWTH * box.width, pad + _GROWTH * box.height
    return Bbox.from_extents(box.x0 - w, box.y0 - h, box.x1 + w, box.y1 + h)


def _renderer(fig):
    """A renderer to measure text with: the canvas's, or Agg's (the one the
    SVG's layout is measured with too) for a canvas that has none."""
    get = getattr(fig.canvas, "get_renderer", None)
    return get() if get else RendererAgg(int(fig.bbox.width), int(fig.bbox.height), fig.dpi)


def _no_line(style):
    return style in (None, "None", "none", "", " ")


def _drawn(ax, renderer):
    """What the axes draw, in display pixels: (polylines as (n, 2) arrays,
    boxes clipped to the axes as an (n, 4) array x0 y0 x1 y1, boxes of text
    and arrows, which are not clipped, filled areas as closed paths)."""
    ax.get_xlim(), ax.get_ylim()  # autoscaling done: the transforms are final
    points = renderer.points_to_pixels(1.0)
    lines, boxes, texts, areas = [], [], [], []

    def box(b):
        return [b.x0, b.y0, b.x1, b.y1]

    for line in ax.lines:
        if not line.get_visible():
            continue
        xy = line.get_transform().transform(np.asarray(line.get_xydata(), dtype=float))
        if not _no_line(line.get_linestyle()) and len(xy) > 1:
            lines.append(xy)
        if not _no_line(line.get_marker()):
            r = points * (0.5 * line.get_markersize() + line.get_markeredgewidth())
            xy = xy[np.isfinite(xy).all(axis=1)]
            boxes.extend(np.column_stack([xy - r, xy + r]))
    for c in ax.collections:
        if not c.get_visible():
            continue
        if isinstance(c, LineCollection):  # error bars
            transform = c.get_transform()
            lines.extend(transform.transform(np.asarray(v, dtype=float)) for v in c.get_segments() if len(v))
        elif type(c) is PolyCollection and not np.any(c.get_offsets()):  # fill_between(x): a band, by its outline
            # (its bounding box would keep a legend off a diagonal band's empty side)
            transform = c.get_transform()
            areas.extend(transform.transform_path(p) for p in c.get_paths() if len(p.vertices))
        else:
            boxes.append(box(c.get_window_extent(renderer)))
    for patch in ax.patches:
        if not patch.get_visible():
            continue
        if patch.get_fill():  # bars
            boxes.append(box(patch.get_window_extent(renderer)))
        else:  # steps
            path = patch.get_transform().transform_path(patch.get_path())
            lines.extend(path.to_polygons(closed_only=False))
    for text in ax.texts:
        if not text.get_visible():
            continue
        if text.get_text():
            texts.append(box(text.get_window_extent(renderer)))
        arrow = getattr(text, "arrow_patch", None)
        if arrow is not None:
            text.update_positions(renderer)
            texts.append(box(arrow.get_window_extent(renderer)))
    return (lines, np.array(boxes, dtype=float).reshape(-1, 4), np.array(texts, dtype=float).reshape(-1, 4),
            areas)


def _overlap(boxes, b):
    return bool(np.any((boxes[:, 0] < b.x1) & (boxes[:, 2] > b.x0) & (boxes[:, 1] < b.y1) & (boxes[:, 3] > b.y0)))


def _covers(b, drawn, clip):
    """Whether box b covers anything drawn (data is clipped to the axes' box)."""
    lines, boxes, texts, areas = drawn
    if _overlap(texts, b):
        return True
    inner = Bbox.intersection(b, clip)
    if inner is None:
        return False
    if _overlap(boxes, inner):
        return True
    if any(area.intersects_bbox(inner, filled=True) for area in areas):  # its edge, or the box inside it
        return True
    for xy in lines:
        finite = np.isfinite(xy).all(axis=1)
        for run in np.split(xy, np.flatnonzero(np.diff(finite.astype(int))) + 1):  # a NaN breaks a line
            run = run[np.isfinite(run).all(axis=1)]
            if len(run) and Path(run).intersects_bbox(inner, filled=False):
                return True
    return False


def legend(ax, fontsize=None):
    """The axes' legend where it covers no data: the first place inside the
    axes whose box, with 3 points around it, covers no point, line, error
    bar, bar, step, reference line or label the axes draw; where there is
    none, beneath the axes' tick labels and label (in as many columns as fit
    the axes' width, at most 3), the figure grown to hold it. Call it when
    the axes are complete (limits set). Returns the legend, or None without
    labelled artists."""
    handles, labels = ax.get_legend_handles_labels()
    if not handles:
        return None
    fig = ax.figure
    renderer = _renderer(fig)
    drawn = _drawn(ax, renderer)
    pad = renderer.points_to_pixels(_CLEARANCE)
    # Made once and measured: each place's box is the legend's size anchored
    # in the axes inset by its border pad, as matplotlib places it.
    placed = ax.legend(handles, labels, loc=_INSIDE[0][0], fontsize=fontsize)
    size = placed.get_window_extent(renderer)
    inset = ax.bbox.padded(-placed.borderaxespad * renderer.points_to_pixels(placed.prop.get_size_in_points()))
    for loc, anchor in _INSIDE:
        if not _covers(_around(size.anchored(anchor, container=inset), pad), drawn, ax.bbox):
            return placed if loc == _INSIDE[0][0] else ax.legend(handles, labels, loc=loc, fontsize=fontsize)
    below = ax.xaxis.get_tightbbox(renderer)
    bottom = min(ax.bbox.y0, below.y0 if below is not None else ax.bbox.y0) - pad
    anchor = (0.5, (bottom - ax.bbox.y0) / ax.bbox.height)
    for ncol in range(min(3, len(handles)), 0, -1):
        placed = ax.legend(handles, labels, loc="upper center", bbox_to_anchor=anchor, bbox_transform=ax.transAxes,
                           ncol=ncol, fontsize=fontsize)
        extent = placed.get_window_extent(renderer)
        if extent.width <= ax.bbox.width:
            break
    need = _floor_beneath(ax, extent, renderer) - _around(extent, pad).y0
    if need > 0:
        _grow_beneath(fig, ax.bbox.y0, need)
    return placed


def _floor_beneath(ax, extent, renderer):
    """The highest display y that a legend beneath ax must stay above: the
    tops of the axes below it (with room for a one-line title, which a panel
    drawn later may still get, or above the title it has: the bubble panels'
    are two lines) and the figure's own texts (a footer) under it, else the
    figure's bottom edge."""
    title = renderer.get_text_width_height_descent("Ag", FontProperties(size=matplotlib.rcParams["axes.titlesize"]),
                                                   ismath=False)[1]
    title += renderer.points_to_pixels(matplotlib.rcParams["axes.titlepad"])
    floor = 0.0
    for other in ax.figure.axes:
        b = other.bbox
        if other is not ax and b.y1 <= ax.bbox.y0 and b.x0 < extent.x1 and b.x1 > extent.x0:
            floor = max(floor, b.y1 + title)
            if other.title.get_text():
                floor = max(floor, other.title.get_window_extent(renderer).y1)
    for text in ax.figure.texts:
        b = text.get_window_extent(renderer)
        if b.y1 <= ax.bbox.y0 and b.x0 < extent.x1 and b.x1 > extent.x0:
            floor = max(floor, b.y1)
    return floor


def _grow_beneath(fig, y, pixels):
    """Opens a band `pixels` high at display height y: the figure grows and
    every axes at or above y moves up, each keeping its size in inches."""
    width, height = fig.get_size_inches()
    grow = pixels / fig.dpi
    positions = [(a, a.get_position()) for a in fig.axes]
    fig.set_size_inches(width, height + grow)
    for a, p in positions:
        lift = grow if p.y0 * height * fig.dpi >= y - 0.5 else 0.0
        a.set_position([p.x0, (p.y0 * height + lift) / (height + grow), p.width, p.height * height / (height + grow)])


def _not_ok(ax, what, result):
    """True, said in the panel, when a structure result (clusters, arrivals) has nothing to draw."""
    if result and result.get("status") == "ok":
        return False
    note(ax, f"{what}: " + ((result or {}).get("reason") or "not computed"))
    return True


def _both_tips(rows, ax, key, xlabel, title):
    """A phase quantity of both tips (``key`` and ``key_ci95`` in each tip) against position."""
    fig, ax = _profile_axes(ax)
    y, ylabel = positions_mm(rows)
    for tip, colour, marker, ls, name in ((0, BLUE, "o", "-", "leading"), (1, ORANGE, "s", "--", "trailing")):
        _series(ax, y, rows, lambda r: get(r, "tips", tip, key), lambda r: get(r, "tips", tip, key + "_ci95"),
                color=colour, marker=marker, ls=ls, label=f"{name} tip, 95 % interval")
    ax.set_xlim(left=0)
    _finish(ax, ylabel, xlabel, title)
    return fig


def profile_void_fraction(rows, ax=None):
    return _both_tips(rows, ax, "void_fraction", "void fraction c (-)", "Void fraction")


def profile_count_rate(rows, ax=None):
    return _both_tips(rows, ax, "bubble_count_rate", "bubble count rate F (1/s)", "Bubble count rate")


def _awcc_and_corrected(ax, y, rows, quantity, measured_label):
    """AWCC's value of a quantity with its 95 % interval (and, under the
    bubble-probe correction, the value measured before it), and the
    corrected median with its 95 % (thin) and 80 % (thick) bands."""
    if any(get(r, "awcc", "probe_corrected") for r in rows):
        _series(ax, y, rows, lambda r: get(r, "awcc", quantity + "_measured"), color=SKY, marker="v", ls=":",
                label="AWCC before the probe correction")
        measured_label = "AWCC probe-corrected, 95 % interval"
    _series(ax, y, rows, lambda r: get(r, "awcc", quantity), lambda r: get(r, "awcc", quantity + "_ci95"),
            color=BLUE, marker="o", ls="-", label=measured_label)
    # Rows corrected by an extended model's FSCC forest (no usable AWCC
    # result; the velocity only) are drawn apart, so that a reader sees which
    # forest each corrected value comes from.
    for forest, colour, mark, what in (("awcc", VERMILION, "^", "corrected"),
                                       ("fscc", PURPLE, "s", "corrected from FSCC (no usable AWCC)")):
        def corrected(r, forest=forest):
            if (get(r, "correction", "forest") or "awcc") != forest or _untrusted(r, quantity):
                return None
            return get(r, "correction", quantity, "median")
        for low, high, marker, width, label in (("0.025", "0.975", None, 1.0, f"{what}, 95 % band"),
                                                ("0.1", "0.9", mark, 3.0, f"{what} median, 80 % band")):
            if forest == "fscc" and not any(corrected(r) is not None for r in rows):
                continue  # no such rows: no legend entry
            _series(ax, y, rows, corrected, lambda r, lo=low, hi=high: _quantiles(r, quantity, lo, hi), color=colour,
                    marker=marker, ls="none", elinewidth=width, label=label)


def _quantiles(r, q, a, b):
    qs = get(r, "correction", q, "quantiles")
    return (qs.get(a), qs.get(b)) if qs else None


def _untrusted(r, quantity=None):
    """A correction whose quantiles are kept but not presented as corrected:
    an untrusted row, or (of `quantity`) a quantity whose median the trust
    rules hold back on a corrected row (a reason in its object: Tu, rule (e)
    of correction/model.hpp)."""
    if get(r, "correction", "status") == "untrusted":
        return True
    return quantity is not None and get(r, "correction", quantity, "reason") is not None


def _untrusted_medians(ax, y, rows, quantity, unit):
    """Untrusted corrections' medians, drawn apart (hollow, grey, no band)
    once the axes' limits are set, which they leave as they are: one beyond
    them is drawn at the edge, pointing out, with its value."""
    # An untrusted row's median is null: the forest's answer is its 0.5 quantile.
    points = [(y[i], number(get(r, "correction", quantity, "quantiles", "0.5"))) for i, r in enumerate(rows)
              if _untrusted(r, quantity)]
    points = [(yi, v) for yi, v in points if v is not None]
    if not points:
        return
    lo, hi = ax.get_xlim()
    style = dict(ls="none", mfc="none", mec=GREY, mew=1.5, ms=8)
    for yi, v in points:
        x, marker, side = (hi, ">", -1) if v > hi else (lo, "<", 1) if v < lo else (v, "o", 0)
        ax.plot([x], [yi], marker=marker, clip_on=False, scalex=False, scaley=False, **style)
        if side:
            ax.annotate(f"{v:.3g} {unit}".rstrip(), (x, yi), textcoords="offset points", xytext=(8 * side, 0),
                        ha="left" if side > 0 else "right", va="center", fontsize=7, color=GREY)
    ax.plot([], [], marker="o", label="untrusted correction's median (not a corrected value)", **style)
    ax.set_xlim(lo, hi)


def _from_fscc_forest(r):
    return get(r, "correction", "forest") == "fscc"


def _limit_to_the_measured(ax, y, rows, quantity, unit, measured):
    """The value axis set by what was measured and the corrections of the
    AWCC forest with their bands; a row corrected by the FSCC forest (no
    usable AWCC: a sparse row, whose 95 % band can reach twice the flow's
    velocity) sets it by its median and 80 % band only, its 95 % band
    clipped at the edge with a marker and its end, instead of stretching
    the axis for every other row."""
    values = [v for r in rows for v in measured(r) if v is not None]
    for r in rows:
        if _untrusted(r, quantity):
            continue
        values += [number(get(r, "correction", quantity, "median"))]
        band = _quantiles(r, quantity, "0.1", "0.9") if _from_fscc_forest(r) else \
            _quantiles(r, quantity, "0.025", "0.975")
        values += list(band) if band else []
    values = [v for v in values if v is not None and math.isfinite(v)]
    if not values:
        return
    lo, hi = min(values), max(values)
    pad = 0.05 * (hi - lo) if hi > lo else 0.05 * abs(hi) + 1e-9
    lo, hi = lo - pad, hi + pad
    style = dict(ls="none", color=GREY, ms=6, clip_on=False, scalex=False, scaley=False)
    clipped = False
    for yi, r in zip(y, rows):
        band = _quantiles(r, quantity, "0.025", "0.975") if _from_fscc_forest(r) and not _untrusted(r, quantity) \
            else None
        if not band or band[0] is None or band[1] is None:
            continue
        for end, edge, marker, side in ((band[1], hi, ">", -1), (band[0], lo, "<", 1)):
            if (end > edge) if side < 0 else (end < edge):
                ax.plot([edge], [yi], marker=marker, **style)
                ax.annotate(f"95 % to {end:.3g} {unit}".rstrip(), (edge, yi), textcoords="offset points",
                            xytext=(-8 * -side if side > 0 else -8, 6), ha="right" if side < 0 else "left",
                            va="bottom", fontsize=7, color=GREY)
                clipped = True
    if clipped:
        ax.plot([], [], marker=">", ls="none", color=GREY, label="a 95 % band beyond the axis (its end written)")
    ax.set_xlim(lo, hi)


def profile_velocity(rows, ax=None):
    fig, ax = _profile_axes(ax)
    y, ylabel = positions_mm(rows)
    _series(ax, y, rows, lambda r: get(r, "fscc", "velocity"), color=BLACK, marker="D", ls=":", mfc="none",
            label="FSCC")
    _awcc_and_corrected(ax, y, rows, "velocity", "AWCC, 95 % interval")
    _limit_to_the_measured(ax, y, rows, "velocity", "m/s", lambda r: [
        number(get(r, "fscc", "velocity")), number(get(r, "awcc", "velocity")),
        *(number(v) for v in (get(r, "awcc", "velocity_ci95") or []))])
    _untrusted_medians(ax, y, rows, "velocity", "m/s")
    _finish(ax, ylabel, "mean interfacial velocity (m/s)", "Velocity")
    return fig


def profile_turbulence(rows, ax=None):
    fig, ax = _profile_axes(ax)
    y, ylabel = positions_mm(rows)
    _awcc_and_corrected(ax, y, rows, "turbulence_intensity", "AWCC, 95 % interval")
    ax.set_xlim(left=0)
    _untrusted_medians(ax, y, rows, "turbulence_intensity", "")
    _finish(ax, ylabel, "turbulence intensity Tu (-)", "Turbulence intensity (AWCC)")
    return fig


def profile_chanson(rows, ax=None):
    fig, ax = _profile_axes(ax)
    y, ylabel = positions_mm(rows)
    _series(ax, y, rows, lambda r: get(r, "fscc", "turbulence_intensity_chanson"), color=BLACK, marker="D",
            ls=":", mfc="none", label="0.851 sqrt(tau05^2 - T05^2) / lag")
    ax.set_xlim(left=0)
    _finish(ax, ylabel, "Tu from FSCC (-); not comparable to AWCC's", "Chanson's turbulence intensity")
    return fig


def profile_sauter(rows, ax=None):
    fig, ax = _profile_axes(ax)
    y, ylabel = positions_mm(rows)
    _series(ax, y, rows, lambda r: get(r, "tips", 0, "sauter_diameter"), scale=1e3, color=GREEN, marker="o",
            ls="-", label="d32 = 1.5 u c / F")
    ax.set_xlim(left=0)
    _finish(ax, ylabel, "Sauter diameter d32 (mm)", "Sauter diameter")
    return fig


def profile_yield(rows, ax=None):
    """Accepted / total AWCC windows, each row marked with its quality level."""
    fig, ax = _profile_axes(ax)
    y, ylabel = positions_mm(rows)
    seen = set()
    for yi, r in zip(y, rows):
        quality = get(r, "awcc", "quality")
        colour, marker = QUALITY_STYLE.get(quality, QUALITY_STYLE[None])
        total, accepted = get(r, "awcc", "windows_total"), get(r, "awcc", "windows_accepted")
        value = accepted / total if total else 0.0
        label = quality or "AWCC not run"
        ax.plot([value], [yi], marker=marker, color=colour, ls="none", markersize=7,
                label=None if label in seen else label)
        seen.add(label)
        ax.annotate(f"{accepted}/{total}" if total is not None else "not run", (value, yi), fontsize=7,
                    va="center", textcoords="offset points", xytext=(6, 0))
    ax.set_xlim(0, 1.15)
    _finish(ax, ylabel, "AWCC data yield: accepted / total windows (-)", "Data yield and quality level")
    return fig


PROFILE_FIGURES = [
    ("void-fraction", "Void fraction", profile_void_fraction),
    ("count-rate", "Bubble count rate", profile_count_rate),
    ("velocity", "Velocity", profile_velocity),
    ("turbulence", "Turbulence intensity", profile_turbulence),
    ("chanson", "Chanson's FSCC turbulence intensity", profile_chanson),
    ("sauter", "Sauter diameter", profile_sauter),
    ("yield", "Data yield and quality", profile_yield),
]


# --- a profile as a flow: the profile JSON's "flow" (METHOD 12) --------------
# Every quantity drawn or written is the one pdp process wrote; the curves are
# the models' formulas (awcc/profile_flow.hpp, written here once) evaluated
# with the D', D_0, N, u90 and Y90 of the JSON.

_ATANH_SQRT_01 = math.atanh(math.sqrt(0.1))  # c(Y90) = 0.9: tanh^2 of it is 0.1


def smooth_chute_c(y, diffusivity, y90):
    """Chanson (1997): c = 1 - tanh^2(K' - y' / (2 D')), K' = atanh(sqrt(0.1))
    + 1 / (2 D'), y' = y / Y90."""
    yp = np.asarray(y, dtype=float) / y90
    k = _ATANH_SQRT_01 + 1 / (2 * diffusivity)
    return 1 - np.tanh(k - yp / (2 * diffusivity)) ** 2


def stepped_chute_c(y, diffusivity, y90):
    """Chanson & Toombes (2002): c = 1 - tanh^2(K' - y' / (2 D_0) + (y' -
    1/3)^3 / (3 D_0)), K' = atanh(sqrt(0.1)) + 1 / (2 D_0) - 8 / (81 D_0)."""
    yp = np.asarray(y, dtype=float) / y90
    k = _ATANH_SQRT_01 + 1 / (2 * diffusivity) - 8 / (81 * diffusivity)
    return 1 - np.tanh(k - yp / (2 * diffusivity) + (yp - 1 / 3) ** 3 / (3 * diffusivity)) ** 2


def power_law_u(y, n, u90, y90):
    """u = u90 (y / Y90)^(1/N)."""
    return u90 * (np.asarray(y, dtype=float) / y90) ** (1 / n)


# (JSON key, symbol, name, formula, colour, line style) of the air-concentration models.
CONCENTRATION_MODELS = (("smooth_chute", "D'", "smooth chute (Chanson 1997)", smooth_chute_c, BLUE, "-"),
                        ("stepped_chute", "D_0", "stepped chute (Chanson & Toombes 2002)", stepped_chute_c,
                         VERMILION, "--"))

# How each row's velocity source is drawn: (name, colour, marker, hollow).
VELOCITY_SOURCES = {"corrected awcc": ("corrected AWCC (median, 95 % band)", VERMILION, "^", False),
                    "awcc": ("AWCC, 95 % interval", BLUE, "o", False),
                    "fscc": ("FSCC, 95 % interval", BLACK, "D", True)}

# A figure's own reasons, beneath it: text of this size, wrapped to this many characters a line.
_REASON_SIZE, _REASON_CHARS, _REASON_LINE = 7, 88, 7 * 1.25 / 72  # points, characters, inches a line


def depth_name(level):
    """Y90, Y50, Y95, Y92.5: the name papers give the depth where c = level."""
    return f"Y{100 * level:.10g}"


def flow_depths(flow):
    """Y90 then the further levels: the JSON's depth objects, each with its name."""
    return [(depth_name(d.get("level", 0.9)), d) for d in [flow.get("y90") or {}] + list(flow.get("levels") or [])]


def flow_rows(rows, flow):
    """The flow's rows (increasing y) with their intervals, which the flow
    object does not repeat: c's from the leading tip, the velocity's from the
    source the row names (the corrected quantiles, AWCC's or FSCC's
    interval), each found in the profile row at the same position (a
    position is one recording: pdp refuses it twice). Each: y (m), c,
    c_ci95, u, source, u_ci95."""
    by_position = {number(r.get("position")): r for r in rows}
    out = []
    for f in flow.get("rows") or []:
        y, row = number(f.get("position")), by_position.get(number(f.get("position"))) or {}
        source = f.get("velocity_source")
        if source == "corrected awcc":
            u_ci = _quantiles(row, "velocity", "0.025", "0.975")
        elif source in ("awcc", "fscc"):
            u_ci = get(row, source, "velocity_ci95")
        else:
            u_ci = None
        out.append({"y": y, "c": number(f.get("void_fraction")), "c_ci95": get(row, "tips", 0, "void_fraction_ci95"),
                    "u": number(f.get("velocity")), "source": source, "u_ci95": list(u_ci) if u_ci else None,
                    "name": f.get("name")})
    return out


def interval_text(q, scale=1.0, digits=3):
    """'value [lower, upper]' of a flow quantity, scaled."""
    v = number(q.get("value"))
    if v is None:
        return "none"
    lo, hi = (number(b) for b in (q.get("ci95") or (None, None)))
    text = f"{scale * v:.{digits}g}"
    return text + (f" [{scale * lo:.{digits}g}, {scale * hi:.{digits}g}]" if lo is not None and hi is not None
                   else " (no interval)")


def _flow_figure(title_lines=1):
    """A profile figure with room for a title of title_lines lines."""
    left, bottom, right, top = PROFILE_MARGINS
    more = 0.14 * (title_lines - 1)
    fig, ((ax,),) = figure(height=3.4 + more, margins=(left, bottom, right, top + more))
    return fig, ax


def _flow_refused(flow):
    """The reason a profile has no flow quantities at all, or None."""
    if flow is None:
        return "no flow quantities: a profile needs two or more recordings with their positions (pdp process " \
               "--positions)"
    if flow.get("status") == "refused":
        return f"the profile's flow quantities were refused: {flow.get('reason')}"
    return None


def _flow_y_limits(ax, ys):
    """From the invert (the curves start there) to above the highest point or depth drawn."""
    top = max([y for y in ys if y is not None] or [1.0])
    ax.set_ylim(0, 1.06 * top)


def _depth_markers(ax, flow, ys):
    """Each characteristic depth with its 95 % interval at (its level, Yc); a
    depth below the first position as its bound y_0, pointing down. Appends
    the heights drawn to ys; returns the reasons of the depths without a
    value."""
    reasons = []
    styles = [(GREEN, "s"), (PURPLE, "P"), (ORANGE, "X"), (SKY, "h"), (BLACK, "*")]
    for k, (name, d) in enumerate(flow_depths(flow)):
        colour, marker = styles[k % len(styles)]
        v, x = number(d.get("value")), d.get("level", 0.9)
        if v is not None:
            lo, hi = (number(b) for b in (d.get("ci95") or (None, None)))
            err = [[1e3 * (v - lo)], [1e3 * (hi - v)]] if lo is not None and hi is not None else None
            ax.errorbar([x], [1e3 * v], yerr=err, color=colour, marker=marker, ms=7, ls="none", capsize=3,
                        mec=BLACK, mew=0.6, label=f"{name} = {interval_text(d, 1e3, 4)} mm")
            ys += [1e3 * (hi if hi is not None else v)]
        elif d.get("status") == "below_first_position" and number(d.get("position")) is not None:
            ax.plot([x], [1e3 * d["position"]], color=colour, marker="v", ms=7, ls="none", mec=BLACK, mew=0.6,
                    label=f"{name} < {1e3 * d['position']:.3g} mm (below the first position)")
            reasons.append(f"{name}: {d.get('reason')}")
        else:
            reasons.append(f"{name}: {d.get('reason') or d.get('status')}")
    return reasons


def flow_concentration(rows, flow, ax=None):
    """c(y) as hydraulics papers draw a profile (y from the invert up): the
    measured points with their 95 % intervals, both air-concentration models
    fitted with c(Y90) = 0.9 (the curve at the written D and Y90, over
    0 <= y <= Y90, where they were fitted) with their bands (the curve at D's
    2.5 and 97.5 % values, Y90 held), the characteristic depths with their
    intervals, C_mean and d in the title. Without Y90 no curve, and the
    reasons beneath the axes."""
    refused = _flow_refused(flow)
    flow = flow or {}
    c_mean, depth = flow.get("c_mean") or {}, flow.get("clear_water_depth") or {}
    stated = number(c_mean.get("value")) is not None
    reasons = [refused] if refused else []
    fig, ax = _flow_figure(2 if stated else 1) if ax is None else (ax.figure, ax)
    points = flow_rows(rows, flow)
    ys = [1e3 * p["y"] for p in points if p["y"] is not None]
    drawn = [p for p in points if p["y"] is not None and p["c"] is not None]
    if drawn:
        lo = [max(0.0, p["c"] - number(get(p, "c_ci95", 0))) if number(get(p, "c_ci95", 0)) is not None else 0.0
              for p in drawn]
        hi = [max(0.0, number(get(p, "c_ci95", 1)) - p["c"]) if number(get(p, "c_ci95", 1)) is not None else 0.0
              for p in drawn]
        ax.errorbar([p["c"] for p in drawn], [1e3 * p["y"] for p in drawn], xerr=[lo, hi], color=BLACK, marker="o",
                    ms=5, mfc="white", ls="none", capsize=2.5, zorder=3, label="measured c, 95 % interval")
    y90, curves = number((flow.get("y90") or {}).get("value")), False
    if not refused:
        reasons += _depth_markers(ax, flow, ys)
        if y90 is None:  # the depth's own reason is above
            reasons.append("No Y90: no fitted curves (D', D_0), no C_mean, no d.")
        for key, symbol, name, model, colour, ls in CONCENTRATION_MODELS:
            fit = flow.get(key) or {}
            d = number(fit.get("value"))
            if d is None or y90 is None:
                if y90 is not None:
                    reasons.append(f"{symbol}, {name}: no curve: {fit.get('reason') or 'not fitted'}")
                continue
            y = np.linspace(0.0, y90, 241)
            lo, hi = (number(b) for b in (fit.get("ci95") or (None, None)))
            if lo is not None and hi is not None:
                ax.fill_betweenx(1e3 * y, model(y, lo, y90), model(y, hi, y90), color=colour, alpha=0.18, lw=0)
            residual = number(fit.get("residual"))
            curves = True
            ax.plot(model(y, d, y90), 1e3 * y, color=colour, ls=ls, lw=1.5,
                    label=f"{name}:\n{symbol} = {interval_text(fit)}"
                    + (f", rms {residual:.2g}" if residual is not None else ""))
    if stated:
        ax.set_title(f"Air concentration\nC_mean = {interval_text(c_mean)}, d = {interval_text(depth, 1e3)} mm")
    else:
        ax.set_title("Air concentration")
        if not refused and y90 is not None:
            reasons.append(f"C_mean: {c_mean.get('reason')}")
    if not drawn and not refused:
        reasons.append("no row has a void fraction")
    ax.set_xlim(0, 1)
    _flow_y_limits(ax, ys)
    ax.set_xlabel("void fraction c (-)" + ("; bands: D at its 95 % ends, Y90 held" if curves else ""))
    ax.set_ylabel("y from the invert (mm)")
    _reasons_beneath(fig, ax, reasons)
    legend(ax)
    return fig


def _reasons_beneath(fig, ax, reasons):
    """The reasons beneath the axes (wrapped), the figure grown to hold them."""
    if not reasons:
        return
    import textwrap
    lines = [line for r in reasons for line in textwrap.wrap(r, _REASON_CHARS, subsequent_indent="  ")]
    _grow_beneath(fig, fig.bbox.y0 + 1.0, (_REASON_LINE * len(lines) + 0.1) * fig.dpi)
    fig.text(0.06, 0.04, "\n".join(lines), fontsize=_REASON_SIZE, color=BLACK, va="bottom", ha="left",
             linespacing=1.25, transform=fig.dpi_scale_trans)


def flow_velocity(rows, flow, ax=None):
    """u(y): each row's velocity with its 95 % interval, marked by the source
    the row contributes (corrected AWCC, AWCC, FSCC); the power law u90
    (y / Y90)^(1/N) with its band (u90 and N both at their interval's ends:
    wider than a joint band, the draws' correlation not being written), N
    and u90 in the legend. Without them, the reason beneath the axes."""
    refused = _flow_refused(flow)
    flow = flow or {}
    reasons = [refused] if refused else []
    fig, ax = _flow_figure() if ax is None else (ax.figure, ax)
    points = flow_rows(rows, flow)
    ys = [1e3 * p["y"] for p in points if p["y"] is not None]
    for source, (name, colour, marker, hollow) in VELOCITY_SOURCES.items():
        drawn = [p for p in points if p["source"] == source and p["u"] is not None and p["y"] is not None]
        if not drawn:
            continue
        ci = [(number(get(p, "u_ci95", 0)), number(get(p, "u_ci95", 1))) for p in drawn]
        lo = [max(0.0, p["u"] - a) if a is not None else 0.0 for p, (a, _) in zip(drawn, ci)]
        hi = [max(0.0, b - p["u"]) if b is not None else 0.0 for p, (_, b) in zip(drawn, ci)]
        ax.errorbar([p["u"] for p in drawn], [1e3 * p["y"] for p in drawn], xerr=[lo, hi], color=colour,
                    marker=marker, ms=6, mfc="white" if hollow else colour, ls="none", capsize=2.5, zorder=3,
                    label=name)
    without = [p["name"] for p in points if p["u"] is None]
    if without and not refused:
        reasons.append(f"no velocity at {', '.join(map(str, without))} (the notes say why)")
    # The axis spans the points with their intervals and u90's: the law below
    # the first position, down to u = 0 at the invert, is clipped.
    span = [x for p in points if p["u"] is not None for x in (p["u"], number(get(p, "u_ci95", 0)),
                                                              number(get(p, "u_ci95", 1))) if x is not None]
    power = flow.get("power_law") or {}
    n, u90 = power.get("n") or {}, power.get("u90") or {}
    span += [x for x in [number(u90.get("value"))] + [number(b) for b in (u90.get("ci95") or [])] if x is not None]
    y90 = number((flow.get("y90") or {}).get("value"))
    curves = not refused and None not in (number(n.get("value")), number(u90.get("value")), y90)
    if not refused:
        if curves:
            y = np.linspace(0.0, y90, 241)
            (n_lo, n_hi), (u_lo, u_hi) = (n.get("ci95") or (None, None)), (u90.get("ci95") or (None, None))
            if None not in (n_lo, n_hi, u_lo, u_hi):  # (y/Y90)^(1/N) grows with N below Y90
                ax.fill_betweenx(1e3 * y, power_law_u(y, n_lo, u_lo, y90), power_law_u(y, n_hi, u_hi, y90),
                                 color=GREEN, alpha=0.2, lw=0)
            ax.plot(power_law_u(y, n["value"], u90["value"], y90), 1e3 * y, color=GREEN, lw=1.5,
                    label=f"u90 (y/Y90)^(1/N): N = {interval_text(n)},\nu90 = {interval_text(u90)} m/s")
            ax.axhline(1e3 * y90, color=GREY, ls=":", lw=1.0, label=f"Y90 = {1e3 * y90:.4g} mm")
            ys.append(1e3 * y90)
        elif y90 is None:
            reasons.append(f"No power law (N, u90): no Y90: {(flow.get('y90') or {}).get('reason')}")
        else:
            reasons.append(f"No power law: {n.get('reason') or u90.get('reason') or 'not fitted'}")
    ax.set_title("Velocity and power law")
    if span:
        pad = 0.08 * (max(span) - min(span)) or 0.1 * abs(max(span)) or 1.0
        ax.set_xlim(max(0.0, min(span) - pad), max(span) + pad)
    _flow_y_limits(ax, ys)
    ax.set_xlabel("velocity u (m/s)" + ("; band: N and u90 at their 95 % ends" if curves else ""))
    ax.set_ylabel("y from the invert (mm)")
    _reasons_beneath(fig, ax, reasons)
    legend(ax)
    return fig


# The flow's figures (drawn when the JSON has a profile): (key, title, make(rows, flow)).
FLOW_FIGURES = [("flow-concentration", "Air concentration with the fitted models", flow_concentration),
                ("flow-velocity", "Velocity with the power law", flow_velocity)]


# --- per-position figures --------------------------------------------------------


def _steps(ax, edges_lower, width, fractions, scale, **style):
    """A PDF as steps over bins (lower, lower + width]; the last (overflow) bin drawn one width wide."""
    xs = [scale * e for e in edges_lower] + [scale * (edges_lower[-1] + width)]
    ax.stairs([number(f) or 0.0 for f in fractions], xs, **style)  # null: a phase without chords


def chord_pdf(ax, pdf, basis):
    if not pdf or not any(number(f) for f in pdf["air_fraction"] + pdf["water_fraction"]):
        note(ax, "no chord lengths: no velocity to convert chord times" if basis == "length" and not pdf
             else "no chords")
        return
    scale, unit = (1e3, "ms") if basis == "time" else (1e3, "mm")
    edges, width = pdf["lower_edges"], pdf["bin_width"]
    _steps(ax, edges, width, pdf["air_fraction"], scale, color=BLUE, lw=1.4, label="air chords")
    _steps(ax, edges, width, pdf["water_fraction"], scale, color=ORANGE, lw=1.2, ls="--", label="water chords")
    _finish(ax, "fraction of chords (-)", f"chord {basis} ({unit}); last bin: above {scale * pdf['max']:g} {unit}",
            f"Chord-{basis} PDF")


def voltage_pdf(ax, structure, tips):
    pdfs = get(structure, "voltage_pdf") or {}
    if not pdfs.get("leading"):
        note(ax, "binary input: no voltage PDF")
        return
    for name, colour, ls, tip in (("leading", BLUE, "-", tips[0]), ("trailing", ORANGE, "--", tips[1])):
        p = pdfs.get(name)
        if not p:
            continue
        lower = [u - (p["upper"][1] - p["lower"][1]) if lo is None else lo for lo, u in zip(p["lower"], p["upper"])]
        ax.stairs(p["fraction"], lower + [p["upper"][-1]], color=colour, ls=ls, label=f"{name} tip")
        ax.axvline(tip["threshold"], color=colour, ls=":", lw=1.2)
        for level, marker in ((tip.get("air_level"), "v"), (tip.get("water_level"), "^")):
            if number(level) is not None:  # at the axis' foot: a log axis has no 0
                ax.plot([level], [0.04], marker=marker, color=colour, ls="none", ms=7,
                        transform=ax.get_xaxis_transform())
    ax.set_yscale("log")
    ax.minorticks_off()  # a third of the panel's drawing time, for no reading
    ax.plot([], [], color=GREY, ls=":", label="threshold")
    ax.plot([], [], color=GREY, marker="v", ls="none", label="air mode")
    ax.plot([], [], color=GREY, marker="^", ls="none", label="water mode")
    _finish(ax, "fraction of samples (-)", "voltage (V)", "Voltage PDF")


def correlation(ax, functions, fscc):
    if functions is None:
        note(ax, "R11 and R12 not available: see this position's note")
        return
    lag = [1e3 * t for t in functions["lag"]]
    ax.plot(lag, functions["r11"], color=BLUE, label="R11 (leading tip)")
    ax.plot(lag, functions["r12"], color=ORANGE, ls="--", label="R12 (cross)")
    if fscc and number(fscc.get("lag")) is not None and number(fscc.get("r12_max")) is not None:
        ax.plot([1e3 * fscc["lag"]], [fscc["r12_max"]], marker="o", color=VERMILION, ls="none",
                label=f"peak: {1e3 * fscc['lag']:.3g} ms, {fscc['r12_max']:.3g}")
        if number(fscc.get("t_half")) is not None:
            half = fscc["r12_max"] / 2
            ax.annotate("", xy=(1e3 * fscc["t_half"], half), xytext=(1e3 * fscc["lag"], half),
                        arrowprops=dict(arrowstyle="<->", color=VERMILION, lw=1))
            ax.plot([], [], color=VERMILION, lw=1, label=f"tau05 = {1e3 * fscc['tau05']:.3g} ms")
    if fscc and number(fscc.get("t05")) is not None:
        ax.annotate("", xy=(1e3 * fscc["t05"], 0.5), xytext=(0, 0.5),
                    arrowprops=dict(arrowstyle="<->", color=GREEN, lw=1))
        ax.plot([], [], color=GREEN, lw=1, label=f"T05 = {1e3 * fscc['t05']:.3g} ms")
    ax.axhline(0, color=BLACK, lw=0.6)
    ax.set_xlim(min(lag[0], 0), lag[-1])
    _finish(ax, "correlation (-)", "lag (ms)", "Auto- and cross-correlation")


def _window_fates(ax, windows, awcc):
    """The windows' velocities with the indices of the accepted ones and of the
    rejected ones that have a velocity; None, said in the panel, without windows."""
    if windows is None or not len(windows["velocity"]):
        if not awcc:
            note(ax, "AWCC not run")
        elif windows is None:
            note(ax, "window table not available: see this position's note")
        else:
            note(ax, "no AWCC windows")
        return None
    v, fate = windows["velocity"], windows["fate"]
    return (v, [i for i in range(len(v)) if fate[i] == "accepted"],
            [i for i in range(len(v)) if fate[i] != "accepted" and v[i] > 0])


def window_series(ax, windows, awcc):
    fates = _window_fates(ax, windows, awcc)
    if fates is None:
        return
    (v, acc, rej), t = fates, windows["start_time"]
    ax.plot([t[i] for i in rej], [v[i] for i in rej], ls="none", marker="x", color=GREY, ms=3.5,
            label=f"rejected ({len(v) - len(acc)}; {len(rej)} with a velocity)", rasterized=len(rej) > 2000)
    ax.plot([t[i] for i in acc], [v[i] for i in acc], ls="none", marker="o", color=BLUE, ms=3,
            label=f"accepted ({len(acc)})", rasterized=len(acc) > 2000)
    if awcc and number(awcc.get("velocity")) is not None:
        ax.axhline(awcc["velocity"], color=VERMILION, lw=1.2, label=f"mean {awcc['velocity']:.3g} m/s")
    if acc:
        top = 2.0 * max(v[i] for i in acc)
        ax.set_ylim(0, top)
        above = sum(1 for i in rej if v[i] > top)
        if above:
            ax.plot([], [], ls="none", label=f"{above} rejected above {top:.3g} m/s not shown")
    _finish(ax, "window velocity (m/s)", "window start (s)", "AWCC window velocities")


def window_histogram(ax, windows, awcc):
    fates = _window_fates(ax, windows, awcc)
    if fates is None:
        return
    v, accepted, rejected = fates
    if not accepted:
        note(ax, "no accepted window")
        return
    acc = [v[i] for i in accepted]
    top = 2.0 * max(acc)
    rej = [v[i] for i in rejected if v[i] <= top]
    bins = max(8, min(40, int(math.sqrt(len(acc)) * 2)))
    edges = [top * k / bins for k in range(bins + 1)]
    above = len(rejected) - len(rej)
    ax.hist([acc, rej], bins=edges, stacked=True, color=[BLUE, GREY],
            label=["accepted", f"rejected ({above} above {top:.3g} m/s not shown)" if above else "rejected"])
    _finish(ax, "windows", "window velocity (m/s)", "Window velocity histogram")


def cluster_sizes(ax, clusters):
    if _not_ok(ax, "cluster sizes", clusters):
        return
    sizes = list(range(2, 21)) + [21]
    width = 0.27
    largest = 2
    for k, (name, colour) in enumerate((("median", BLUE), ("constant", ORANGE), ("near_wake", GREEN))):
        c = clusters["criteria"][name]
        label = f"{name.replace('_', '-')}: {c['n_clusters']} clusters"
        if not c["n_clusters"]:  # its PDF is 0/0
            ax.bar([], [], color=colour, label=label, hatch=["", "//", ".."][k])
            continue
        ax.bar([s + (k - 1) * width for s in sizes], c["size_pdf"], width=width, color=colour, label=label,
               hatch=["", "//", ".."][k])
        largest = max([largest] + [s for s, f in zip(sizes, c["size_pdf"]) if f])
    ax.set_xlim(1.4, max(largest, 6) + 0.6)
    ticks = [t for t in (2, 3, 4, 5, 6, 8, 10, 12, 15, 18, 21) if t <= max(largest, 6)]
    ax.set_xticks(ticks, [">20" if t == 21 else str(t) for t in ticks])
    _finish(ax, "fraction of clusters (-)", f"particles per cluster ({clusters['basis']} criteria)",
            "Cluster sizes")


def arrival_pdf(ax, arrivals):
    if _not_ok(ax, "arrival times", arrivals):
        return
    w = arrivals["bin_width"]
    unit = "mm" if arrivals.get("basis") == "length" else "ms"
    shown = 0
    for k, cls in enumerate(arrivals["classes"]):
        if not cls.get("pdf") or not cls.get("intervals"):
            continue
        n = min(30, len(cls["pdf"]) - 1)  # the first 30 bins; the last is the overflow
        x = [1e3 * w * (i + 0.5) for i in range(n)]
        colour = PALETTE[k % len(PALETTE)]
        marker = "osD^vP*X"[k % 8]
        lo, hi = cls.get("lower"), cls.get("upper")
        name = (f"{'' if lo is None else f'{1e3 * lo:g}-'}{'' if hi is None else f'{1e3 * hi:g}'} {unit}"
                if lo is not None or hi is not None else "all")
        if lo is None and hi is not None:
            name = f"<= {1e3 * hi:g} {unit}"
        elif hi is None and lo is not None:
            name = f"> {1e3 * lo:g} {unit}"
        ax.plot(x, _gaps(cls["pdf"][:n]), color=colour, marker=marker, ms=3, label=f"{name} (N={cls['particles']})")
        ax.plot(x, _gaps(cls["reference"][:n]), color=colour, ls=":", lw=1.0)
        shown += 1
    if not shown:
        note(ax, "no class has intervals")
        return
    ax.plot([], [], color=GREY, ls=":", label="Poisson reference")
    _finish(ax, "fraction of intervals (-)", "inter-particle arrival time (ms)", "Inter-particle arrival times",
            legend_size=0.8 * matplotlib.rcParams["legend.fontsize"])


def velocity_spectrum(ax, spectrum, series):
    if spectrum is None:
        reason = (series or {}).get("reason")
        note(ax, f"velocity spectrum: {reason}" if reason else "velocity spectrum not available: see this position's note")
        return
    f = [x for x in spectrum["frequency"] if x > 0]
    p = [d for x, d in zip(spectrum["frequency"], spectrum["density"]) if x > 0]
    if not f:
        note(ax, "velocity spectrum: no frequency above 0")
        return
    ax.loglog(f, p, color=BLUE, label="Welch PSD of AWCC's series")
    # A -5/3 line through the PSD's middle, for the inertial subrange.
    mid = len(f) // 2
    ref = [p[mid] * (x / f[mid]) ** (-5.0 / 3.0) for x in f]
    ax.loglog(f, ref, color=BLACK, ls="--", lw=1.0, label="-5/3")
    fr = spectrum.get("resolvable_frequency")
    if number(fr) is not None:
        ax.axvline(fr, color=VERMILION, ls=":", label=f"1/(2 T_W) = {fr:.3g} Hz")
    ax.minorticks_off()
    _finish(ax, "PSD ((m/s)^2/Hz)", "frequency (Hz)", "Velocity spectrum")


# --- bubble by bubble: event detection and the multi-tip probe ------------------
# Panels of a recording processed bubble by bubble (the JSON's "events" and
# "multi_tip"; the per-bubble columns from pdp.process's ``bubbles`` and
# ``vectors``). Each title states the method's quality and flag, and a result
# that is not of quality ok is drawn hollow in grey, never as if trusted.

BUBBLE_FLAGS = {"events": "events_disagree", "multi_tip": "multi_tip_doubtful"}


def verdict(row, key):
    """(quality, text for a title): the quality level and, when raised, the flag."""
    result = row.get(key) or {}
    quality = result.get("quality")
    flag = BUBBLE_FLAGS[key] if BUBBLE_FLAGS[key] in (row.get("flags") or []) else None
    text = f"quality {quality or 'not stated'}" + (f", flag {flag}" if flag else "")
    return quality, flag, text


def _trusted_style(trusted, colour, marker):
    if trusted:
        return dict(color=colour, marker=marker, ls="none", ms=7)
    return dict(color=GREY, marker=marker, ls="none", ms=8, mfc="none", mew=1.5)


def _interval_point(ax, x, value, interval, label, **style):
    v = number(value)
    if v is None:
        return False
    lo, hi = (number(b) for b in (interval or (None, None)))
    err = [[max(0.0, v - lo) if lo is not None else 0.0], [max(0.0, hi - v) if hi is not None else 0.0]]
    err = err if interval else None
    ax.errorbar([x], [v], yerr=err, capsize=4, label=label, **style)
    return True


def vector_components(ax, row):
    """The multi-tip mean vector's components with their 95 % intervals;
    the tip pair's FSCC and AWCC velocities beside u_x, as labs compare them."""
    m = row.get("multi_tip") or {}
    quality, flag, text = verdict(row, "multi_tip")
    if m.get("status") != "ok" or m.get("velocity") is None:
        note(ax, f"multi-tip mean vector: {m.get('reason') or m.get('status') or 'not computed'}")
        return
    trusted = quality == "ok" and flag is None
    style = _trusted_style(trusted, BLUE, "o")
    what = "mean vector, 95 % interval" + ("" if trusted else " (doubtful)")
    for k, name in enumerate(("u_x", "u_y", "u_z")):
        _interval_point(ax, k, m["velocity"][k], get(m, "velocity_ci95", k), what if k == 0 else None, **style)
    for dx, key, colour, marker, name in ((-0.25, "fscc", BLACK, "D", "FSCC"), (0.25, "awcc", VERMILION, "^", "AWCC")):
        result = row.get(key) or {}
        _interval_point(ax, dx, result.get("velocity"), result.get("velocity_ci95"), f"{name} of the tip pair",
                        color=colour, marker=marker, ls="none", mfc="none", ms=6)
    ax.axhline(0, color=BLACK, lw=0.6)
    ax.set_xticks([0, 1, 2], ["u_x", "u_y", "u_z"])
    ax.set_xlim(-0.6, 2.6)
    _finish(ax, "velocity (m/s)", f"component ({m.get('bubbles_accepted')} bubbles accepted)",
            f"Multi-tip mean vector\n{text}")


def events_velocity(ax, row):
    """Event detection's mean velocity with its interval beside FSCC's and AWCC's."""
    e = row.get("events") or {}
    quality, flag, text = verdict(row, "events")
    trusted = e.get("status") == "ok" and quality == "ok" and flag is None
    shown = _interval_point(ax, 0, e.get("velocity"), e.get("velocity_ci95"),
                            "ED, 95 % interval" + ("" if trusted else " (doubtful)"),
                            **_trusted_style(trusted, BLUE, "o"))
    for x, key, colour, marker, name in ((1, "fscc", BLACK, "D", "FSCC"), (2, "awcc", VERMILION, "^", "AWCC")):
        result = row.get(key) or {}
        shown |= _interval_point(ax, x, result.get("velocity"), result.get("velocity_ci95"),
                                 name + (", 95 % interval" if result.get("velocity_ci95") else ""),
                                 color=colour, marker=marker, ls="none", ms=6)
    if not shown:
        note(ax, f"event detection: {e.get('reason') or e.get('status') or 'not run'}")
        return
    ax.set_xticks([0, 1, 2], ["events", "FSCC", "AWCC"])
    ax.set_xlim(-0.6, 2.6)
    _finish(ax, "mean velocity (m/s)", f"method ({e.get('bubbles_paired')} bubbles paired)",
            f"Event detection against FSCC, AWCC\n{text}")


def _column(table, name):
    return np.asarray([np.nan if v is None else v for v in table[name]], dtype=float)


def _kept(table, fate):
    """Indices of the rows of one fate; None, said by the caller, without a table."""
    if table is None:
        return None
    return np.flatnonzero(np.asarray(table["fate"]) == fate)


def _references(ax, row, mean, mean_label, trusted, vertical=True):
    line = ax.axvline if vertical else ax.axhline
    if number(mean) is not None:
        line(mean, color=BLUE if trusted else GREY, lw=1.6, ls="-" if trusted else "-.",
             label=f"{mean_label} {mean:.3g} m/s" + ("" if trusted else " (doubtful)"))
    for key, colour, ls, name in (("fscc", BLACK, "--", "FSCC"), ("awcc", VERMILION, ":", "AWCC")):
        v = number(get(row, key, "velocity"))
        if v is not None:
            line(v, color=colour, ls=ls, lw=1.4, label=f"{name} {v:.3g} m/s")


def bubble_histogram(ax, row, table, key):
    """Per-bubble velocities (events: the paired bubbles' u_h; multi-tip: the
    solved bubbles' u_x), the method's mean, FSCC's and AWCC's marked."""
    what = "paired" if key == "events" else "solved"
    column = "velocity" if key == "events" else "velocity_x"
    quality, flag, text = verdict(row, key)
    trusted = quality == "ok" and flag is None
    rows = _kept(table, what)
    if rows is None:
        note(ax, "per-bubble table not available: see this position's note")
        return
    values = _column(table, column)[rows]
    values = values[np.isfinite(values)]
    if not len(values):
        note(ax, f"no {what} bubble")
        return
    lo, hi = np.percentile(values, [0.5, 99.5])
    pad = 0.05 * (hi - lo) or 0.1 * abs(hi) or 1.0
    edges = np.linspace(lo - pad, hi + pad, max(10, min(60, int(2 * math.sqrt(len(values))))) + 1)
    outside = int(((values < edges[0]) | (values > edges[-1])).sum())
    ax.hist(values, bins=edges, color=SKY, label=f"{len(values)} {what} bubbles"
            + (f" ({outside} outside not shown)" if outside else ""))
    mean = get(row, key, "velocity", 0) if key == "multi_tip" else get(row, key, "velocity")
    _references(ax, row, mean, "mean u_x" if key == "multi_tip" else "ED mean", trusted)
    name = "u_x" if key == "multi_tip" else "u_h = dx / lag"
    _finish(ax, "bubbles", f"per-bubble velocity {name} (m/s)",
            f"{'Multi-tip' if key == 'multi_tip' else 'Events'}: bubble velocities\n{text}")


def bubble_size_velocity(ax, row, table, key):
    """Size against velocity: multi-tip diameter_front against speed of the
    solved bubbles; events chord length against velocity of the paired ones."""
    what = "paired" if key == "events" else "solved"
    size, velocity = ("chord_length", "velocity") if key == "events" else ("diameter_front", "speed")
    _, _, text = verdict(row, key)
    rows = _kept(table, what)
    if rows is None:
        note(ax, "per-bubble table not available: see this position's note")
        return
    x, y = _column(table, velocity)[rows], 1e3 * _column(table, size)[rows]
    finite = np.isfinite(x) & np.isfinite(y)
    if not finite.any():
        note(ax, f"no {what} bubble with a size (Tian's vectors have none)" if key == "multi_tip"
             else f"no {what} bubble")
        return
    x, y = x[finite], y[finite]
    ax.plot(x, y, ls="none", marker=".", ms=3, color=BLUE, alpha=0.6, rasterized=len(x) > 2000,
            label=f"{len(x)} {what} bubbles")
    xl, xh = np.percentile(x, [0.5, 99.5])
    yl, yh = np.percentile(y, [0.5, 99.5])
    ax.set_xlim(xl - 0.05 * (xh - xl or 1), xh + 0.05 * (xh - xl or 1))
    ax.set_ylim(max(0.0, yl - 0.05 * (yh - yl or 1)), yh + 0.05 * (yh - yl or 1))
    outside = int(((x < ax.get_xlim()[0]) | (x > ax.get_xlim()[1]) | (y > ax.get_ylim()[1])).sum())
    if outside:
        ax.plot([], [], ls="none", label=f"{outside} outside not shown")
    xlabel = "speed |V| (m/s)" if key == "multi_tip" else "velocity u_h (m/s)"
    ylabel = "front diameter (mm)" if key == "multi_tip" else "chord length (mm)"
    _finish(ax, ylabel, xlabel, f"{'Multi-tip' if key == 'multi_tip' else 'Events'}: size against "
            f"velocity\n{text}")


# The bubble-by-bubble rows of the per-position figure, for the JSON key of
# each method: (SVG group key, title) of its three panels.
BUBBLE_PANELS = {
    "multi_tip": [("multi-tip-vector", "multi-tip mean vector components"),
                  ("multi-tip-histogram", "multi-tip bubble velocity histogram"),
                  ("multi-tip-size-velocity", "multi-tip size against velocity")],
    "events": [("events-velocity", "event detection against FSCC and AWCC"),
               ("events-histogram", "event detection bubble velocity histogram"),
               ("events-size-velocity", "event detection chord length against velocity")],
}


def bubble_rows(row):
    """The JSON keys of the bubble-by-bubble methods a recording holds, in BUBBLE_PANELS' order."""
    return [key for key in BUBBLE_PANELS if row.get(key) is not None]


def profile_vector(rows, ax=None):
    """The multi-tip mean vector's components with their 95 % intervals
    against position; a doubtful row's points hollow and grey."""
    fig, ax = _profile_axes(ax)
    y, ylabel = positions_mm(rows)

    def trusted(r):
        quality, flag, _ = verdict(r, "multi_tip")
        return quality == "ok" and flag is None

    doubtful = [r for r in rows if r.get("multi_tip") is not None and not trusted(r)]
    for k, (name, colour, marker, ls) in enumerate((("u_x", BLUE, "o", "-"), ("u_y", ORANGE, "s", "--"),
                                                    ("u_z", GREEN, "^", ":"))):
        def value(r, k=k, want=True):
            return get(r, "multi_tip", "velocity", k) if trusted(r) == want else None
        _series(ax, y, rows, value, lambda r, k=k: get(r, "multi_tip", "velocity_ci95", k), color=colour,
                marker=marker, ls=ls, label=f"{name}, 95 % interval")
        if doubtful:
            _series(ax, y, rows, lambda r, k=k: value(r, k, False),
                    lambda r, k=k: get(r, "multi_tip", "velocity_ci95", k), color=GREY, marker=marker, ls="none",
                    mfc="none", label="quality not ok (doubtful): hollow, grey" if k == 0 else None)
    ax.axvline(0, color=BLACK, lw=0.6)
    _finish(ax, ylabel, "mean velocity component (m/s)", "Multi-tip mean vector")
    return fig


# --- bubble sizes: each row's "sizes" (docs/output.md; METHOD 12) ----------------

SIZES_WITH_VALUES = ("ok", "not_converged")  # statuses whose distribution and diameters exist


def _sizes_missing(rows, labels):
    """The positions without a distribution (or whose EM did not converge),
    grouped by status: each status once, with its positions and the first
    one's reason (the reasons of one status differ only in their numbers)."""
    groups = {}  # status -> (labels, first reason)
    for label, r in zip(labels, rows):
        s = r.get("sizes")
        if s is None:
            status, reason = "no size distribution", "pdp process --sizes off, or a JSON without sizes"
        elif s.get("status") != "ok":
            status, reason = s.get("status"), s.get("reason")
        else:
            continue
        groups.setdefault(status, ([], reason))[0].append(label)
    out = []
    for status, (where, reason) in groups.items():
        first = f" (at {where[0]}: {reason})" if reason and len(where) > 1 else (f": {reason}" if reason else "")
        out.append(f"{', '.join(where)}: {status}{first}")
    return out


def sizes_drawable(rows):
    """Whether any row has a size distribution to draw (else the size
    figures are left out and one note says why: sizes_note)."""
    return any(get(r, "sizes", "status") in SIZES_WITH_VALUES and get(r, "sizes", "bins") is not None for r in rows)


def sizes_note(rows):
    """The one note that stands for the size figures when no row has a distribution."""
    labels, _, _ = _row_labels(rows)
    return "Bubble size distributions: none to draw. " + "; ".join(_sizes_missing(rows, labels)) + "."


def _row_labels(rows):
    y, ylabel = positions_mm(rows)
    return [f"y = {v:g} mm" if ylabel.startswith("position") else f"row {v}" for v in y], y, ylabel


def profile_size_distributions(rows, ax=None):
    """The number distributions n(D) of the positions, one curve each
    (colour by position, the colour bar its scale; a distribution whose EM
    did not converge dotted), D on a log axis as the bins are equal in ln D;
    the positions without one, with their status and reason, beneath."""
    if ax is None:  # room on the right for the colour bar
        left, bottom, _, top = PROFILE_MARGINS
        fig, ((ax,),) = figure(width=5.0, margins=(left, bottom, 0.75, top))
    fig = ax.figure
    labels, y, _ = _row_labels(rows)
    order = sorted(range(len(rows)), key=lambda i: y[i])
    drawn = [i for i in order if get(rows[i], "sizes", "status") in SIZES_WITH_VALUES
             and get(rows[i], "sizes", "bins") is not None]
    cmap = matplotlib.colormaps["cividis"]
    low, high = (min(y), max(y)) if y else (0, 1)
    norm = Normalize(low, high if high > low else low + 1)
    for i in drawn:
        bins = rows[i]["sizes"]["bins"]
        converged = rows[i]["sizes"]["status"] == "ok"
        ax.plot(1e3 * np.asarray(bins["diameters"], dtype=float), 1e-3 * np.asarray(_gaps(bins["density"])),
                color=cmap(norm(y[i])), lw=1.4 if converged else 1.1, ls="-" if converged else ":")
    if drawn:
        ax.set_xscale("log")
        ax.xaxis.set_major_locator(LogLocator(subs=(1.0, 2.0, 5.0)))
        ax.xaxis.set_major_formatter(FuncFormatter(lambda v, _: f"{v:g}"))
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.set_ylim(bottom=0)
        bar = fig.colorbar(ScalarMappable(norm=norm, cmap=cmap), ax=ax, pad=0.03, fraction=0.06)
        bar.set_label("position (mm)" if labels[0].startswith("y") else "row", fontsize=8)
        bar.ax.tick_params(labelsize=7)
        if any(rows[i]["sizes"]["status"] != "ok" for i in drawn):
            ax.plot([], [], color=GREY, ls=":", label="EM not converged (last iterate)")
        ax.set_xlabel("sphere diameter D (mm)")
        ax.set_ylabel("number density n(D) (1/mm)")
    else:
        ax.set_axis_off()
    ax.set_title("Bubble size distributions")
    _reasons_beneath(fig, ax, _sizes_missing(rows, labels))
    legend(ax)
    return fig


def profile_size_d32(rows, ax=None):
    """d32 of the inverted distribution against 1.5 u c / F (the flux
    estimate, METHOD 12) by position; a distribution whose EM did not
    converge hollow and grey; positions without one say why beneath."""
    fig, ax = _profile_axes(ax)
    labels, y, ylabel = _row_labels(rows)

    def distribution_d32(r, want_ok=True):
        s = r.get("sizes") or {}
        return s.get("d32") if s.get("status") in SIZES_WITH_VALUES and (s.get("status") == "ok") == want_ok \
            else None

    _series(ax, y, rows, distribution_d32, scale=1e3, color=GREEN, marker="o", ls="-",
            label="d32 of the size distribution n(D)")
    if any(get(r, "sizes", "status") == "not_converged" for r in rows):
        _series(ax, y, rows, lambda r: distribution_d32(r, False), scale=1e3, color=GREY, marker="o", mfc="none",
                ls="none", label="d32, EM not converged (doubtful)")
    _series(ax, y, rows, lambda r: get(r, "sizes", "d32_flux"), scale=1e3, color=BLACK, marker="D", mfc="none",
            ls=":", label="1.5 u c / F (flux, spheres)")
    ax.set_xlim(left=0)
    ax.set_ylabel(ylabel)
    ax.set_xlabel("Sauter diameter d32 (mm)")
    ax.set_title("Sauter diameter: distribution against flux")
    _reasons_beneath(fig, ax, _sizes_missing(rows, labels))
    legend(ax)
    return fig


# Profile figures drawn only when a row holds their method's results.
BUBBLE_PROFILE_FIGURES = [("multi-tip-vector", "Multi-tip mean vector", profile_vector, "multi_tip"),
                          ("size-distributions", "Bubble size distributions", profile_size_distributions, "sizes"),
                          ("size-d32", "Sauter diameter: distribution against flux", profile_size_d32, "sizes")]


# The per-position figure is printed at about half its size: its text is
# drawn larger, to stay legible (about 6.5 pt on A4).
POSITION_FONTS = {"font.size": 13, "axes.titlesize": 14, "axes.labelsize": 13, "legend.fontsize": 11,
                  "xtick.labelsize": 12, "ytick.labelsize": 12}


def position_svg(row, detail, salt):
    """The per-position figure as SVG; each panel is the group ``salt-KEY``
    (KEY of POSITION_PANELS)."""
    with matplotlib.rc_context(POSITION_FONTS):
        return svg(position_figure(row, detail), salt=salt)


def position_figure(row, detail, gid_prefix=""):
    """Every per-position panel of one recording in one figure (3 x 3, and a
    row of three for each bubble-by-bubble method it holds: BUBBLE_PANELS);
    each panel's SVG group is named gid_prefix + its POSITION_PANELS (or
    BUBBLE_PANELS) key. ``detail`` holds what the JSON does not (windows,
    correlation, spectrum, the per-bubble tables bubbles and vectors); a key
    that is None or missing is said missing in its panel."""
    methods = bubble_rows(row)
    # Each panel keeps the height of the 3 x 3 layout (2.375 in, gaps half of it).
    n = 3 + len(methods)
    fig, axes = figure(width=13.5, height=1.0 + 2.375 * (n + 0.5 * (n - 1)), rows=n, cols=3,
                       margins=(0.8, 0.6, 0.12, 0.4))
    # The bubble rows first: their two-line titles are then there for the
    # legends placed beneath the panels above them to keep clear of (_floor_beneath).
    panels = list(POSITION_PANELS)
    for k, key in enumerate(methods):
        ax = axes[3 + k]
        table = detail.get("vectors" if key == "multi_tip" else "bubbles")
        (vector_components if key == "multi_tip" else events_velocity)(ax[0], row)
        bubble_histogram(ax[1], row, table, key)
        bubble_size_velocity(ax[2], row, table, key)
        panels += BUBBLE_PANELS[key]
    s = row.get("structure") or {}
    chord_pdf(axes[0][0], s.get("chord_time_pdf"), "time")
    chord_pdf(axes[0][1], s.get("chord_length_pdf"), "length")
    voltage_pdf(axes[0][2], s, row["tips"])
    correlation(axes[1][0], detail.get("correlation"), row.get("fscc"))
    window_series(axes[1][1], detail.get("windows"), row.get("awcc"))
    window_histogram(axes[1][2], detail.get("windows"), row.get("awcc"))
    clusters = get(s, "clusters", "length")
    if not clusters or clusters.get("status") != "ok":
        clusters = get(s, "clusters", "time") or clusters
    cluster_sizes(axes[2][0], clusters)
    arrival_pdf(axes[2][1], get(s, "arrivals", "time"))
    velocity_spectrum(axes[2][2], detail.get("spectrum"), row.get("velocity_spectrum"))
    for ax, (key, _) in zip((a for r in axes for a in r), panels):
        ax.set_gid(gid_prefix + key)
    return fig


# (SVG group key, title) of each per-position panel, in reading order.
POSITION_PANELS = [("chord-time-pdf", "chord-time PDF"), ("chord-length-pdf", "chord-length PDF"),
                   ("voltage-pdf", "voltage PDF"), ("correlation", "R11 and R12"),
                   ("window-velocities", "AWCC window velocities"), ("window-histogram", "window velocity histogram"),
                   ("cluster-sizes", "cluster sizes"), ("arrival-pdf", "arrival-time PDF"),
                   ("velocity-spectrum", "velocity spectrum")]


def write_page(text, out, prefix=".pdp-page-"):
    """Writes a page (HTML text) to `out` through a temporary file in the same
    folder and a rename: a reader never sees a partial page, and an error
    leaves no file behind. Raises OSError."""
    folder = os.path.dirname(os.path.abspath(out))
    fd, tmp = tempfile.mkstemp(prefix=prefix, suffix=".tmp", dir=folder)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(text)
        os.chmod(tmp, 0o644)
        os.replace(tmp, out)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise


# pdp's exit status (docs/guide/settings.md, "Exit status") for what finish_page decides.
EXIT_OUTPUT_FAILED, EXIT_INTERNAL = 3, 4


def finish_page(program, build, output, output_flag, problems, prefix=".pdp-page-"):
    """The end of a page script (pdp report, pdp design --report): builds the
    page, writes it (write_page) and returns pdp's exit status
    (docs/guide/settings.md, "Exit status"). `problems` maps the script's exception classes to their exit
    status (bad input 1, bad usage 2); any other exception is a defect (4),
    an unwritable page 3."""
    import sys
    try:
        page = build()
    except tuple(problems) as e:
        print(f"{program}: {e}", file=sys.stderr)
        return next(code for kind, code in problems.items() if isinstance(e, kind))
    except Exception:  # a defect: Python's own exit status 1 would read as bad input
        import traceback
        traceback.print_exc()
        print(f"{program}: internal error; please report it with the command line", file=sys.stderr)
        return EXIT_INTERNAL
    try:
        write_page(page, output, prefix=prefix)
    except OSError as e:
        print(f"{program}: {output}: cannot write: {e.strerror}; choose a writable folder with {output_flag}",
              file=sys.stderr)
        return EXIT_OUTPUT_FAILED
    print(f"{program}: wrote {output}", file=sys.stderr)
    return 0

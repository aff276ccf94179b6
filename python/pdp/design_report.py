"""pdp design's page: one self-contained HTML page showing which probe
geometry and settings measure a flow best, and why.

    python3 python/pdp/design_report.py RANKED.csv --config DESIGN.toml -o design.html
    (or: pdp design --config DESIGN.toml -o RANKED.csv --report design.html)

It reads the ranked CSV pdp design writes (one row per candidate and
condition, best first; docs in libstudy/include/study/design.hpp; the needle column,
the leading needle's diameter in m, 0 for point tips, is optional) and shows:

- the recommended candidate (rank 1) with its errors in every condition, and
  how much better it is than the worst candidate and the lab's current probe;
- per condition, maps over the probe geometry (dx, dy) at the recommended
  Np, fs, duration and needle: the RMS errors of u and Tu that the ranking uses, and
  raw AWCC's signed biases of u and Tu, which show the mechanisms (METHOD 6:
  E1 selective sampling grows with dx; E2 oblique impacts with dy at small
  dx); a heat map when the geometries form a grid, else a scatter;
- when several Np were tried, the objective over (dx, dy) for each Np;
- the ranking (the first 15, the current probe and the worst) and the
  provenance of the design and of this page.

The design file (--config) is read only for its name, its SHA-256 and the
conditions' descriptions (with Python 3.11's tomllib; older interpreters name
the file only). Figures are inline SVG drawn with pdp.plotting's layer, which
this file loads from beside itself: the compiled core is not needed.

Exit status as pdp's (docs/guide/settings.md, "Exit status"): 1 bad input, 2 bad usage,
3 output not written, 4 internal error, 5 a package is missing.
"""

import argparse
import csv
import datetime
import hashlib
import importlib.util
import math
import os
import shlex
import sys

EXIT_BAD_INPUT, EXIT_BAD_USAGE, EXIT_MISSING_PACKAGE = 1, 2, 5  # the others: plotting.finish_page
MISSING_PACKAGE_HELP = ("pdp design --report draws with matplotlib and NumPy and writes the page with Jinja2: "
                        "install Debian's python3-matplotlib, python3-numpy and python3-jinja2 (sudo apt install "
                        "python3-matplotlib python3-numpy python3-jinja2)")

# The ranked CSV's header is its declaration (study::ranked_columns in libstudy/include/study/design.hpp):
# the columns before CONDITION are the candidate's (the same on each of its rows), the rest the condition's.
CONDITION = "condition"
# The design's ranking, as pdp design writes it in every row: (column, the values it takes).
RANKING = ("ranking", ("worst-case", "mean"))
VALUES = ("values", ("corrected", "raw"))
TEXT_COLUMNS = {CONDITION, RANKING[0], VALUES[0]}
# The columns this page reads (any others are carried, not shown).
USED = ["rank", "objective", RANKING[0], VALUES[0], "failures", "current", "dx", "dy", "np", "fs", "duration",
        "seconds_awcc", CONDITION, "records", "condition_failures", "score", "u_bias", "u_spread", "u_rms", "tu_bias",
        "tu_spread", "tu_rms", "raw_u_bias", "raw_tu_bias", "corrected_fraction", "data_yield"]
# Optional columns and their value when absent (files of pdp design before needles).
OPTIONAL = {"needle": 0.0}
# Whole numbers: (smallest allowed, largest allowed or None).
WHOLE = {"rank": (1, None), "failures": (0, None), "current": (0, 1), "np": (1, None), "records": (0, None),
         "condition_failures": (0, None)}
TABLE_TOP = 15  # candidates in the ranking table, before the current probe and the worst

# (CSV column, title, diverging): the maps drawn for each condition.
MAP_QUANTITIES = [
    ("u_rms", "u error, RMS", False),
    ("tu_rms", "Tu error, RMS", False),
    ("raw_u_bias", "raw AWCC u bias", True),
    ("raw_tu_bias", "raw AWCC Tu bias", True),
]
SEQUENTIAL_MAP, DIVERGING_MAP = "YlOrRd", "RdBu_r"


class InputProblem(Exception):
    """A ranked CSV that is not what pdp design writes."""


class UsageProblem(Exception):
    """Arguments or a named file that cannot be used."""


# --- reading ------------------------------------------------------------------------


def value(text):
    """A finite float, or None for an empty cell, inf or NaN (a candidate without a value); ValueError otherwise."""
    text = text.strip()
    if text == "":
        return None
    v = float(text)
    return v if math.isfinite(v) else None


def geometry_key(dx, dy):
    """(dx, dy) in m, rounded so that 0.005 from two rows is one geometry."""
    return (round(dx, 9), round(dy, 9))


def mm(x):
    return f"{round(1e3 * x, 6):g}"


class Candidate:
    """One candidate: its fields and, per condition, its values (None: no value)."""

    def __init__(self, fields):
        self.rank = int(fields["rank"])
        self.objective = fields["objective"]
        self.failures = int(fields["failures"])
        self.current = fields["current"] == 1
        self.dx, self.dy = fields["dx"], fields["dy"]
        self.np = int(fields["np"])
        self.fs, self.duration, self.needle = fields["fs"], fields["duration"], fields["needle"]
        self.seconds = fields["seconds_awcc"]
        self.ranking, self.values = fields[RANKING[0]], fields[VALUES[0]]
        self.conditions = {}  # name -> {column: value}

    @property
    def geometry(self):
        return geometry_key(self.dx, self.dy)

    @property
    def setting(self):
        """Everything but the geometry: Np, fs, duration, needle."""
        return (self.np, self.fs, self.duration, self.needle)

    @property
    def name(self):
        """As pdp design names it: "dx 3 mm, dy 0.5 mm, Np 10, 100 kHz, 60 s[, needle 0.8 mm]"."""
        return (f"dx {mm(self.dx)} mm, dy {mm(self.dy)} mm, Np {self.np}, {self.fs / 1e3:g} kHz, "
                f"{self.duration:g} s" + (f", needle {mm(self.needle)} mm" if self.needle else ""))

    def score(self, condition):
        return self.conditions.get(condition, {}).get("score")


def read_ranked(path):
    """(candidates by rank, condition names in order, SHA-256 of the file)."""
    try:
        with open(path, "rb") as f:
            raw = f.read()
    except OSError as e:
        raise InputProblem(f"{path}: cannot read: {e.strerror}; give the ranked CSV pdp design -o wrote") from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        raise InputProblem(f"{path}: not text (UTF-8): give the ranked CSV pdp design -o wrote") from None
    lines = list(csv.reader(text.splitlines()))
    header = [h.strip() for h in lines[0]] if lines else []
    missing = [c for c in USED if c not in header]
    if missing:
        raise InputProblem(f"{path}: column{'s' if len(missing) > 1 else ''} {', '.join(missing)} missing: not a "
                           "ranked CSV of this pdp design; give the file pdp design -o wrote (pdp design ranks "
                           "again from its runs file without simulating)")
    candidate_columns = set(header[:header.index(CONDITION)]) | set(OPTIONAL)
    candidates, conditions, ranking = {}, [], None
    for line, cells in enumerate(lines[1:], start=2):
        if not cells:
            continue
        if len(cells) != len(header):
            raise InputProblem(f"{path}: line {line} has {len(cells)} cells, not {len(header)}: the file is cut or "
                               "edited; write it again with pdp design")
        row = dict(zip(header, cells))
        fields, values = dict(OPTIONAL), {}
        for c in header:
            if c in TEXT_COLUMNS:
                continue
            try:
                v = value(row[c])
            except ValueError:
                raise InputProblem(f"{path}: line {line}, column {c}: '{row[c]}' is not a number") from None
            if c in WHOLE or c in ("dx", "dy", "fs", "duration", "needle"):
                if v is None:
                    raise InputProblem(f"{path}: line {line}, column {c}: empty or not finite; every row names its "
                                       "candidate: write the file again with pdp design")
                lo, hi = WHOLE.get(c, (None, None))
                if c in WHOLE and (v != int(v) or v < lo or (hi is not None and v > hi)):
                    raise InputProblem(f"{path}: line {line}, column {c}: {row[c]} is not a whole number from {lo}"
                                       f"{f' to {hi}' if hi is not None else ' up'}")
                if (c in ("fs", "duration") and v <= 0) or (c in ("dx", "needle") and v < 0):
                    raise InputProblem(f"{path}: line {line}, column {c}: {row[c]} is out of range")
            (fields if c in candidate_columns else values)[c] = v
        for column, allowed in (RANKING, VALUES):
            text = row[column].strip()
            if text not in allowed:
                raise InputProblem(f"{path}: line {line}, column {column}: '{text}' is not one of "
                                   f"{', '.join(allowed)}; write the file again with pdp design")
            fields[column] = text
        if ranking is None:
            ranking = (fields[RANKING[0]], fields[VALUES[0]])
        elif ranking != (fields[RANKING[0]], fields[VALUES[0]]):
            raise InputProblem(f"{path}: line {line}: ranked by {fields[RANKING[0]]} of the {fields[VALUES[0]]} values, "
                               f"the rows before by {ranking[0]} of the {ranking[1]} values: a design ranks one "
                               "way; write the file again with pdp design")
        name = row[CONDITION].strip()
        if not name:
            raise InputProblem(f"{path}: line {line}: the condition is empty")
        if name not in conditions:
            conditions.append(name)
        candidate = candidates.get(int(fields["rank"]))
        if candidate is None:
            candidate = candidates[int(fields["rank"])] = Candidate(fields)
        else:
            first = Candidate(fields)
            if (first.geometry, first.setting, first.current) != (candidate.geometry, candidate.setting,
                                                                     candidate.current):
                raise InputProblem(f"{path}: line {line}: rank {candidate.rank} is given to two candidates "
                                   f"({candidate.name} and {first.name}): not a ranked CSV of pdp design")
        if name in candidate.conditions:
            raise InputProblem(f"{path}: line {line}: rank {candidate.rank} has condition {name} twice")
        candidate.conditions[name] = values
    if not candidates:
        raise InputProblem(f"{path}: no candidate (a header without rows): run pdp design again")
    ordered = [candidates[r] for r in sorted(candidates)]
    seen = {}
    for c in ordered:
        other = seen.setdefault((c.geometry, c.setting), c)
        if other is not c:
            raise InputProblem(f"{path}: {c.name} is ranked twice (ranks {other.rank} and {c.rank})")
    return ordered, conditions, hashlib.sha256(raw).hexdigest()


def _describe_setting(v):
    if isinstance(v, list):
        log = len(v) == 3 and v[2] == "log"
        return f"{v[0]} to {v[1]}{' (log-uniform)' if log else ''}"
    if isinstance(v, bool):
        return "true" if v else "false"
    return str(v)


def read_design(path):
    """What the page says of the design file: name, SHA-256, and when Python
    reads TOML (3.11's tomllib), the conditions' settings and [design]."""
    try:
        with open(path, "rb") as f:
            raw = f.read()
    except OSError as e:
        raise UsageProblem(f"--config {path}: cannot read: {e.strerror}; give the design file pdp design read") \
            from None
    design = {"file": path, "sha256": hashlib.sha256(raw).hexdigest(), "conditions": {}, "settings": {},
              "note": None}
    try:
        import tomllib
    except ImportError:
        design["note"] = (f"Python {sys.version_info.major}.{sys.version_info.minor} has no tomllib (3.11+): the "
                          "design file is named, not read")
        return design
    try:
        table = tomllib.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, tomllib.TOMLDecodeError) as e:
        design["note"] = f"the design file could not be read as TOML ({e}): it is named, not described"
        return design
    conditions = table.get("conditions")
    if isinstance(conditions, dict):
        for name, fields in conditions.items():
            if isinstance(fields, dict):
                design["conditions"][name] = ", ".join(f"{k} {_describe_setting(v)}" for k, v in fields.items())
    if isinstance(table.get("design"), dict):
        design["settings"] = {k: _describe_setting(v) for k, v in table["design"].items()}
    return design


# --- what the page says -----------------------------------------------------------


def pct(v, signed=False, digits=1):
    if v is None:
        return "no value"
    return f"{100 * v:+.{digits}f} %" if signed else f"{100 * v:.{digits}f} %"


def ratio(other, best):
    """other's objective / best's, as text."""
    if other.objective is None:
        return "not comparable (no value in every record of some condition)"
    if best.objective is None or best.objective <= 0:
        return "not defined (the recommended candidate's objective is not positive)"
    return f"{other.objective / best.objective:.1f}x the recommended error"


class Layout:
    """How geometries are drawn: a grid (xs, ys: sorted dx and dy) or a scatter."""

    def __init__(self, geometries, current):
        self.geometries = sorted(set(geometries))
        self.off_grid = None  # the current probe's geometry when it alone breaks the grid
        self.grid = self._grid(self.geometries)
        if not self.grid and current is not None and current in self.geometries:
            rest = [g for g in self.geometries if g != current]
            if len(rest) >= 2 and self._grid(rest):
                self.grid, self.off_grid = True, current
                self.geometries = rest
        self.xs = sorted({g[0] for g in self.geometries})
        self.ys = sorted({g[1] for g in self.geometries})

    @staticmethod
    def _grid(geometries):
        xs, ys = {g[0] for g in geometries}, {g[1] for g in geometries}
        return len(geometries) == len(xs) * len(ys)


# --- figures ----------------------------------------------------------------------


def _plotting():
    """pdp.plotting, loaded from beside this file (no compiled core needed)."""
    name = "pdp.plotting"
    if name in sys.modules:
        return sys.modules[name]
    name = "_pdp_design_plotting"
    if name not in sys.modules:
        spec = importlib.util.spec_from_file_location(
            name, os.path.join(os.path.dirname(os.path.abspath(__file__)), "plotting.py"))
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        sys.modules[name] = module
    return sys.modules[name]


def _norm(values, diverging):
    """A colour scale over values in %: 0 to the largest, or symmetric about 0."""
    from matplotlib.colors import Normalize
    finite = [v for v in values if v is not None]
    if diverging:
        top = max([abs(v) for v in finite] + [1e-9])
        return Normalize(-top, top)
    return Normalize(0.0, max(finite + [1e-9]))


def _text_colour(cmap, norm, v):
    r, g, b, _ = cmap(norm(v))
    return "white" if 0.299 * r + 0.587 * g + 0.114 * b < 0.5 else "black"


def _cell_text(v, signed):
    """A value in %: one decimal under 10, none above (cells are narrow)."""
    digits = 1 if abs(v) < 9.95 else 0
    return f"{v:+.{digits}f}" if signed else f"{v:.{digits}f}"


MARKS = {  # role -> (edge colour, line style, line width, label)
    "recommended": ("#000000", "-", 2.2, "recommended"),
    "current": ("#D55E00", "--", 1.8, "current probe"),
}


def _grid_map(ax, layout, values, norm, cmap, signed, marks, notes=None, fontsize=7, prefix=""):
    """A heat map: dx across, dy up, one cell per grid geometry, annotated in %.
    values: geometry -> value in % or None (a hatched blank cell). Returns (mesh, blank cells)."""
    import numpy as np
    from matplotlib.patches import Rectangle
    p = _plotting()
    nx, ny = len(layout.xs), len(layout.ys)
    col = {x: i for i, x in enumerate(layout.xs)}
    row = {y: j for j, y in enumerate(layout.ys)}
    grid = np.full((ny, nx), np.nan)
    for g in layout.geometries:
        v = values.get(g)
        if v is not None:
            grid[row[g[1]], col[g[0]]] = v
    ax.grid(False)
    mesh = ax.pcolormesh(np.arange(nx + 1) - 0.5, np.arange(ny + 1) - 0.5, np.ma.masked_invalid(grid), cmap=cmap,
                         norm=norm, edgecolors="white", linewidth=0.8)
    blank = 0
    for g in layout.geometries:
        i, j = col[g[0]], row[g[1]]
        v = values.get(g)
        extra = (notes or {}).get(g)
        if v is None:
            ax.add_patch(Rectangle((i - 0.5, j - 0.5), 1, 1, facecolor="#f4f4f4", edgecolor=p.GREY, hatch="///",
                                   lw=0.5, gid=f"{prefix}blank-{i}-{j}", zorder=2))
            ax.text(i, j, "no value" + (f"\n{extra}" if extra else ""), ha="center", va="center", fontsize=6,
                    color=p.BLACK, zorder=3, bbox={"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none"})
            blank += 1
        else:
            ax.text(i, j, _cell_text(v, signed) + (f"\n{extra}" if extra else ""), ha="center", va="center",
                    fontsize=fontsize, color=_text_colour(cmap, norm, v), zorder=3)
    for role, geometry in marks:
        if geometry in layout.geometries:
            colour, ls, lw, _ = MARKS[role]
            inset = 0.06 if role == "recommended" else 0.14
            corner = (col[geometry[0]] - 0.5 + inset, row[geometry[1]] - 0.5 + inset)
            ax.add_patch(Rectangle(corner, 1 - 2 * inset, 1 - 2 * inset, fill=False, edgecolor=colour, ls=ls, lw=lw,
                                   gid=prefix + role, zorder=4))
    ax.set_xticks(range(nx), [mm(x) for x in layout.xs])
    ax.set_yticks(range(ny), [mm(y) for y in layout.ys])
    ax.set_xlim(-0.5, nx - 0.5)
    ax.set_ylim(-0.5, ny - 0.5)
    ax.grid(False)
    ax.set_xlabel("dx (mm)")
    ax.set_ylabel("dy (mm)")
    return mesh, blank


def _scatter_map(ax, layout, values, norm, cmap, signed, marks, notes=None, fontsize=7, prefix=""):
    """Geometries that are not a grid: one point each at (dx, dy) in mm, coloured by its value in %."""
    p = _plotting()
    have = [g for g in layout.geometries if values.get(g) is not None]
    mesh = ax.scatter([1e3 * g[0] for g in have], [1e3 * g[1] for g in have], c=[values[g] for g in have], cmap=cmap,
                      norm=norm, s=150, edgecolors=p.GREY, linewidths=0.6, zorder=3)
    blank = 0
    for k, g in enumerate(layout.geometries):
        v = values.get(g)
        extra = (notes or {}).get(g)
        if v is None:
            ax.scatter([1e3 * g[0]], [1e3 * g[1]], marker="X", s=70, color=p.GREY, zorder=3, gid=f"{prefix}blank-{k}")
            blank += 1
        ax.annotate(("no value" if v is None else _cell_text(v, signed)) + (f" ({extra})" if extra else ""),
                    (1e3 * g[0], 1e3 * g[1]), textcoords="offset points", xytext=(0, -13), ha="center", va="top",
                    fontsize=fontsize - 0.5, zorder=5)
    for role, geometry in marks:
        if geometry in layout.geometries:
            colour, ls, lw, _ = MARKS[role]
            ax.scatter([1e3 * geometry[0]], [1e3 * geometry[1]], marker="s" if role == "recommended" else "D",
                       s=420 if role == "recommended" else 300, facecolors="none", edgecolors=colour, linewidths=lw,
                       linestyles=ls, zorder=4, gid=prefix + role)
    xs, ys = [1e3 * g[0] for g in layout.geometries], [1e3 * g[1] for g in layout.geometries]
    # Room for the labels under the points: more below than above.
    for lo, hi, setter, below, above in ((min(xs), max(xs), ax.set_xlim, 0.15, 0.15),
                                         (min(ys), max(ys), ax.set_ylim, 0.3, 0.15)):
        span = hi - lo or 1.0
        setter(lo - below * span, hi + above * span)
    ax.set_xlabel("dx (mm)")
    ax.set_ylabel("dy (mm)")
    return mesh, blank


def _map(ax, layout, values, norm, cmap, signed, marks, notes=None, fontsize=7, prefix=""):
    """A heat map when the geometries are a grid, else a scatter; element ids start with prefix."""
    draw = _grid_map if layout.grid else _scatter_map
    return draw(ax, layout, values, norm, cmap, signed, marks, notes, fontsize, prefix)


def _marks_legend(fig, marks, y=0.0):
    from matplotlib.lines import Line2D
    roles = list(dict.fromkeys(role for role, _ in marks))
    if not roles:
        return
    handles = [Line2D([], [], color=MARKS[r][0], ls=MARKS[r][1], lw=MARKS[r][2], label=MARKS[r][3]) for r in roles]
    fig.legend(handles=handles, loc="lower center", ncol=len(handles), frameon=False, fontsize=7,
               bbox_to_anchor=(0.45, y))


MAP_FONTS = {"axes.titlesize": 8.5, "axes.labelsize": 8, "xtick.labelsize": 7.5, "ytick.labelsize": 7.5}


def _cell_font(layout, base):
    """Smaller cell text when the grid is wide."""
    return base - 0.5 * max(0, len(layout.xs) - 5) if layout.grid else base


def map_svg(layout, values, title, diverging, marks, salt, off_grid_note=None):
    """One quantity of one condition over (dx, dy), as SVG (shown at its own
    size: 2.95 in, about 283 px). Returns (svg, blank cells)."""
    import matplotlib
    p = _plotting()
    width, height = 2.95, 2.8
    left, bottom, right, top = 0.5, 0.72 + (0.12 if off_grid_note else 0.0), 0.62, 0.24
    with matplotlib.rc_context(MAP_FONTS):
        fig, ((ax,),) = p.figure(width=width, height=height, margins=(left, bottom, right, top))
        cmap = matplotlib.colormaps[DIVERGING_MAP if diverging else SEQUENTIAL_MAP]
        norm = _norm(list(values.values()), diverging)
        mesh, blank = _map(ax, layout, values, norm, cmap, diverging, marks, fontsize=_cell_font(layout, 7))
        ax.set_title(title)
        cax = fig.add_axes([1 - (right - 0.1) / width, bottom / height, 0.1 / width, 1 - (bottom + top) / height])
        cax.grid(False)
        fig.colorbar(mesh, cax=cax)
        cax.set_title("%", fontsize=7.5, loc="left")
        _marks_legend(fig, [(r, g) for r, g in marks if g in layout.geometries], y=0.12 / height if off_grid_note
                      else 0.0)
        if off_grid_note:
            fig.text(0.02, 0.01, off_grid_note, fontsize=7, color=p.BLACK)
        return p.svg(fig, salt=salt), blank


def objective_svg(layout, by_np, marks_of, salt):
    """Small multiples: the objective over (dx, dy) for each Np at the recommended fs and duration.
    by_np: [(np, {geometry: objective in % or None}, {geometry: note})]."""
    import matplotlib
    p = _plotting()
    n = len(by_np)
    cols = min(n, 4)
    rows = (n + cols - 1) // cols
    panel_w, panel_h = 2.7, 2.45
    left, bottom, right, top = 0.5, 0.75, 0.75, 0.25
    width, height = cols * panel_w + right, rows * panel_h + 0.35
    with matplotlib.rc_context(MAP_FONTS):
        fig, axes = p.figure(width=width, height=height, rows=rows, cols=cols, margins=(left, bottom, right, top))
        cmap = matplotlib.colormaps[SEQUENTIAL_MAP]
        norm = _norm([v for _, values, _ in by_np for v in values.values()], False)
        mesh, all_marks = None, []
        for k, (np_, values, notes) in enumerate(by_np):
            ax = axes[k // cols][k % cols]
            marks = marks_of(np_)
            all_marks += [(r, g) for r, g in marks if g in layout.geometries]
            mesh, _ = _map(ax, layout, values, norm, cmap, False, marks, notes, fontsize=_cell_font(layout, 6.5),
                            prefix=f"np{np_}-")
            ax.set_title(f"Np {np_}")
            ax.set_gid(f"np-{np_}")
        for k in range(n, rows * cols):
            axes[k // cols][k % cols].set_axis_off()
        cax = fig.add_axes([1 - (right - 0.15) / width, bottom / height, 0.1 / width, 1 - (bottom + top) / height])
        cax.grid(False)
        fig.colorbar(mesh, cax=cax).set_label("objective (%)")
        _marks_legend(fig, all_marks)
        return p.svg(fig, salt=salt)


# --- the page -----------------------------------------------------------------------


def condition_rows(candidate, conditions):
    """The errors of a candidate in each condition, as the tables show them."""
    signed = {"u_bias", "tu_bias", "raw_u_bias", "raw_tu_bias"}
    rows = []
    for name in conditions:
        v = candidate.conditions.get(name)
        if v is None:
            rows.append({"condition": name, "missing": True})
            continue
        row = {"condition": name, "missing": False, "records": int(v["records"]),
               "failures": int(v["condition_failures"])}
        for q in ("score", "u_bias", "u_spread", "u_rms", "tu_bias", "tu_spread", "tu_rms", "raw_u_bias",
                  "raw_tu_bias"):
            row[q] = pct(v.get(q), signed=q in signed)
        for q in ("data_yield", "corrected_fraction"):
            row[q] = pct(v.get(q), digits=0)
        rows.append(row)
    return rows


def setting_of(c):
    """A candidate's setting as the page writes it; text: "Np 10, 100 kHz, 60 s[, needle 0.8 mm]"."""
    s = {"np": c.np, "fs": f"{c.fs / 1e3:g}", "duration": f"{c.duration:g}", "needle": mm(c.needle)}
    s["text"] = f"Np {s['np']}, {s['fs']} kHz, {s['duration']} s" + (f", needle {s['needle']} mm" if c.needle else "")
    s["at"] = f"{s['fs']} kHz, {s['duration']} s" + (f", needle {s['needle']} mm" if c.needle else "")
    return s


def build(csv_path, design_path=None, command_line=None, pdp_version=None, argv=None):
    import jinja2

    candidates, conditions, digest = read_ranked(csv_path)
    design = read_design(design_path) if design_path else None
    best, worst = candidates[0], candidates[-1]
    currents = [c for c in candidates if c.current]
    current = currents[0] if currents else None
    kind = best.ranking  # every row has the design's: read_ranked checked it
    corrected = best.values == "corrected"

    # Maps: every candidate at the recommended Np, fs, duration and needle, by geometry.
    at_best = {c.geometry: c for c in candidates if c.setting == best.setting}
    layout = Layout([c.geometry for c in candidates], current.geometry if current else None)
    marks = [("recommended", best.geometry)] + ([("current", current.geometry)] if current else [])
    maps = []
    for ci, name in enumerate(conditions):
        figures = []
        for qi, (column, title, diverging) in enumerate(MAP_QUANTITIES):
            values = {}
            for g in layout.geometries:
                c = at_best.get(g)
                v = c.conditions.get(name, {}).get(column) if c else None
                values[g] = None if v is None else 100 * v
            off_grid_note = None
            if layout.off_grid is not None:
                c = at_best.get(layout.off_grid)
                v = c.conditions.get(name, {}).get(column) if c else None
                off_grid_note = (f"current probe ({mm(layout.off_grid[0])}, {mm(layout.off_grid[1])}) mm, off the "
                                 f"grid: {'no value' if v is None else _cell_text(100 * v, diverging) + ' %'}")
            svg, blank = map_svg(layout, values, f"{name}: {title} (%)", diverging, marks, f"m{ci}-{qi}",
                                 off_grid_note)
            figures.append({"quantity": column, "title": title, "svg": svg, "blank": blank,
                            "cells": len(layout.geometries), "diverging": diverging})
        maps.append({"name": name, "description": (design or {}).get("conditions", {}).get(name), "figures": figures})

    # The objective over (dx, dy) for each Np, at the recommended fs, duration and needle.
    nps = sorted({c.np for c in candidates})
    objective_figure = None
    if len(nps) > 1:
        by_np = []
        for n in nps:
            at = {c.geometry: c for c in candidates if c.setting == (n,) + best.setting[1:]}
            values = {g: (None if at.get(g) is None or at[g].objective is None else 100 * at[g].objective)
                      for g in layout.geometries}
            notes = {g: f"{at[g].failures} failed" for g in layout.geometries if at.get(g) and at[g].failures}
            by_np.append((n, values, notes))

        def marks_of(n):
            return ([("recommended", best.geometry)] if best.np == n else []) + (
                [("current", current.geometry)] if current and current.setting == (n,) + best.setting[1:] else [])
        objective_figure = objective_svg(layout, by_np, marks_of, "objective")

    # The best candidate of each setting (Np, fs, duration, needle).
    settings = []
    for setting in sorted({c.setting for c in candidates}):
        first = next(c for c in candidates if c.setting == setting)  # candidates are in rank order
        settings.append(dict(setting_of(first), rank=first.rank, dx=mm(first.dx), dy=mm(first.dy),
                             objective=pct(first.objective), failures=first.failures, best=first is best))

    # The ranking table: the first 15, the current probe and the worst.
    shown = [c for c in candidates if c.rank <= candidates[min(TABLE_TOP, len(candidates)) - 1].rank]
    shown += [c for c in currents + [worst] if c not in shown]
    shown.sort(key=lambda c: c.rank)
    table, previous = [], None
    for c in shown:
        roles = (["recommended"] if c is best else []) + (["current probe"] if c.current else []) + (
            ["worst"] if c is worst and c is not best else [])
        table.append(dict(setting_of(c), gap=previous is not None and candidates.index(c) != candidates.index(
            previous) + 1, rank=c.rank, dx=mm(c.dx), dy=mm(c.dy), objective=pct(c.objective), failures=c.failures,
            scores=[pct(c.score(n)) for n in conditions], roles=roles, current=c.current, best=c is best,
            seconds="no value" if c.seconds is None else f"{c.seconds:.3g}"))
        previous = c

    def summary_of(c):
        rows = condition_rows(c, conditions)
        return {"name": c.name, "rank": c.rank, "objective": pct(c.objective), "failures": c.failures,
                "seconds": "no value" if c.seconds is None else f"{c.seconds:.3g}", "rows": rows,
                "dx": mm(c.dx), "dy": mm(c.dy)}

    summary = {"best": summary_of(best), "worst": summary_of(worst), "worst_ratio": ratio(worst, best),
               "nothing_measured": best.objective is None,
               "current": summary_of(current) if current else None,
               "current_is_best": current is best,
               "current_ratio": ratio(current, best) if current else None,
               "count": len(candidates), "conditions": len(conditions), "kind": kind, "corrected": corrected,
               "geometries": len(set(c.geometry for c in candidates)), "nps": nps,
               "fss": sorted({f"{c.fs / 1e3:g}" for c in candidates}, key=float),
               "durations": sorted({f"{c.duration:g}" for c in candidates}, key=float),
               "needles": sorted({mm(c.needle) for c in candidates}, key=float)}
    argv = sys.argv[1:] if argv is None else argv
    made = {"command_line": command_line or " ".join(["python3 pdp/design_report.py"]
                                                      + [shlex.quote(a) for a in argv]),
            "utc_time": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
            "pdp_version": pdp_version, "ranked": csv_path, "ranked_sha256": digest}
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(os.path.dirname(os.path.abspath(__file__))),
                             autoescape=True, trim_blocks=True, lstrip_blocks=True, undefined=jinja2.StrictUndefined)
    title = os.path.basename(design_path) if design_path else os.path.basename(csv_path)
    return env.get_template("design_report.html.j2").render(
        title=title, summary=summary, maps=maps, layout={"grid": layout.grid, "off_grid": layout.off_grid},
        best_setting=setting_of(best), objective_figure=objective_figure, settings=settings, table=table,
        conditions=conditions, design=design, made=made, top=TABLE_TOP, needles=any(c.needle for c in candidates),
        current_setting=dict(setting_of(current), same=current.setting == best.setting) if current else None)


def _pdp_version(given):
    """The version pdp passed, else the Python module's beside this file, else None."""
    if given:
        return given
    try:
        import pdp
        return pdp.__version__
    except Exception:  # the compiled core is optional here: the page says "not recorded"
        return None


def _parser():
    parser = argparse.ArgumentParser(prog="pdp design --report", description="One self-contained HTML page for the "
                                     "ranked CSV of pdp design: the recommended probe, error maps over (dx, dy) per "
                                     "condition, the ranking and the provenance.")
    parser.add_argument("input", nargs="?", metavar="RANKED.csv", help="the ranked CSV pdp design -o wrote")
    parser.add_argument("-o", "--output", metavar="REPORT.html", help="the page to write (required)")
    parser.add_argument("--config", metavar="DESIGN.toml",
                        help="the design file pdp design read: named on the page with its SHA-256; its conditions "
                        "describe the maps")
    parser.add_argument("--command-line", default=None, help=argparse.SUPPRESS)
    parser.add_argument("--pdp-version", default=None, help=argparse.SUPPRESS)
    return parser


def main(argv=None):
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = _parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as e:
        return EXIT_BAD_USAGE if e.code else 0
    try:
        if args.input is None or args.output is None:
            raise UsageProblem("give the ranked CSV and the page to write: pdp design --report REPORT.html, or "
                               "python3 design_report.py RANKED.csv --config DESIGN.toml -o REPORT.html")
        for given in (args.input, args.config):
            if given and os.path.exists(args.output) and os.path.exists(given) and os.path.samefile(args.output,
                                                                                                     given):
                raise UsageProblem(f"{args.output} is an input; choose another output file with -o")
        if args.config and not os.path.isfile(args.config):
            raise UsageProblem(f"--config {args.config}: no such file; give the design file pdp design read")
    except UsageProblem as e:
        print(f"pdp design: {e}", file=sys.stderr)
        return EXIT_BAD_USAGE
    try:
        import jinja2  # noqa: F401
        import matplotlib  # noqa: F401
        import numpy  # noqa: F401
    except ImportError as e:
        print(f"pdp design: {e.name} is missing: {MISSING_PACKAGE_HELP}", file=sys.stderr)
        return EXIT_MISSING_PACKAGE
    return _plotting().finish_page(
        "pdp design", lambda: build(args.input, args.config, command_line=args.command_line,
                                    pdp_version=_pdp_version(args.pdp_version), argv=argv),
        args.output, "--report", {InputProblem: EXIT_BAD_INPUT, UsageProblem: EXIT_BAD_USAGE},
        prefix=".pdp-design-report-")


if __name__ == "__main__":
    sys.exit(main())

"""pdp's profile report: one self-contained HTML page showing a whole
measurement and how far to trust it.

    python3 -m pdp.report PROFILE.json -o report.html     (or: pdp report ...)

The page holds the profile figures (pdp.plotting), the profile's flow
quantities (the JSON's "flow", METHOD 12: the c(y) and u(y) figures with the
fitted curves, a table of every quantity with its interval or the reason it
has none), one collapsible panel of
figures per position, a table of every profile-CSV column with its unit and
meaning (pdp.profile_columns(), the libraries' one declaration), the warnings
and reasons with every gap explained, and the provenance of the profile and
of the report. Figures are inline SVG: no network, no external file.

The per-position figures need what the JSON does not keep (the AWCC window
table, R11/R12, the velocity spectrum, the per-bubble tables of event
detection and of a multi-tip probe): each recording named in the
provenance is found (as written, then beside the JSON), its SHA-256 checked,
and processed again with the provenance's options through the Python module;
the report uses it only when the re-processed velocities (FSCC, AWCC, event
detection, the multi-tip mean vector) equal the JSON's. Otherwise the position says why its detail is missing.

Exit status as pdp's (docs/guide/settings.md, "Exit status"): 1 bad input, 2 bad usage,
3 output not written, 4 internal error, 5 a package is missing.
"""

import argparse
import datetime
import hashlib
import json
import math
import os
import shlex
import sys

EXIT_BAD_INPUT, EXIT_BAD_USAGE, EXIT_MISSING_PACKAGE = 1, 2, 5  # the others: plotting.finish_page
MISSING_PACKAGE_HELP = ("pdp report draws with matplotlib and writes the page with Jinja2: install Debian's "
                        "python3-matplotlib and python3-jinja2 (sudo apt install python3-matplotlib python3-jinja2)")


class InputProblem(Exception):
    """A JSON file that is not a pdp result."""


# --- reading the profile ---------------------------------------------------------


def load(path):
    try:
        with open(path, "rb") as f:
            raw = f.read()
    except OSError as e:
        raise InputProblem(f"{path}: cannot read: {e.strerror}") from None
    try:
        data = json.loads(raw)
    except ValueError as e:
        raise InputProblem(f"{path}: not JSON ({e}); give the file pdp process --json wrote") from None
    if not isinstance(data, dict):
        raise InputProblem(f"{path}: not a pdp result (a JSON object); give the file pdp process --json wrote")
    rows = data.get("profile") if "profile" in data else [data]
    if not isinstance(rows, list) or not rows or not all(isinstance(r, dict) and isinstance(r.get("tips"), list)
                                                          and r["tips"] for r in rows):
        raise InputProblem(f"{path}: field 'profile' (or a recording's 'tips') missing or empty: not a pdp "
                           "process result; give the file pdp process --json wrote")
    where = "profile[{}]" if "profile" in data else "the recording{}"
    for i, row in enumerate(rows):
        for key in ("fscc", "awcc", "structure", "correction", "velocity_spectrum", "events", "multi_tip", "sizes"):
            if row.get(key) is not None and not isinstance(row[key], dict):
                raise InputProblem(f"{path}: field '{key}' of {where.format(f'[{i}]' if 'profile' in data else '')} "
                                   "is not an object: not what pdp process writes; give the file pdp process "
                                   "--json wrote")
        if not all(isinstance(t, dict) for t in row["tips"]):
            raise InputProblem(f"{path}: field 'tips' of {where.format(f'[{i}]' if 'profile' in data else '')} "
                               "holds something other than objects: not what pdp process writes")
    if not isinstance(data.get("flow", {}), dict):
        raise InputProblem(f"{path}: field 'flow' is not an object: not what pdp process writes")
    if not isinstance(data.get("provenance", {}), dict):
        raise InputProblem(f"{path}: field 'provenance' is not an object: not what pdp process writes")
    return data, rows, hashlib.sha256(raw).hexdigest()


def pointer_value(obj, pointer):
    """The value at an RFC 6901 pointer, or None where the path does not exist."""
    if pointer == "":
        return None
    for token in pointer.split("/")[1:]:
        token = token.replace("~1", "/").replace("~0", "~")
        if isinstance(obj, list):
            obj = obj[int(token)] if token.isdigit() and int(token) < len(obj) else None
        elif isinstance(obj, dict):
            obj = obj.get(token)
        else:
            return None
    return obj


def check_written_values(path, data, rows, columns):
    """Every text the columns declare values for (statuses, the quality, the
    weighting, ...: pdp.profile_columns()' "values", the libraries' own
    lists) is one pdp writes; another is refused naming the file, the row's
    JSON pointer and the value, never drawn as a default."""
    for i, row in enumerate(rows):
        where = f"/profile/{i}" if "profile" in data else ""
        for c in columns:
            value = pointer_value(row, c["pointer"]) if c.get("values") else None
            for v in value if isinstance(value, list) else [value]:  # a list column: each of its codes
                if isinstance(v, str) and v not in c["values"]:
                    raise InputProblem(f"{path}: {where}{c['pointer']} = '{v}' is not a value pdp writes "
                                       f"({', '.join(c['values'])}); give the file pdp process --json wrote")


def cell_value(row, column, provenance):
    if column["name"] == "pdp_version":
        return provenance.get("pdp_version")
    return pointer_value(row, column["pointer"])


def display(value, unit):
    if value is None:
        return ""
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if not math.isfinite(value):
            return str(value)
        if unit in ("m", "s") and value != 0 and abs(value) < 1:
            return f"{1e3 * value:.4g} m{unit}"
        if value == int(value) and abs(value) < 1e12:
            return str(int(value))
        return f"{value:.4g}"
    if isinstance(value, list):
        return "; ".join(str(v) for v in value)
    return str(value)


def gap_reason(row, pointer, have_positions):
    """Why the value at `pointer` is missing from a row, in the user's words."""
    section = pointer.split("/")[1] if pointer.count("/") >= 1 else ""
    if section == "position":
        return "no positions given (pdp process --positions)"
    if section == "awcc":
        awcc = row.get("awcc")
        if awcc is None:
            return "AWCC not run (pdp process --method fscc)"
        if pointer.endswith("_measured") and not awcc.get("probe_corrected"):
            return "no bubble-probe correction (--probe-correction off): the measured values are AWCC's own columns"
        why = awcc.get("reason") or (awcc.get("quality_reason") if awcc.get("quality") != "ok" else None)
        return f"AWCC: {why}" if why else "not defined for this recording"
    if section == "fscc":
        fscc = row.get("fscc")
        if fscc is None:
            return "FSCC not run (pdp process --method awcc)"
        why = fscc.get("reason") or fscc.get("note")
        return f"FSCC: {why}" if why else "not defined for this recording"
    if section == "correction":
        c = row.get("correction")
        if c is None:
            return "not corrected: no model given (pdp process --correct MODEL.qrf)"
        if c.get("in_range") and c.get("forest") == "fscc":
            return ("Tu not corrected: AWCC gave no usable result, and the FSCC forest that corrected this row's "
                    "velocity corrects the velocity only")
        if c.get("status") == "untrusted":
            return "not corrected: untrusted (its quantiles are drawn apart): " + str(c.get("reason"))
        return "not corrected: " + (c.get("reason") or str(c.get("status")))
    if section == "velocity_spectrum":
        s = row.get("velocity_spectrum")
        if s is None:
            return "no velocity spectrum: AWCC not run"
        return "velocity spectrum: " + (s.get("reason") or str(s.get("status")))
    if pointer.endswith("sauter_diameter"):
        return "d32 = 1.5 u c / F needs a velocity and bubbles: " + (
            f"velocity from {row.get('chord_velocity_source')}" if row.get("chord_velocity") else "no velocity")
    if section == "dy" or section == "dx":
        return "no tip separation given (--dx, --dy)"
    return "not defined for this recording"


# --- the profile's flow quantities (the JSON's "flow"; METHOD 12) ------------------

# (JSON pointer in "flow", quantity, symbol, unit shown, scale from the JSON's unit to it), in a paper's order;
# the characteristic depths come first (flow_table).
def _flow_quantities():
    import pdp
    # The characteristic depths come first (flow_table); the continuity error has no symbol of its own.
    return [(q["pointer"], q["meaning"], "" if q["pointer"] == "/continuity_error" else q["symbol"], q["shown_unit"],
             q["shown_scale"]) for q in pdp._pdp.flow_quantities() if q["pointer"] != "/y90"]


FLOW_QUANTITIES = _flow_quantities()

# What each rule does below the lowest position (awcc/profile_flow.hpp, InvertRule).
INVERT_RULES = {
    "held": "c is held at the lowest position's value from the invert up to it (the probe's lowest reading is the "
            "best guess of the layer it cannot reach)",
    "zero": "c = 0 from the invert to the lowest position (clear water at the invert)",
    "left-out": "the integrals start at the lowest position: C_mean is the mean over [y_0, Y90], and d takes the "
                "layer below y_0 at that mean",
}


def _number_text(value, scale):
    v = None if value is None else scale * value
    return "" if v is None else f"{v:.4g}"


def flow_table(flow):
    """The page's table of the flow quantities: each with its value, unit, 95 %
    interval or the reason it has none (the JSON's, never recomputed), and
    the fits' residuals; with the rule below the lowest position, the notes
    and each row's velocity source."""
    from pdp import plotting
    quantities = []

    def add(pointer, name, symbol, unit, scale, q, residual=None):
        value, ci = plotting.number(q.get("value")), q.get("ci95")
        lower, upper = (plotting.number(b) for b in (ci or (None, None)))
        reason = q.get("reason") or ""
        if value is not None and (lower is None or upper is None) and not reason:
            reason = "no interval"
        quantities.append({
            "pointer": pointer, "name": name, "symbol": symbol, "unit": unit, "scale": scale,
            "value": value, "lower": lower, "upper": upper, "residual": residual,
            "text": _number_text(value, scale), "interval": f"[{_number_text(lower, scale)}, "
                                                            f"{_number_text(upper, scale)}]"
            if lower is not None and upper is not None else "",
            "residual_text": "" if residual is None else f"{residual:.3g}",
            "reason": reason, "draws": q.get("draws_defined"),
            "data": {k: json.dumps(v) for k, v in (("value", value), ("lower", lower), ("upper", upper),
                                                   ("residual", residual))}})

    for k, (name, depth) in enumerate(plotting.flow_depths(flow)):
        level = depth.get("level", 0.9)
        add("/y90" if k == 0 else f"/levels/{k - 1}", f"characteristic depth: the first y where c = {level:g}",
            name, "mm", 1e3, depth)
    discharge = plotting.number(flow.get("discharge"))
    for pointer, name, symbol, unit, scale in FLOW_QUANTITIES:
        if pointer == "/continuity_error" and discharge is None:
            continue  # no check asked for: the page says so beside the table
        q = plotting.get(flow, *pointer.split("/")[1:]) or {}
        residual = None
        if pointer in ("/smooth_chute", "/stepped_chute"):
            residual = plotting.number(q.get("residual"))
        elif pointer == "/power_law/n":
            residual = plotting.number(plotting.get(flow, "power_law", "residual"))
        add(pointer, name, symbol or "(q_w - q) / q", unit, scale, q, residual)
    rows = [{"name": r.get("name"), "position": r.get("position"), "void_fraction": r.get("void_fraction"),
             "velocity": r.get("velocity"), "source": r.get("velocity_source"),
             "y_text": _number_text(plotting.number(r.get("position")), 1e3),
             "c_text": _number_text(plotting.number(r.get("void_fraction")), 1.0),
             "u_text": _number_text(plotting.number(r.get("velocity")), 1.0)} for r in flow.get("rows") or []]
    return {"status": flow.get("status"), "reason": flow.get("reason"), "notes": flow.get("notes") or [],
            "invert": flow.get("invert"), "invert_text": INVERT_RULES.get(flow.get("invert"), ""),
            "discharge": discharge, "discharge_text": None if discharge is None else f"{discharge:.4g} m\u00b2/s",
            "draws": flow.get("draws"), "seed": flow.get("seed"), "quantities": quantities, "rows": rows}


def flow_absent_reason(data):
    """Why a JSON has no flow object."""
    if "profile" not in data:
        return "one recording: the flow quantities are a profile's (pdp process with two or more recordings and " \
               "--positions)"
    return "no flow quantities: they need two or more recordings with their positions (pdp process --positions " \
           "or --manifest)"


# --- per-position detail: the recording processed again ---------------------------


def _sha256_of(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _same(a, b):
    a, b = (None if v is None or (isinstance(v, float) and math.isnan(v)) else v for v in (a, b))
    return a == b


def process_options(provenance, pdp):
    """The provenance's options that differ from their declared defaults, as keywords of pdp.process."""
    defaults = {o["name"]: str(o["default"]) for o in pdp.options() if o["group"] != "scene"}
    return {k.replace("-", "_"): v for k, v in (provenance.get("options") or {}).items()
            if k in defaults and defaults[k] != v}


def shown_path(path, json_path):
    """A recording's path as the report shows it: relative to the JSON's
    folder (where the report is read), the written path kept in the data."""
    if not path or not os.path.isabs(path):
        return path
    return os.path.relpath(path, os.path.dirname(os.path.abspath(json_path)))


def detail_for(index, row, data, json_dir, pdp, options):
    """(detail dict, None) or (None, why not)."""
    provenance = data.get("provenance") or {}
    inputs = provenance.get("inputs") or []
    rows = data.get("profile", [data])
    if len(inputs) != len(rows):
        return None, ("the provenance names no recording for each row (a JSON from pdp correct or edited by "
                      "hand): process the recordings again with pdp process --report")
    entry = inputs[index]
    written = entry.get("file", "")
    candidates = [written] if os.path.isabs(written) else [written, os.path.join(json_dir, written),
                                                            os.path.join(json_dir, os.path.basename(written))]
    path = next((p for p in candidates if os.path.isfile(p)), None)
    if path is None:
        return None, (f"recording {written} not found (looked in the working folder and beside the JSON): run the "
                      "report from the folder pdp process ran in")
    try:
        changed = entry.get("sha256") and _sha256_of(path) != entry["sha256"]
    except OSError as e:
        return None, f"{path} cannot be read: {e.strerror}"
    if changed:
        return None, f"{path} is not the recording processed (its SHA-256 differs from the provenance's)"
    try:
        r = pdp.process(path, **options)
    except pdp.PdpError as e:
        return None, f"{path} could not be processed again: {e}"
    for section, name in (("fscc", "FSCC"), ("awcc", "AWCC"), ("events", "event detection"),
                          ("multi_tip", "multi-tip")):
        if not _same((row.get(section) or {}).get("velocity"), (r.get(section) or {}).get("velocity")):
            return None, (f"processed again, {path} gives a different {name} velocity than the JSON "
                          f"(pdp {provenance.get('pdp_version')} wrote it, this is pdp {pdp.__version__})")
    windows = None if r.windows is None else {k: list(r.windows[k]) for k in
                                              ("start_time", "velocity", "fate")}
    correlation = None if r.correlation is None else {k: [float(x) for x in r.correlation[k]] for k in
                                                      ("lag", "r11", "r12")}
    spectrum = None if r.spectrum is None else {
        "frequency": [float(x) for x in r.spectrum["frequency"]],
        "density": [float(x) for x in r.spectrum["density"]],
        "resolvable_frequency": r.spectrum.get("resolvable_frequency")}
    # The per-bubble columns the panels draw (plotting.bubble_histogram, bubble_size_velocity).
    bubbles = None if r.bubbles is None else {k: list(r.bubbles[k]) for k in
                                              ("velocity", "chord_length", "fate")}
    vectors = None if r.vectors is None else {k: list(r.vectors[k]) for k in
                                              ("velocity_x", "speed", "diameter_front", "fate")}
    return {"windows": windows, "correlation": correlation, "spectrum": spectrum, "bubbles": bubbles,
            "vectors": vectors}, None


# --- figures ------------------------------------------------------------------------


def _profile_svgs(rows, flow):
    """The profile figures; the flow's (plotting.FLOW_FIGURES) when the JSON has a flow object."""
    from pdp import plotting
    # The size figures only where a row has a distribution; else one note
    # (an svg of None) says why for every position at once.
    sizes = plotting.sizes_drawable(rows)
    figures = list(plotting.PROFILE_FIGURES) + [(key, title, make) for key, title, make, method in
                                                 plotting.BUBBLE_PROFILE_FIGURES
                                                 if any(r.get(method) is not None for r in rows)
                                                 and (method != "sizes" or sizes)]
    svgs = [(key, title, plotting.svg(make(rows), salt=key)) for key, title, make in figures]
    if not sizes and any(r.get("sizes") is not None for r in rows):
        svgs.append(("size-distributions", plotting.sizes_note(rows), None))
    if flow is not None:
        svgs += [(key, title, plotting.svg(make(rows, flow), salt=key)) for key, title, make in plotting.FLOW_FIGURES]
    return svgs


def _position_svg(args):
    from pdp import plotting
    index, row, detail = args
    if detail is None:  # not recomputed: each panel that needs it says so
        detail = {"windows": None, "correlation": None, "spectrum": None, "bubbles": None, "vectors": None}
    return plotting.position_svg(row, detail, salt=f"p{index}")


class _Serial:
    """The pool's interface, run in this process (--jobs 1)."""

    class _Done:
        def __init__(self, value):
            self.value = value

        def get(self):
            return self.value

    def apply_async(self, function, args):
        return self._Done(function(*args))


def figures(rows, detail_of, jobs, per_position=True, flow=None):
    """(profile SVGs, per-position SVGs, per-position notes). Workers draw
    while this process reads and processes the recordings again (detail_of(i)
    -> (detail, note)); they are forked before any processing, so no thread
    of the core library is copied half-way."""
    pool = None
    if jobs > 1 and len(rows) > 1 and per_position:
        import multiprocessing
        pool = multiprocessing.get_context("fork").Pool(min(jobs, len(rows) + 1))
    try:
        runner = pool or _Serial()
        profile = runner.apply_async(_profile_svgs, (rows, flow))
        positions, notes = [], []
        for i, row in enumerate(rows):
            detail, note = detail_of(i)
            notes.append(note)
            positions.append(runner.apply_async(_position_svg, ((i, row, detail),)) if per_position
                             else _Serial._Done(None))
        return profile.get(), [p.get() for p in positions], notes
    finally:
        if pool:
            pool.close()
            pool.join()


# --- the page -----------------------------------------------------------------------


def build(json_path, detail=True, jobs=1, command_line=None, input_name=None):
    from pdp import plotting
    import jinja2
    import pdp

    data, rows, digest = load(json_path)
    columns = pdp.profile_columns()
    check_written_values(json_path, data, rows, columns)
    provenance = data.get("provenance") or {}
    have_positions = all(plotting.number(r.get("position")) is not None for r in rows)
    ys, _ = plotting.positions_mm(rows)
    labels = [f"{y:g} mm" if have_positions else f"row {y}" for y in ys]

    if detail:
        options = process_options(provenance, pdp)
        json_dir = os.path.dirname(os.path.abspath(json_path))

        def detail_of(i):
            return detail_for(i, rows[i], data, json_dir, pdp, options)
    else:
        def detail_of(i):
            return None, None
    profile_svgs, position_svgs, detail_notes = figures(rows, detail_of, jobs, per_position=detail,
                                                        flow=data.get("flow"))

    text_columns = [c for c in columns if c["name"].endswith("reason") or c["name"] == "warnings"]
    # A row's flags are codes, each with its text among the warnings: an empty list is no gap.
    list_columns = text_columns + [c for c in columns if c["name"] == "flags" or c["name"].endswith("notes")]
    gaps, table = {}, []
    for c in columns:
        cells = []
        for i, row in enumerate(rows):
            value = cell_value(row, c, provenance)
            shown = shown_path(value, json_path) if c["name"] == "file" and isinstance(value, str) else value
            cell = {"value": json.dumps(value), "text": display(shown, c["unit"]), "gap": None, "note": False}
            if c in text_columns and value:  # long text: told below the table, linked from here
                cell["text"], cell["note"] = "see note", True
            if value is None or value == []:
                if c not in list_columns:  # an empty reason, warning or flag list is no gap
                    cell["gap"] = gaps.setdefault(gap_reason(row, c["pointer"], have_positions), len(gaps) + 1)
            cells.append(cell)
        table.append({"name": c["name"], "unit": c["unit"], "meaning": c["meaning"], "pointer": c["pointer"],
                      "cells": cells})

    positions = []
    for i, row in enumerate(rows):
        notes = []  # (name, text, anchor): the table links a column's first note
        for c in text_columns:
            value = cell_value(row, c, provenance)
            for k, v in enumerate(v for v in (value if isinstance(value, list) else [value]) if v):
                notes.append((c["name"], v, f"note-{i}-{c['name']}" if k == 0 else None))
        # Files written before the warnings were one list kept E4's warning apart.
        spectrum_warning = (row.get("velocity_spectrum") or {}).get("warning")
        if spectrum_warning and spectrum_warning not in (row.get("warnings") or []):
            notes.append(("velocity_spectrum.warning", spectrum_warning, None))
        correction = row.get("correction") or {}
        if correction.get("status") == "untrusted":
            notes.append(("correction.status", "untrusted: its quantiles are kept in the table but are not a "
                          "corrected value (the figures draw its median apart, hollow)", None))
        for text in correction.get("notes") or []:
            notes.append(("correction.notes", text, None))
        # The bubble-by-bubble methods' quality and flag beside AWCC's, in the position's summary.
        bubble = [(name, *plotting.verdict(row, key)[:2]) for key, name in (("multi_tip", "multi-tip"),
                                                                             ("events", "event detection"))
                  if row.get(key) is not None]
        positions.append({"index": i, "label": labels[i], "file": shown_path(row.get("file"), json_path),
                          "svg": position_svgs[i],
                          "quality": (row.get("awcc") or {}).get("quality"), "bubble": bubble, "notes": notes,
                          "detail_note": detail_notes[i]})

    made = {"pdp_version": pdp.__version__, "utc_time": datetime.datetime.now(datetime.timezone.utc)
            .strftime("%Y-%m-%dT%H:%M:%SZ"), "command_line": command_line or " ".join(
                ["python3 -m pdp.report"] + [shlex.quote(a) for a in sys.argv[1:]]),
            "input": input_name or json_path, "sha256": digest}
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(os.path.dirname(os.path.abspath(__file__))),
                             autoescape=True, trim_blocks=True, lstrip_blocks=True, undefined=jinja2.StrictUndefined)
    return env.get_template("report.html.j2").render(
        title=input_name or os.path.basename(json_path), rows=rows, labels=labels, profile_svgs=profile_svgs,
        positions=positions, table=table, gaps=sorted(gaps.items(), key=lambda kv: kv[1]),
        provenance=dict(provenance, inputs=[dict(i, file=shown_path(i.get("file"), json_path))
                                            for i in provenance.get("inputs") or []]),
        made=made, panels=plotting.POSITION_PANELS, bubble_panels=plotting.BUBBLE_PANELS,
        flow=flow_table(data["flow"]) if isinstance(data.get("flow"), dict) else None,
        flow_absent=flow_absent_reason(data),
        single="profile" not in data,
        sampling_intervals_only=pdp._pdp.sampling_intervals_only)


def _parser():
    """The report's options: their one declaration (pdp report hands its arguments here)."""
    parser = argparse.ArgumentParser(prog="pdp report", description="One self-contained HTML page for a pdp "
                                     "process JSON (a profile or one recording): figures, table, provenance.")
    parser.add_argument("input", nargs="?", metavar="PROFILE.json", help="the file pdp process --json wrote")
    parser.add_argument("-o", "--output", metavar="REPORT.html", help="the page to write (required)")
    parser.add_argument("--no-detail", action="store_true",
                        help="leave out the per-position figures (no recording is read again)")
    parser.add_argument("--jobs", type=int, default=min(os.cpu_count() or 1, 4), metavar="N",
                        help="processes drawing the figures; the page is the same for any N (default: the "
                        "cores, at most 4)")
    parser.add_argument("--config", metavar="FILE.toml",
                        help="settings file (TOML): keys are these options' names without --, at the top level or "
                        "in a [report] table; the command line overrides it")
    parser.add_argument("--command-line", default=None, help=argparse.SUPPRESS)
    # pdp process --report: the JSON is a scratch file; the page names what made it instead.
    parser.add_argument("--input-name", default=None, help=argparse.SUPPRESS)
    return parser


def _apply_config(parser, args, argv):
    """Settings from --config for the options not given on the command line."""
    import tomllib
    try:
        with open(args.config, "rb") as f:
            table = tomllib.load(f)
    except OSError as e:
        raise ValueError(f"{args.config}: cannot read: {e.strerror}; give an existing settings file") from None
    except tomllib.TOMLDecodeError as e:
        raise ValueError(f"{args.config}: not TOML ({e}); fix the file") from None
    settings = dict(table.get("report", {}), **{k: v for k, v in table.items() if not isinstance(v, dict)})
    known = {a.dest.replace("_", "-"): a for a in parser._actions
             if a.dest not in ("help", "config", "command_line", "input_name")}
    # What the command line gave, however it was spelt (--output=X, -oX, --out X):
    # a second parse in which nothing has a default.
    bare = _parser()
    for action in bare._actions:
        action.default = argparse.SUPPRESS
    given = set(vars(bare.parse_args(argv)))
    for key, value in settings.items():
        action = known.get(key)
        if action is None:
            raise ValueError(f"{args.config}: unknown setting '{key}'; pdp report's settings are "
                             f"{', '.join(sorted(known))}")
        if action.dest in given or (action.dest == "input" and args.input is not None):
            continue
        expected = bool if isinstance(action, argparse._StoreTrueAction) else action.type or str
        if not isinstance(value, expected) or (expected is int and isinstance(value, bool)):
            kind = {bool: "true or false", int: "a whole number", str: "a string"}[expected]
            raise ValueError(f"{args.config}: setting '{key}' is {value!r}; give {kind}")
        setattr(args, action.dest, value)


def main(argv=None):
    argv = sys.argv[1:] if argv is None else list(argv)
    parser = _parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as e:
        return EXIT_BAD_USAGE if e.code else 0
    try:
        if args.config:
            _apply_config(parser, args, argv)
        if args.input is None or args.output is None:
            raise ValueError("give the profile JSON and the page to write: pdp report PROFILE.json -o REPORT.html")
        if args.jobs < 1:
            raise ValueError(f"--jobs {args.jobs}: give at least 1")
        if os.path.exists(args.output) and os.path.exists(args.input) and os.path.samefile(args.output, args.input):
            raise ValueError(f"{args.output} is the input; choose another output file with -o")
    except ValueError as e:
        print(f"pdp report: {e}", file=sys.stderr)
        return EXIT_BAD_USAGE
    try:
        import jinja2  # noqa: F401
        import matplotlib  # noqa: F401
        import numpy  # noqa: F401
    except ImportError as e:
        print(f"pdp report: {e.name} is missing: {MISSING_PACKAGE_HELP}", file=sys.stderr)
        return EXIT_MISSING_PACKAGE
    try:
        import pdp  # noqa: F401
    except ImportError as e:
        print(f"pdp report: the pdp module cannot be loaded ({e}): build pdp with its Python module or install it "
              "(cmake --install), and run Debian's /usr/bin/python3", file=sys.stderr)
        return EXIT_MISSING_PACKAGE
    from pdp import plotting
    return plotting.finish_page(
        "pdp report", lambda: build(args.input, detail=not args.no_detail, jobs=args.jobs,
                                    command_line=args.command_line, input_name=args.input_name),
        args.output, "-o", {InputProblem: EXIT_BAD_INPUT}, prefix=".pdp-report-")


if __name__ == "__main__":
    sys.exit(main())

"""pdp: dual-tip phase-detection probe measurements in bubbly and self-aerated flows.

Numpy in, numpy and dicts out, no file needed:

    rec = pdp.read("dc157_05.dat", fs=20e3)             # channels, fs, metadata
    r = pdp.process(rec, dx="7.15mm")                   # as `pdp process --json`
    r.tips[0].void_fraction, r.awcc.velocity, r.windows # attribute or key access
    r = pdp.process("four-tip.h5")                      # a multi-tip probe: r.multi_tip, r.vectors
    r.bubbles                                           # method="events": a velocity per bubble
    a = pdp.awcc(lead, trail, fs=20e3, dx=7.15e-3, np=10)
    s = pdp.synth(duration=10, fs=100e3)                # signals and their truth
    c = pdp.correct(r, model="awcc.qrf")                # bias-corrected quantiles
    p = pdp.process(files, fs=20e3, dx="7.15mm", positions=ys)  # a Profile
    p.to_dataframe(), p.profile[1].windows              # the profile CSV's table; a position's windows
    p.flow.y90.value, p.flow.report()                   # the profile as a flow (Y90, C_mean, q_w, fits)
    f = pdp.flow("profile.json", discharge="0.2m2/s")   # the same of a profile JSON or CSV read back

Options are the command line's, by the same declarations (``pdp process
--help``): write ``filter_a=0.5`` for ``--filter-a 0.5``. A number is in SI
units (m, s, Hz, V); a string may carry its unit ("7.15mm", "20kHz"); True and
False switch flags. Results carry the JSON keys of docs/output.md. Errors
raise pdp.InputError or pdp.OptionError (both ValueError) with the library's
message. Use Debian's /usr/bin/python3, whose NumPy the module was built with.
"""

import json as _json
import os as _os
import sys as _sys

import numpy as _np

from . import _pdp
from ._errors import InputError, OptionError, OutputError, PdpError

__version__ = _pdp.version
generator_version = _pdp.generator_version  # the seeded streams' version (awcc/random.hpp)
__all__ = ["read", "binarise", "phase_statistics", "fscc", "awcc", "process", "synth", "correct", "options",
           "profile_columns", "flow",
           "Result", "Profile", "Flow", "Recording", "InputError", "OptionError", "OutputError", "PdpError"]


class Result(dict):
    """A result: the JSON object of docs/output.md, with attribute access
    (``r.awcc.velocity`` is ``r["awcc"]["velocity"]``). A key that is also a
    dict method (``values`` of a profile column) is read with brackets:
    ``c["values"]``; ``c.values`` is the method."""

    def __getattr__(self, name):
        try:
            return self[name]
        except KeyError:
            raise AttributeError(f"no '{name}' in this result; it has: {', '.join(self)}") from None

    def __dir__(self):
        return list(self) + list(super().__dir__())

    def to_json(self, **kwargs):
        """The result as JSON text (array attributes such as ``windows`` are not part of it)."""
        return _json.dumps(self, **kwargs)


# What pdp.process keeps of a recording beside its JSON, as attributes of its
# Result: the window table, R11 and R12, the velocity spectrum, event
# detection's bubble table and the multi-tip vector table.
_DETAIL = ("windows", "correlation", "spectrum", "bubbles", "vectors")


class Profile(Result):
    """A profile: ``{"profile": [...], "provenance": ...}`` as ``pdp process
    --json`` writes it, one Result per position in ``profile``. Processed by
    pdp.process, each position keeps its detail: ``profile[i].windows`` (the
    AWCC window table), ``.correlation``, ``.spectrum``, ``.bubbles`` (event
    detection's bubble table) and ``.vectors`` (the multi-tip vector table).
    With every position given, ``flow`` is the profile as a flow (a Flow)."""

    def __getattr__(self, name):
        if name in _DETAIL and name not in self:
            raise AttributeError(f"a profile has no '{name}' of its own: each position has its own, "
                                 f"profile[i].{name}")
        if name == "flow" and name not in self:
            raise AttributeError("this profile has no flow quantities: give every file its position "
                                 "(positions=[...], m) to pdp.process")
        return super().__getattr__(name)

    def to_dataframe(self):
        """The profile as a pandas DataFrame: one row per position, the
        profile CSV's columns (pdp.profile_columns(self): names, order, SI
        units in ``attrs["units"]``, meanings in ``attrs["meanings"]``) with
        the JSON's values (None/NaN where the CSV cell is empty; true/false
        where it writes on/off; ``file`` as given; ``warnings`` a list).
        Needs pandas (Debian's python3-pandas)."""
        try:
            import pandas
        except ImportError:
            raise ImportError("Profile.to_dataframe needs pandas: install Debian's python3-pandas "
                              "(scripts/setup installs it)") from None
        from .report import cell_value  # the report's table reads its cells the same way

        columns = profile_columns(self)
        provenance = self.get("provenance") or {}
        rows = self["profile"]
        frame = pandas.DataFrame({c["name"]: [cell_value(row, c, provenance) for row in rows] for c in columns},
                                 columns=[c["name"] for c in columns])
        frame.attrs["units"] = {c["name"]: c["unit"] for c in columns}
        frame.attrs["meanings"] = {c["name"]: c["meaning"] for c in columns}
        return frame


# The quantities of a profile's flow, in the order Flow.to_dataframe lists
# them: (name, unit, where in the flow JSON).
_FLOW_QUANTITIES = tuple((q["symbol"], q["unit"], tuple(q["pointer"].split("/")[1:]))
                         for q in _pdp.flow_quantities())


class ConcentrationFit(Result):
    """A fitted air-concentration model of a Flow (``smooth_chute``: D',
    Chanson 1997; ``stepped_chute``: D_0, Chanson & Toombes 2002): ``value``
    (the diffusivity), ``ci95``, ``reason``, ``residual`` (rms of c_i -
    c(y_i)), ``points``, ``k_prime``; ``curve(y)`` evaluates c at y (m)."""

    def curve(self, y):
        """c(y) of the fitted model at every y (m; a number or an array), by
        the library's formula (awcc/profile_flow.hpp). Raises ValueError,
        with the fit's reason, when the fit has no value."""
        if self.get("value") is None:
            raise ValueError(f"no fitted curve: {self.get('reason')}")
        values = _pdp.concentration_curve(self._kind, float(self["value"]), float(self._y90),
                                          _np.atleast_1d(_np.asarray(y, dtype=float)))
        return values.reshape(_np.shape(y)) if _np.ndim(y) else float(values[0])


class Flow(Result):
    """A profile as a flow (METHOD 12, awcc/profile_flow.hpp): the ``flow``
    object of the profile JSON (docs/output.md), with attribute access.
    Every quantity (``y90``, each of ``levels``, ``c_mean``,
    ``clear_water_depth``, ``power_law.n`` and ``.u90``,
    ``water_discharge``, ``air_discharge``, ``continuity_error``,
    ``smooth_chute``, ``stepped_chute``) has ``value``, ``ci95`` (95 % by
    Monte Carlo over the rows' own uncertainty) and ``reason`` (why none, or
    how to read it); ``rows`` each with its ``velocity_source``; ``notes``;
    ``status`` (ok, incomplete, refused) and ``message``. The fits'
    ``curve(y)`` evaluates c(y); ``to_dataframe()`` is the quantities'
    table; ``report()`` the summary pdp prints."""

    @property
    def message(self):
        """Why the status is not ok (the JSON's ``reason``); None when ok."""
        return self.get("reason")

    def report(self):
        """The summary ``pdp process`` prints for the profile: every quantity
        with its interval or its reason, the notes, each row's velocity."""
        return self._report

    def to_dataframe(self):
        """The quantities as a pandas DataFrame, one row each: ``quantity``
        (Y90, Y50 ..., C_mean, d, N, u90, q_w, q_a, continuity_error, D',
        D_0, H_res), ``value``, ``ci95_lower``, ``ci95_upper``, ``unit`` and
        ``reason`` (NaN/None where there is none); the units also in
        ``attrs["units"]``. Needs pandas (Debian's python3-pandas)."""
        try:
            import pandas
        except ImportError:
            raise ImportError("Flow.to_dataframe needs pandas: install Debian's python3-pandas "
                              "(scripts/setup installs it)") from None
        rows = []

        def add(name, unit, q):
            ci = q.get("ci95") or [None, None]
            rows.append({"quantity": name, "value": q.get("value"), "ci95_lower": ci[0], "ci95_upper": ci[1],
                         "unit": unit, "reason": q.get("reason")})

        for name, unit, path in _FLOW_QUANTITIES:
            q = self
            for key in path:
                q = q[key]
            add(name, unit, q)
            if name == "Y90":
                for level in self["levels"]:
                    add(f"Y{100 * level['level']:g}", "m", level)
        frame = pandas.DataFrame(rows, columns=["quantity", "value", "ci95_lower", "ci95_upper", "unit", "reason"])
        for column in ("value", "ci95_lower", "ci95_upper"):
            frame[column] = frame[column].astype(float)
        frame.attrs["units"] = dict(zip(frame["quantity"], frame["unit"]))
        return frame


def _flow_of(answer):
    """A Flow from the compiled core's profile_flow answer (None when the
    source has no profile's flow), its warnings issued."""
    if answer["flow"] is None:
        return None
    import warnings as _warnings
    for w in answer["warnings"]:
        _warnings.warn(w, stacklevel=3)
    f = _wrap(answer["flow"], "flow")
    f._report = answer["report"]
    return f


def _wrap(value, key=None):
    if isinstance(value, dict):
        if key == "flow":
            f = Flow((k, _wrap(v, k)) for k, v in value.items())
            y90 = f["y90"].get("value") if isinstance(f.get("y90"), dict) else None
            for kind in ("smooth_chute", "stepped_chute"):
                if isinstance(f.get(kind), dict):
                    fit = ConcentrationFit(f[kind])
                    fit._kind, fit._y90 = kind, y90
                    f[kind] = fit
            f._report = None
            return f
        if isinstance(value.get("profile"), list):
            return Profile((k, _wrap(v, k)) for k, v in value.items())
        out = Result((k, _wrap(v, k)) for k, v in value.items())
        sizes = out.get("sizes")
        if isinstance(sizes, Result) and "bins" in sizes:  # a recording's size distribution: its bins as a table
            sizes.__dict__["table"] = _sizes_table(sizes)
        return out
    if isinstance(value, list):
        return [_wrap(v) for v in value]
    return value


_TABLE_UNITS = {table: dict(columns) for table, columns in _pdp.table_units().items()}


def _table(columns, name="windows"):
    """A dict of arrays (one per declared column of table ``name``: windows,
    bubbles, vectors) as a pandas DataFrame when pandas is importable, its
    columns' SI units in ``attrs["units"]`` ("" for text)."""
    if columns is None:
        return None
    try:
        import pandas
    except ImportError:
        return columns
    frame = pandas.DataFrame(columns)
    frame.attrs["units"] = dict(_TABLE_UNITS[name])
    return frame


def _sizes_table(sizes):
    """The JSON's ``sizes`` (docs/output.md) as a table of its bins
    (``result.sizes.table``): one row
    per diameter bin, ``diameter`` (geometric centre), ``lower``, ``upper``
    (edges, m), ``density`` (number density n(D), 1/m) and ``cumulative``
    (number fraction below ``upper``); the moments, counts and status in
    ``attrs`` (``status``, ``reason``, ``dispersed_phase``, ``median``,
    ``d10``, ``d20``, ``d30``, ``d32``, ``d32_chords``, ``d32_flux`` in m,
    ``chords_used``, ``chords_by_velocity``). No rows without a distribution
    (``attrs["status"]`` says why)."""
    bins = sizes.get("bins") or {"edges": [], "diameters": [], "density": [], "cumulative": []}
    edges, cumulative = bins["edges"], bins["cumulative"]
    columns = {"diameter": list(bins["diameters"]), "lower": list(edges[:-1]), "upper": list(edges[1:]),
               "density": list(bins["density"]), "cumulative": list(cumulative[1:])}
    units = {"diameter": "m", "lower": "m", "upper": "m", "density": "1/m", "cumulative": "-"}
    attrs = {k: v for k, v in sizes.items() if k != "bins"}
    try:
        import pandas
    except ImportError:
        import numpy
        out = Result((k, numpy.asarray(v, dtype=float)) for k, v in columns.items())
        out["attrs"] = {**attrs, "units": units}
        return out
    frame = pandas.DataFrame(columns, columns=list(columns))
    frame.attrs.update(attrs)
    frame.attrs["units"] = units
    return frame


class Recording:
    """Channels read from a file: ``data`` (samples x channels, float32,
    volts when ``info.volts_known``), ``fs`` (Hz) and ``info`` (format,
    channel names, warnings, ...)."""

    def __init__(self, data, fs, info):
        self.data, self.fs, self.info = data, fs, _wrap(info)

    @property
    def channels(self):
        """The channels as a list of 1-D arrays (views of ``data``)."""
        return [self.data[:, k] for k in range(self.data.shape[1])]

    def __repr__(self):
        return (f"Recording({self.info.file!r}, {self.data.shape[1]} channels x {self.data.shape[0]} samples, "
                f"fs={self.fs:g} Hz, {self.info.format})")


# --- options -----------------------------------------------------------------

_OPTIONS = _pdp.options()
_NAMES = {o["name"] for o in _OPTIONS if o["group"] not in ("scene", "flow")}
# A profile's flow quantities (awcc/profile_flow.hpp): discharge, invert, depth_levels, flow_draws, flow_seed.
_FLOW_NAMES = {o["name"] for o in _OPTIONS if o["group"] == "flow"}


def options(group=None):
    """Every option with its group, name, unit, help and default (the
    declarations the command line reads); only ``group``'s when given
    ("probe and methods", "input", "binarisation", "fscc", "awcc",
    "structure", "event detection", "multi-tip", "flow", "scene")."""
    return [Result(o) for o in _OPTIONS if group is None or o["group"] == group]


def profile_columns(result=None):
    """The profile CSV's columns as the libraries declare them: ``name``,
    ``unit`` ("" for text, "-" when dimensionless), ``pointer`` (RFC 6901:
    where the same value is in a recording's result; "" for the version,
    which is in the provenance), ``meaning`` and ``values`` (the texts an
    enum or on/off column may hold; empty for numbers and free text; read it
    as ``c["values"]``). Without ``result``: every column, the correction's
    last. With a result of pdp.process or pdp.correct (a profile, one
    recording, or their JSON as a dict): the columns its CSV has, the
    correction's only when it holds a correction."""
    if result is None:
        corrected = True
    elif isinstance(result, dict):
        rows = result["profile"] if isinstance(result.get("profile"), list) else [result]
        corrected = any(isinstance(r, dict) and r.get("correction") is not None for r in rows)
    else:
        raise TypeError(f"profile_columns(result): result is of type {type(result).__name__}; give what pdp.process or "
                        "pdp.correct returned (or a process JSON loaded as a dict), or nothing for every column")
    return [Result(c) for c in _pdp.profile_columns(corrected)]


_UNITS = {o["name"]: o["unit"] for o in _OPTIONS if o["group"] != "scene"}


def _flow_settings(options):
    """Splits keyword options into the flow's (as (declared name, text)
    pairs) and the rest (a dict), by the declarations' group "flow"."""
    flow, rest = [], {}
    for key, value in options.items():
        name = key.replace("_", "-")
        if name in _FLOW_NAMES:
            if value is not None:
                flow.append((name, _text(value, _UNITS[name])))
        else:
            rest[key] = value
    return flow, rest


def _refuse_flow(settings, why):
    """The flow's options given where there is no profile's flow: refused,
    naming the first (as pdp process refuses them)."""
    name = settings[0][0]
    err = OptionError(f"{name}: a profile's flow quantities need two or more recordings with their positions"
                      f"{': ' + why if why else ' (positions=[...], m)'} (keyword {name.replace('-', '_')})")
    err.quantity = name
    raise err


def _text(value, unit=""):
    """An option's value as a user types it; a number gets its SI unit (the
    library refuses a quantity without one); a list of points (tips) is
    written x,y,z;x,y,z."""
    if isinstance(value, bool) or isinstance(value, _np.bool_):
        return "on" if value else "off"
    suffix = "" if unit in ("", "-", "bytes") else unit
    if isinstance(value, (int, _np.integer)):
        return f"{int(value)}{suffix}"
    if isinstance(value, (float, _np.floating)):
        return f"{float(value)!r}{suffix}"
    if isinstance(value, (list, tuple, _np.ndarray)):
        if any(isinstance(v, (list, tuple, _np.ndarray)) for v in value):
            return ";".join(_text(v, unit) for v in value)
        return ",".join(_text(v, unit) for v in value)
    if isinstance(value, (str, _os.PathLike)):
        return _os.fspath(value)
    raise OptionError(f"a value of type {type(value).__name__} ({value!r}) cannot be an option; give a number, "
                      "a string with its unit, True/False or a list")


def _settings(kwargs):
    """Keyword options as (declared name, text) pairs: filter_a -> filter-a."""
    out = []
    for key, value in kwargs.items():
        if value is None:
            continue
        name = key.replace("_", "-")
        if name not in _NAMES:
            close = sorted(n for n in _NAMES if n.split("-")[0] == name.split("-")[0])
            hint = f"; did you mean {', '.join(n.replace('-', '_') for n in close)}?" if close else ""
            err = OptionError(f"'{key}' is not an option{hint} (pdp.options() lists them)")
            err.quantity = name
            raise err
        out.append((name, _text(value, _UNITS[name])))
    return out


# The most tips of a probe a 2-D array is read as (samples x channels): a
# wider array with at most this many rows is refused as transposed.
_MOST_TIPS = 16


def _channels(lead, trail):
    """The signals as 1-D arrays: a Recording, a 2-D array (samples x
    channels), or one array per tip."""
    if isinstance(lead, Recording):
        return lead.channels, lead.fs
    a = _np.asarray(lead)
    if trail is None:
        if a.ndim == 2:
            # Samples x channels; a probe has a few tips and a record many
            # samples, so a wide array is a transposed one.
            if a.shape[1] > a.shape[0] and a.shape[0] <= _MOST_TIPS:
                err = OptionError(f"an array of shape {a.shape}: pdp takes samples x channels, so this would be "
                                  f"{a.shape[1]} channels of {a.shape[0]} samples; give its transpose "
                                  f"(array.T, shape {a.shape[::-1]})")
                err.quantity = "channels"
                raise err
            return [a[:, k] for k in range(a.shape[1])], None
        return [a], None
    return [a, _np.asarray(trail)], None


def _rate(fs, recorded):
    if fs is None and recorded is None:
        err = OptionError("the sampling rate is needed: give fs=... (Hz)")
        err.quantity = "fs"
        raise err
    return float(recorded if fs is None else fs)


def _arrays(lead, trail, fs, volts_per_count, kwargs, preset=""):
    channels, recorded = _channels(lead, trail)
    return _pdp.process_arrays(channels, _rate(fs, recorded), volts_per_count, _settings(kwargs), preset or "")


def _call_text(name, args, kwargs):
    shown = [repr(a) if isinstance(a, (str, _os.PathLike, list)) else "<array>" for a in args]
    shown += [f"{k}={v!r}" for k, v in kwargs.items() if v is not None]
    return f"python {_sys.version.split()[0]}: pdp.{name}({', '.join(shown)})"


# --- the functions -------------------------------------------------------------


def read(path, **options):
    """Reads a recording: every format ``pdp process`` reads (WAV/FLAC/W64/RF64,
    UQ .dat, raw, CSV/LabVIEW .lvm, NI TDMS, HDF5, MATLAB .mat), detected by
    content and extension. Returns a Recording: ``data`` samples x channels
    (float32 volts, or counts when ``info.volts_known`` is False), ``fs``
    (Hz), ``info``. The whole file is held in memory."""
    data, fs, info = _pdp.read(_os.fspath(path), _settings(options))
    return Recording(data, fs, info)


def binarise(volts, fs=None, *, output="intervals", volts_per_count=None, **options):
    """Binarises a tip's signal (1-D array) or the two tips of a Recording or
    2-D array (samples x channels; ``leading_channel``/``trailing_channel``
    choose them). ``output="intervals"`` gives the air intervals as an
    (n, 2) int64 array of [start, end) samples; ``output="binary"`` a 0/1
    uint8 array. Float samples are volts; integer samples counts
    (``volts_per_count`` makes them volts). Returns a Result with
    ``threshold`` (rule, levels, value) and ``intervals`` or ``binary``; for
    two tips, ``leading`` and ``trailing`` such Results."""
    if output not in ("intervals", "binary"):
        raise OptionError(f"output={output!r}: give 'intervals' or 'binary'")
    channels, recorded = _channels(volts, None)
    single = len(channels) == 1
    if single:
        channels = channels * 2  # the library binarises a pair of tips
    b = _pdp.binarise(channels, _rate(fs, recorded), volts_per_count, _settings(options))

    def tip(t):
        r = Result(threshold=_wrap(t["threshold"]))
        if output == "intervals":
            r["intervals"] = t["intervals"]
        else:
            dense = _np.zeros(b["sample_count"], dtype=_np.uint8)
            for start, end in t["intervals"]:
                dense[start:end] = 1
            r["binary"] = dense
        r["fs"], r["sample_count"] = b["fs"], b["sample_count"]
        return r

    if single:
        return tip(b["leading"])
    return Result(leading=tip(b["leading"]), trailing=tip(b["trailing"]), fs=b["fs"], sample_count=b["sample_count"])


def phase_statistics(lead, trail=None, fs=None, *, volts_per_count=None, **options):
    """Void fraction, bubble count rate, chord times and their 95 % intervals
    of each tip: the ``tips`` of the process JSON (a list of Results; one
    for a single 1-D signal)."""
    channels, recorded = _channels(lead, trail)
    single = len(channels) == 1
    r, _, _ = _pdp.process_arrays(channels * 2 if single else channels, _rate(fs, recorded), volts_per_count,
                               _settings({**options, "method": "none"}), "")
    tips = _wrap(r["tips"])
    return tips[:1] if single else tips


def fscc(lead, trail=None, fs=None, dx=None, *, volts_per_count=None, **options):
    """Full-signal cross-correlation of the leading and trailing tips: the
    ``fscc`` object of the process JSON (velocity, lag, r12_max, T05,
    correlation scales, status and reason). ``dx`` is the streamwise tip
    separation (m, or a string with its unit)."""
    r, _, _ = _arrays(lead, trail, fs, volts_per_count, {**options, "dx": dx, "method": "fscc"})
    return _wrap(r["fscc"])


def awcc(lead, trail=None, fs=None, dx=None, np=None, *, volts_per_count=None, **options):
    """Adaptive window cross-correlation of the leading and trailing tips
    (``np`` particles per window): the ``awcc`` object of the process JSON
    (velocity, turbulence intensity and their intervals, quality, status)
    with ``windows``, the per-window table as a dict of arrays (a pandas
    DataFrame when pandas is importable)."""
    r, windows, _ = _arrays(lead, trail, fs, volts_per_count, {**options, "dx": dx, "np": np, "method": "awcc"})
    out = _wrap(r["awcc"])
    out.windows = _table(windows)
    return out


def process(source, trail=None, *, fs=None, preset=None, correct=None, positions=None, volts_per_count=None,
            **options):
    """Processes a recording as ``pdp process --json`` does and returns the
    same JSON as a Result: ``source`` is a file path (the result is the
    file's JSON object, with ``provenance``), a list of paths (a profile:
    ``{"profile": [...], "provenance": ...}``, ``positions`` in m one per
    file), a Recording, a 2-D array samples x channels, or the leading tip's
    array with ``trail`` the trailing tip's. ``correct`` names a correction
    model (.qrf) that adds each result's ``correction`` (bias-corrected
    quantiles of u and Tu). For a single recording, ``result.windows`` is the
    AWCC window table, ``result.correlation`` R11 and R12 (``lag`` in s,
    ``r11``, ``r12``; NaN outside a function's lags) and ``result.spectrum``
    Welch's PSD of AWCC's velocity series (``frequency`` Hz, ``density``
    (m/s)^2/Hz, ``resolvable_frequency``), or None. Bubble by bubble (the
    tables ``pdp process --bubbles`` writes, one row per leading bubble, NaN
    where a bubble has no value, the fate of each): ``result.bubbles`` is
    event detection's table when it ran (``method="events"``; the JSON's
    ``events``), ``result.vectors`` the multi-tip vector table when the probe
    was processed bubble by bubble (``method="multi-tip"``, or ``"auto"``
    with four or more tips; the JSON's ``multi_tip``), else None. A probe's
    tips: ``tips=[[0, 0, 0], [5e-3, 0, 0], ...]`` (m) or the command line's
    text. A profile is a Profile: each position ``result.profile[i]`` has
    them, and ``result.to_dataframe()`` is the profile CSV's table. With a
    position for every file, ``result.flow`` is the profile as a flow (a
    Flow: Y90, C_mean, d, power law, discharges, both air-concentration
    fits, 95 % intervals), with the corrected velocities when ``correct`` is
    given; its options are the flow group's (``discharge="0.2m2/s"``,
    ``invert``, ``depth_levels``, ``flow_draws``, ``flow_seed``).
    ``result.sizes`` is the JSON's size distribution (status, moments,
    counts) and ``result.sizes.table`` its bins as a table, the moments in
    its ``attrs`` (on a recording and on each position of a profile)."""
    call = _call_text("process", [source], {**options, "fs": fs, "preset": preset, "correct": correct})
    flow_settings, options = _flow_settings(options)
    profile = isinstance(source, (list, tuple)) and len(source) >= 2 and positions is not None
    if flow_settings and not profile:
        _refuse_flow(flow_settings, "")
    if profile and len(positions) == len(source):
        why = _pdp.repeated_position([float(y) for y in positions],
                                     [_os.path.basename(_os.fspath(p)) for p in source])
        if why:
            err = OptionError(f"positions: {why} (keyword positions)")
            err.quantity = "positions"
            raise err
    settings = _settings({**options, "fs": fs} if isinstance(source, (str, _os.PathLike, list, tuple)) else options)
    flow = None
    if isinstance(source, (str, _os.PathLike, list, tuple)):
        # Files: the library's profile run (study/profile_run.hpp), as pdp process runs it.
        paths = [_os.fspath(source)] if isinstance(source, (str, _os.PathLike)) else [_os.fspath(p) for p in source]
        if positions is not None and len(positions) != len(paths):
            raise OptionError(f"{len(positions)} positions for {len(paths)} files; give one per file")
        at = [] if positions is None or not isinstance(source, (list, tuple)) else [float(y) for y in positions]
        out, windows, details, warnings, flow_json, flow_report, inputs = _pdp.process_profile(
            paths, at, settings, preset or "", "" if correct is None else _os.fspath(correct), flow_settings,
            isinstance(source, (list, tuple)))
        _issue(warnings)
        if profile and flow_json is not None:
            flow = _wrap(flow_json, "flow")
            flow._report = flow_report
    else:
        out, windows, detail = _arrays(source, trail, fs, volts_per_count, options, preset)
        inputs = []
        if correct is not None:
            out, warnings = _pdp.correct(_json.dumps(out), _os.fspath(correct), None, None, None)
            _issue(warnings)
    out["provenance"] = _pdp.provenance(inputs, settings, preset or "", call)
    result = _wrap(out)
    if flow is not None:
        result["flow"] = flow
    if "profile" in out:
        for row, row_windows, row_detail in zip(result.profile, windows, details):
            row.__dict__.update(_detail(row_windows, row_detail))
    elif isinstance(source, (str, _os.PathLike, list, tuple)):
        result.__dict__.update(_detail(windows[0], details[0]))
    else:
        result.__dict__.update(_detail(windows, detail))
    return result


def _issue(warnings):
    """Issues the compiled core's warnings as Python warnings."""
    import warnings as _warnings
    for w in warnings:
        _warnings.warn(w, stacklevel=3)


def _detail(windows, detail):
    """A recording's detail (_DETAIL) from the compiled core's answer."""
    detail = detail or {}
    return {"windows": _table(windows), "correlation": detail.get("correlation"),
            "spectrum": detail.get("spectrum"), "bubbles": _table(detail.get("bubbles"), "bubbles"),
            "vectors": _table(detail.get("vectors"), "vectors")}


def synth(scene=None, *, signal="binary", **fields):
    """Synthesises a scene with the synthetic probe (the fields of ``pdp synth``,
    from a dict and/or keywords: ``pdp.synth(duration=10, fs=100e3,
    mean_velocity=2.0)``). Returns a Result: ``signals`` samples x tips
    (uint8 0/1 for ``signal="binary"``; float32 volts for ``"voltage"``, with
    the int16 ``counts`` and ``volts_per_count``), ``fs``, ``scene`` and
    ``truth`` (the sidecar's objects) and ``generator_version`` (the version
    of the seeded streams: a seed gives the same numbers within a version)."""
    merged = dict(scene or {})
    merged.update(fields)
    s = _pdp.synthesise(_settings_scene(merged), signal)
    out = _wrap({"fs": s["fs"], "scene": s["scene"], "truth": s["truth"], "volts_per_count": s["volts_per_count"],
                 "generator_version": s["generator_version"]})
    if signal == "voltage":
        out["counts"] = s["signals"]
        out["signals"] = (s["signals"] * s["volts_per_count"]).astype(_np.float32)
    else:
        out["signals"] = s["signals"]
    return out


_SCENE_UNITS = {o["name"]: o["unit"] for o in _OPTIONS if o["group"] == "scene"}


def _settings_scene(fields):
    names = _SCENE_UNITS
    out = []
    for key, value in fields.items():
        name = key.replace("_", "-")
        if name not in names and key in names:
            name = key
        if name not in names:
            err = OptionError(f"'{key}' is not a scene field (pdp.options('scene') lists them)")
            err.quantity = key
            raise err
        if isinstance(value, (list, tuple)) and value and isinstance(value[0], (list, tuple)):
            value = ";".join(_text(v, _SCENE_UNITS[name]) for v in value)  # points: "x,y,z;x,y,z"
        out.append((name, _text(value, _SCENE_UNITS[name])))
    return out


def correct(results, model, *, dx=None, dy=None, np=None, **options):
    """Bias-corrects AWCC's velocity and turbulence intensity with a
    correction model (.qrf from ``pdp train``): ``results`` is what
    ``pdp.process`` returns (one recording or a profile) or a process JSON
    loaded as a dict. Returns the results with a ``correction`` object per
    recording (median and nine quantiles, 2.5-97.5 %, of u and Tu, or why not
    corrected), as ``pdp correct`` writes them, each recording's windows,
    correlation, spectrum, bubbles and vectors kept. ``dx``, ``dy`` (m) and ``np``
    fill values the results lack. A profile with every position gets its
    ``flow`` anew with the corrected velocities (the flow group's options, as
    ``pdp correct`` takes them: ``discharge="0.2m2/s"``, ...)."""
    flow_settings, unknown = _flow_settings(options)
    if unknown:
        _settings(unknown)  # refused by name
    results = {k: v for k, v in results.items() if k != "flow"} if isinstance(results, dict) else results
    out, warnings = _pdp.correct(_json.dumps(results), _os.fspath(model), dx, dy, np)
    for w in warnings:
        import warnings as _warnings
        _warnings.warn(w, stacklevel=2)
    answer = _pdp.profile_flow(_json.dumps(out), "results", flow_settings)
    if answer["flow"] is None and flow_settings:
        _refuse_flow(flow_settings, answer["why_none"])
    flow = _flow_of(answer)
    corrected = _wrap(out)
    if flow is not None:
        corrected["flow"] = flow
    # What pdp.process kept beside the JSON stays with its recording.
    before = results.get("profile", [results]) if isinstance(results, dict) else []
    after = corrected.profile if isinstance(corrected, Profile) else [corrected]
    for old, new in zip(before, after):
        new.__dict__.update({k: v for k, v in getattr(old, "__dict__", {}).items() if k in _DETAIL})
    return corrected


def flow(source, **options):
    """A profile's flow quantities (METHOD 12) from a profile read back:
    ``source`` is a profile JSON (``pdp process --json`` with positions, or
    ``pdp correct``'s), a profile CSV (``pdp process --csv``, corrected or
    not), or such a JSON loaded as a dict (what pdp.process returns). Each
    row's velocity is chosen as ``pdp process`` chooses it (the corrected
    AWCC median where the row is corrected). Options are the flow group's
    (``discharge="0.2m2/s"``, ``invert``, ``depth_levels``, ``flow_draws``,
    ``flow_seed``). Returns a Flow; raises InputError when the source is not
    a profile with every position."""
    settings, unknown = _flow_settings(options)
    if unknown:
        _settings(unknown)  # refused by name
    if isinstance(source, dict):
        text, name = _json.dumps({k: v for k, v in source.items() if k != "flow"}), "results"
    else:
        name = _os.fspath(source)
        with open(name, encoding="utf-8") as f:
            text = f.read()
    answer = _pdp.profile_flow(text, name, settings)
    if answer["flow"] is None:
        raise InputError(answer["why_none"])
    return _flow_of(answer)


# --- help from the declarations ------------------------------------------------

_GROUPS = {
    read: ["input"],
    binarise: ["binarisation"],
    phase_statistics: ["binarisation"],
    fscc: ["probe and methods", "binarisation", "fscc"],
    awcc: ["probe and methods", "binarisation", "awcc"],
    process: ["probe and methods", "input", "binarisation", "fscc", "awcc", "structure", "event detection",
              "multi-tip", "flow"],
    flow: ["flow"],
    synth: ["scene"],
}


def _options_doc(groups):
    lines = ["", "Options (keyword = value; unit; default):"]
    for group in groups:
        lines.append(f"  {group}:")
        for o in _OPTIONS:
            if o["group"] != group:
                continue
            unit = "" if o["unit"] in ("", "-") else f"; {o['unit']}"
            lines.append(f"    {o['name'].replace('-', '_')}{unit}; default {o['default']}")
            lines.append(f"        {o['help']}")
    return "\n".join(lines)


for _function, _groups in _GROUPS.items():
    _function.__doc__ = (_function.__doc__ or "") + "\n" + _options_doc(_groups)
del _function, _groups

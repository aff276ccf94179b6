"""The aggregation of pdp bench's rows (tools/plot_study.py): RMS, bias and
spread over seeds, the Pareto front and the per-scene decision, against
values worked by hand."""
import importlib.util
import math
import os

import pytest

_SPEC = importlib.util.spec_from_file_location(
    "plot_study", os.path.join(os.environ.get("PDP_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", "..")),
                               "tools", "plot_study.py"))
plot_study = importlib.util.module_from_spec(_SPEC)
_SPEC.loader.exec_module(plot_study)


def row(method, duration, seconds, u_err, tu_err, seed, np_=10, fs=500000, scene="base"):
    return {"scene": scene, "seed": str(seed), "method": method, "np": str(np_), "fs": str(fs),
            "duration": str(duration), "seconds": str(seconds),
            "velocity_error": "" if u_err is None else str(u_err),
            "turbulence_intensity_error": "" if tu_err is None else str(tu_err)}


def test_rms_bias_and_spread_over_seeds():
    rows = [row("awcc-intervals", 60, t, e, -0.2, k) for k, (t, e) in enumerate([(0.1, 0.03), (0.3, 0.05), (0.2, 0.07)])]
    (s,) = plot_study.bench_summary(rows)
    assert s["cost"] == pytest.approx(0.2)  # the median
    assert s["velocity_bias"] == pytest.approx(0.05)
    assert s["velocity_spread"] == pytest.approx(0.02)  # sd of 0.03, 0.05, 0.07 with n - 1
    assert s["velocity_rms"] == pytest.approx(math.sqrt((0.03**2 + 0.05**2 + 0.07**2) / 3))
    # RMS^2 = bias^2 + spread^2 (n - 1) / n
    assert s["velocity_rms"] ** 2 == pytest.approx(0.05**2 + 0.02**2 * 2 / 3)
    assert s["turbulence_intensity_spread"] == pytest.approx(0.0)


def test_pareto_front_and_decision():
    rows = []
    # (method, duration, cost, u error): B is beaten by A (dearer and worse), D by C.
    for method, duration, cost, e in [("fscc", 10, 0.01, 0.08), ("awcc-intervals", 10, 0.05, 0.09),
                                      ("fscc", 60, 0.06, 0.045), ("awcc-intervals", 60, 0.3, 0.05),
                                      ("awcc-intervals", 300, 1.5, 0.02)]:
        rows += [row(method, duration, cost, s * e, None, k) for k, s in enumerate((1, -1))]
    # A setting where one seed gave nothing: never on the front nor chosen.
    rows += [row("awcc-fft", 10, 0.001, 0.0, None, 0), row("awcc-fft", 10, 0.001, None, None, 1)]
    summary = plot_study.bench_summary(rows)
    front = plot_study.pareto_front(summary, "velocity")
    assert [(s["method"], s["duration"]) for s in front] == [("fscc", 10), ("fscc", 60), ("awcc-intervals", 300)]
    shortest, cheapest = plot_study.decision(summary, "velocity")
    assert (shortest["method"], shortest["duration"]) == ("fscc", 60)  # 0.045 <= 5 %, and 10 s reaches nothing
    assert (cheapest["method"], cheapest["duration"]) == ("fscc", 60)
    assert plot_study.decision(summary, "turbulence_intensity") is None  # no Tu at all
    assert "none reaches it" in plot_study.bench_table(summary, ["base"])

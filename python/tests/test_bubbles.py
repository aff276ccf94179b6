"""Bubble by bubble in Python (issue 30): ``result.bubbles`` (event
detection's table, method events) and ``result.vectors`` (the multi-tip
vector table), one row per leading bubble, checked against the JSON they
come with and against the binary signals they were computed from:

- the rows are the leading tip's bubbles, their times those of the air
  intervals (awcc/interface_times.hpp: front (start - 1/2) / fs, rear
  (stop - 1/2) / fs), computed here from the signal;
- event detection's fates are Kramer's pairing rules (awcc/event_detection.hpp
  items 1 and 3) re-implemented here by brute force, a paired bubble's
  velocity dx / centre lag exactly, the JSON's mean the weighted mean of the
  paired rows (an identity, so rounding only);
- the multi-tip table has a row per leading bubble, as many solved rows as
  the JSON's accepted bubbles, the JSON's mean vector their weighted mean;
- each position of a profile keeps its tables; None where the method did not run.
"""

import math

import numpy as np
import pandas
import pdp
import pytest

from conftest import made

DX = 5e-3
CLEAN_TIPS = [[0.0, 0.0, 0.0], [2e-3, 0.0, 0.0], [2e-3, 1e-3, 0.0], [2e-3, 0.0, 1e-3]]
# The clean four-tip scene of tests/cli/bubbles_cli_test.sh (METHOD 11.7:
# large spheres, weak turbulence, tips 2 mm apart), where the vectors are
# right and their quality ok; 20 s instead of 60.
CLEAN = dict(velocity="2m/s", tu=0.05, tu_y=0.025, tu_z=0.025, time_scale="1s", void_fraction=0.05,
             bubble_diameter="8mm", tips=CLEAN_TIPS, fs="200kHz", duration="20s", seed=11)


def crossings(binary, fs):
    """(front, rear, censored) of each air interval of a 0/1 signal, as
    awcc::crossings times them."""
    edges = np.diff(np.concatenate([[0], binary.astype(np.int8), [0]]))
    start, stop = np.flatnonzero(edges == 1), np.flatnonzero(edges == -1)
    period = 1.0 / fs
    front = (start.astype(float) - 0.5) * period
    rear = (stop.astype(float) - 0.5) * period
    return front, rear, (start <= 0) | (stop >= len(binary))


def kramer_fates(lead, trail, fs, disparity_max=0.5):
    """Kramer et al. 2020's pairing by brute force (no shared index): each
    leading bubble's candidate is the first trailing bubble whose centre is
    strictly later; fates before the outlier cutoff."""
    f0, r0, c0 = crossings(lead, fs)
    f1, r1, c1 = crossings(trail, fs)
    centre0, centre1 = 0.5 * (f0 + r0), 0.5 * (f1 + r1)
    fates = []
    for h in range(len(f0)):
        later = np.flatnonzero(centre1 > centre0[h])
        if c0[h]:
            fates.append("censored")
            continue
        if not len(later):
            fates.append("no_partner")
            continue
        j = later[0]
        if c1[j]:
            fates.append("censored")
            continue
        lag = 0.5 * ((f1[j] - f0[h]) + (r1[j] - r0[h]))
        to_next = centre0[h + 1] - centre0[h] if h + 1 < len(f0) else math.inf
        dt0, dt1 = r0[h] - f0[h], r1[j] - f1[j]
        if not lag < to_next:
            fates.append("beyond_next")
        elif not abs(dt0 - dt1) / dt0 < disparity_max:
            fates.append("disparity")
        else:
            fates.append("paired")
    return fates


@pytest.fixture(scope="module")
def two_tip():
    s = pdp.synth(velocity="2m/s", void_fraction=0.1, dx=DX, fs="100kHz", duration="10s", seed=5)
    return s, pdp.process(s.signals, fs=s.fs, dx=DX, method="events")


def test_event_bubbles_are_the_leading_bubbles_with_kramers_fates(two_tip):
    s, r = two_tip
    b, e = r.bubbles, r.events
    assert isinstance(b, pandas.DataFrame) and b.attrs["units"]["velocity"] == "m/s"
    assert e.status == "ok" and e.pairing == "kramer"
    lead, trail = s.signals[:, 0], s.signals[:, 1]
    front, rear, _ = crossings(lead, s.fs)
    assert len(b) == e.bubbles_total == len(front)
    assert np.array_equal(b["leading_front"], front) and np.array_equal(b["leading_rear"], rear)
    # The table's fates, and the JSON's counts of them.
    assert {f: int((b["fate"] == f).sum()) for f in e.bubbles_by_fate} == e.bubbles_by_fate
    assert int((b["fate"] == "paired").sum()) == e.bubbles_paired > 300
    # The cutoff rejects among the paired: before it, brute force gives the same fates.
    before = np.where(b["fate"] == "roc", "paired", b["fate"])
    assert list(before) == kramer_fates(lead, trail, s.fs)


def test_event_velocities_are_dx_over_the_centre_lag(two_tip):
    _, r = two_tip
    b, e = r.bubbles, r.events
    lag = b["centre_lag"].to_numpy()
    has = lag > 0  # NaN (no candidate) compares false
    assert np.array_equal(b["velocity"][has], r.dx / lag[has])  # exactly: the same division
    assert b["velocity"][~has].isna().all()
    assert np.array_equal(lag[has], 0.5 * (b["front_lag"][has] + b["rear_lag"][has]))
    paired = b[b["fate"] == "paired"]
    # The mean over the paired bubbles, weighted by each one's interaction time span.
    w, u = paired["weight"].to_numpy(), paired["velocity"].to_numpy()
    assert e.velocity == pytest.approx((w * u).sum() / w.sum(), rel=1e-12)
    # Chord lengths at each bubble's own velocity; d32 = 1.5 mean chord.
    chord = (paired["leading_rear"] - paired["leading_front"]) * paired["velocity"]
    assert np.allclose(paired["chord_length"], chord, rtol=1e-12, atol=0)
    assert e.sauter_diameter == pytest.approx(1.5 * paired["chord_length"].mean(), rel=1e-12)
    # Without event detection: no table.
    assert r.vectors is None
    plain = pdp.process(two_tip[0].signals, fs=two_tip[0].fs, dx=DX)
    assert plain.bubbles is None and plain.vectors is None and "events" not in plain


def check_vectors(r, leading, fs):
    v, m = r.vectors, r.multi_tip
    assert isinstance(v, pandas.DataFrame) and v.attrs["units"]["diameter_front"] == "m"
    front, _, _ = crossings(leading, fs)
    assert len(v) == m.bubbles_total == len(front)
    assert np.array_equal(v["time"], front)
    solved = v[v["fate"] == "solved"]
    assert len(solved) == m.bubbles_accepted > 100
    assert {f: int((v["fate"] == f).sum()) for f in m.bubbles_by_fate} == m.bubbles_by_fate
    # Rows without a vector have none; solved rows all have one.
    assert v.loc[v["fate"].isin(["too_few_tips", "censored"]), "velocity_x"].isna().all()
    assert solved[["velocity_x", "velocity_y", "velocity_z", "speed", "diameter_front"]].notna().all().all()
    speed = np.sqrt(solved["velocity_x"] ** 2 + solved["velocity_y"] ** 2 + solved["velocity_z"] ** 2)
    assert np.allclose(solved["speed"], speed, rtol=1e-12, atol=0)
    # The JSON's statistics are the solved rows': weighted mean vector, number-mean diameter.
    w = solved["weight"].to_numpy()
    for k, axis in enumerate("xyz"):
        mean = (w * solved[f"velocity_{axis}"]).sum() / w.sum()
        assert m.velocity[k] == pytest.approx(mean, rel=1e-10, abs=1e-12), axis
    assert m.diameter_front == pytest.approx(solved["diameter_front"].mean(), rel=1e-10)


def test_a_four_tip_recording_gives_one_vector_row_per_leading_bubble(tmp_path):
    s = pdp.synth(**CLEAN)
    r = pdp.process(s.signals, fs=s.fs, tips=CLEAN_TIPS)  # method auto: multi-tip for four tips
    assert r.multi_tip.status == "ok" and r.multi_tip.quality == "ok", r.multi_tip.quality_reason
    check_vectors(r, s.signals[:, 0], s.fs)
    assert r.bubbles is None
    # The fluid moves at 2 m/s along x: the solved bubbles' median u_x near it.
    assert np.median(r.vectors.loc[r.vectors["fate"] == "solved", "velocity_x"]) == pytest.approx(2.0, rel=0.05)
    # The same scene as pdp synth's .h5, whose tips the file states: the same table.
    made("synth", "-q", "--velocity", "2m/s", "--tu", "0.05", "--tu-y", "0.025", "--tu-z", "0.025", "--time-scale",
         "1s", "--void-fraction", "0.05", "--bubble-diameter", "8mm", "--tips",
         "0mm,0mm,0mm;2mm,0mm,0mm;2mm,1mm,0mm;2mm,0mm,1mm", "--fs", "200kHz", "--duration", "20s", "--seed", "11",
         "-o", tmp_path / "clean.h5")
    f = pdp.process(tmp_path / "clean.h5")
    pandas.testing.assert_frame_equal(f.vectors, r.vectors)
    # Both methods asked: both tables, each as its method alone gives it.
    both = pdp.process(s.signals, fs=s.fs, tips=CLEAN_TIPS, method="multi-tip+events")
    pandas.testing.assert_frame_equal(both.vectors, r.vectors)
    assert len(both.bubbles) == both.events.bubbles_total == r.multi_tip.bubbles_total


def test_each_position_of_a_profile_keeps_its_tables(tmp_path):
    files = []
    for i, seed in enumerate((3, 4)):
        files.append(tmp_path / f"two{i}.flac")
        made("synth", "-q", "--velocity", "2m/s", "--dx", "5mm", "--duration", "5s", "--fs", "50kHz", "--seed",
             str(seed), "-o", files[-1])
    p = pdp.process(files, dx="5mm", method="events", positions=[0.01, 0.02])
    for row, f in zip(p.profile, files):
        alone = pdp.process(f, dx="5mm", method="events")
        pandas.testing.assert_frame_equal(row.bubbles, alone.bubbles)
        assert int((row.bubbles["fate"] == "paired").sum()) == row.events.bubbles_paired
        assert row.vectors is None
    with pytest.raises(AttributeError, match=r"profile\[i\]\.bubbles"):
        p.bubbles

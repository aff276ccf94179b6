"""The size distribution in Python (issue 31): ``result.sizes`` is the
JSON's ``sizes`` and ``result.sizes.table`` its bins as a table, on a
recording and on each position of a profile (kept through pdp.correct),
checked against the JSON it comes from:

- one row per bin, its diameters and densities the JSON's arrays, ``lower``
  and ``upper`` the consecutive edges, ``cumulative`` the number fraction
  below ``upper`` (ending at 1);
- the number density integrates to 1 over the bins (n(D) ~ 1 / D^2 within a
  bin, so the integral of bin j is the step of the cumulative: an identity
  of the model, checked here to 1e-9);
- the moments in ``attrs`` are the JSON's;
- a position without a distribution has no rows and its status.
"""

import math

import pdp
import pytest

from conftest import DATA

# Log-normal spheres (tests/awcc/position_sizes_test.cpp's scene, 20 s).
SCENE = dict(velocity="5m/s", tu=0.05, tu_y=0.025, tu_z=0.025, time_scale="1s", void_fraction=0.1,
             bubble_diameter="2mm", diameter_log_sd=0.3, dy="0mm", fs="100kHz", duration="20s", seed=31)


def test_sizes_table_is_the_json_bins_with_its_moments():
    s = pdp.synth(**SCENE)
    r = pdp.process(s["signals"], fs=s["fs"], dx=5e-3)
    j, t = r["sizes"], r.sizes.table
    assert r.sizes is r["sizes"]
    assert j["status"] == "ok", j["reason"]
    bins = j["bins"]
    assert len(t) == len(bins["diameters"])
    assert list(t["diameter"]) == bins["diameters"]
    assert list(t["lower"]) == bins["edges"][:-1]
    assert list(t["upper"]) == bins["edges"][1:]
    assert list(t["cumulative"]) == bins["cumulative"][1:]
    assert t["cumulative"].iloc[-1] == 1.0
    # Within a bin n(D) = k / D^2 with n(centre) = density: its integral is
    # k (1 / lower - 1 / upper), the cumulative's step.
    for row, before in zip(t.itertuples(), [0.0] + list(t["cumulative"][:-1])):
        step = row.density * row.diameter ** 2 * (1.0 / row.lower - 1.0 / row.upper)
        assert math.isclose(step, row.cumulative - before, rel_tol=1e-9, abs_tol=1e-15)
    for key in ("median", "d10", "d20", "d30", "d32", "d32_chords", "d32_flux", "status", "chords_by_velocity"):
        assert t.attrs[key] == j[key]
    assert t.attrs["units"]["diameter"] == "m"
    assert 0.9 < t.attrs["median"] / 2e-3 < 1.1


def test_each_position_of_a_profile_has_its_sizes():
    if not DATA.is_dir():
        pytest.skip(f"{DATA} is absent")
    files = sorted(DATA.glob("dc157_*.dat"))[-2:]
    p = pdp.process([str(f) for f in files], fs=20e3, dx=7.15e-3, positions=[0.05, 0.054])
    for row in p.profile:
        # 20 kHz: the median bubble spans about one sample, no distribution.
        assert row.sizes.table.attrs["status"] == row.sizes.status == "coarse_sampling"
        assert len(row.sizes.table) == 0
        assert row["interfacial_area"]["source"] == "dual_tip"
    with pytest.raises(AttributeError):
        p.sizes

"""A result's one list of warnings (issue 29): ``r.warnings`` (texts) and
``r.flags`` (codes, one per text), as pdp process writes them; the codes are
the library's (``pdp._pdp.flags()``)."""

import pdp
from pdp import _pdp

from conftest import DATA


def test_flag_codes_are_the_librarys_with_meanings():
    flags = _pdp.flags()
    codes = [f["code"] for f in flags]
    assert "methods_disagree" in codes and "integral_scale_short" in codes and "channels_ignored" in codes
    assert len(set(codes)) == len(codes)
    assert all(f["meaning"] for f in flags)
    column = next(c for c in pdp.profile_columns() if c["name"] == "flags")
    assert sorted(column["values"]) == sorted(codes)
    assert "sampling intervals" in _pdp.sampling_intervals_only and "bias" in _pdp.sampling_intervals_only


def test_the_8mm_row_carries_its_flag_and_warning(real_files):
    r = pdp.process(DATA / "dc157_02.dat", fs="20kHz", dx="7.15mm")
    assert r.flags == ["methods_disagree"]
    assert len(r.warnings) == 1 and "AWCC 33 % below FSCC" in r.warnings[0]
    assert r.fscc.velocity_ci95[0] < r.fscc.velocity < r.fscc.velocity_ci95[1]
    quiet = pdp.process(DATA / "dc157_05.dat", fs="20kHz", dx="7.15mm")
    assert quiet.flags == [] and quiet.warnings == []

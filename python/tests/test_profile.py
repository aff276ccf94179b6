"""A profile in Python (issue 29, case 9): pdp.Profile.to_dataframe() equals
the profile CSV the command line writes, cell for cell; profile_columns takes
the result whose columns it lists; each position keeps its AWCC windows,
R11/R12 and spectrum; every name dir() lists on a result is gettable; the
docs/guide/python.md's profile example runs. pandas is imported unconditionally: scripts/setup
installs it, and a machine without it fails here rather than skipping."""

import csv
import math
import os

import numpy as np
import pandas
import pdp
import pytest

from conftest import DATA, MODEL, SOURCE, made

POSITIONS = [0.002, 0.008, 0.014, 0.020, 0.026, 0.032, 0.038, 0.044, 0.050, 0.054]  # m


@pytest.fixture(scope="module")
def corrected(real_files):
    return pdp.process(real_files, fs=20e3, dx="7.15mm", positions=POSITIONS, correct=MODEL)


def cli_csv(real_files, folder, *more):
    positions = ",".join(f"{1e3 * y:g}mm" for y in POSITIONS[:len(real_files)])
    made("process", *real_files, "--fs", "20kHz", "--dx", "7.15mm", "--positions", positions, *more,
        "--csv", folder / "profile.csv")
    with open(folder / "profile.csv", newline="") as f:
        return list(csv.reader(f))


def same_cell(value, text, name):
    """A DataFrame cell (the JSON's value) against the CSV's text, by the
    writer's rules (awcc/serialise.hpp: on/off or 1/0 for true/false, lists
    joined by "; ", a file by its name, an undefined value empty)."""
    if value is None or (isinstance(value, float) and math.isnan(value)) or (isinstance(value, list) and not value):
        return text == ""
    if isinstance(value, (bool, np.bool_)):
        return {"on": True, "off": False, "1": True, "0": False}.get(text) == bool(value)
    if isinstance(value, (int, float, np.integer, np.floating)):
        return text != "" and float(text) == pytest.approx(float(value), rel=1e-9, abs=1e-300)
    if isinstance(value, list):
        return text == "; ".join(value)
    if name == "file":
        return text == os.path.basename(value)
    return text == value


def check_frame_equals_csv(frame, table):
    header, body = table[0], table[1:]
    assert list(frame.columns) == header
    assert len(frame) == len(body)
    for i, line in enumerate(body):
        for name, text in zip(header, line):
            value = frame[name].iloc[i]
            assert same_cell(value, text, name), (i, name, value, text)


def test_to_dataframe_is_the_cli_profile_csv_cell_for_cell(corrected, real_files, tmp_path):
    frame = corrected.to_dataframe()
    check_frame_equals_csv(frame, cli_csv(real_files, tmp_path, "--correct", MODEL))
    columns = pdp.profile_columns(corrected)
    assert frame.attrs["units"] == {c["name"]: c["unit"] for c in columns}
    assert frame.attrs["units"]["awcc_velocity"] == "m/s" and frame.attrs["units"]["position"] == "m"
    assert list(frame["position"]) == POSITIONS
    # The one number the issue quotes: the 2 mm row's FSCC velocity, 2.80 m/s (Felder's program too).
    assert frame["fscc_velocity"].iloc[0] == pytest.approx(2.80, abs=0.005)
    assert frame.dtypes["awcc_velocity"] == np.float64 and math.isnan(frame["awcc_velocity"].iloc[0])


def test_an_uncorrected_profile_has_the_uncorrected_csvs_columns(real_files, tmp_path):
    p = pdp.process(real_files[:3], fs=20e3, dx="7.15mm", positions=POSITIONS[:3])
    table = cli_csv(real_files[:3], tmp_path)
    assert [c["name"] for c in pdp.profile_columns(p)] == table[0]
    assert not any(name.startswith("correct") for name in table[0])


def test_profile_columns_takes_the_result_whose_columns_it_lists(corrected, real_files):
    every = [c["name"] for c in pdp.profile_columns()]
    assert [c["name"] for c in pdp.profile_columns(corrected)] == every  # a corrected profile has them all
    plain = pdp.process(real_files[0], fs=20e3, dx="7.15mm")
    names = [c["name"] for c in pdp.profile_columns(plain)]
    assert names == every[:len(names)] and "correction_status" not in names and "awcc_velocity" in names
    as_dict = {"profile": [dict(r) for r in corrected.profile]}  # a process JSON loaded by json.load
    assert [c["name"] for c in pdp.profile_columns(as_dict)] == every
    with pytest.raises(TypeError, match="result is of type int; give what pdp.process or pdp.correct returned"):
        pdp.profile_columns(3)


def test_each_position_keeps_its_windows_correlation_and_spectrum(corrected, real_files):
    """Each position's detail is the one pdp.process gives for its file alone,
    and its window table counts the JSON's windows."""
    for row, f in zip(corrected.profile, real_files):
        alone = pdp.process(f, fs=20e3, dx="7.15mm")
        assert isinstance(row.windows, pandas.DataFrame)
        pandas.testing.assert_frame_equal(row.windows, alone.windows)
        assert len(row.windows) == row.awcc.windows_total
        assert int((row.windows["fate"] == "accepted").sum()) == row.awcc.windows_accepted
        for key in ("lag", "r11", "r12"):
            np.testing.assert_array_equal(row.correlation[key], alone.correlation[key])
        assert (row.spectrum is None) == (alone.spectrum is None)
        if row.spectrum is not None:
            np.testing.assert_array_equal(row.spectrum["density"], alone.spectrum["density"])
    # The profile has none of its own, and says where they are.
    with pytest.raises(AttributeError, match=r"profile\[i\]\.windows"):
        corrected.windows
    # Correcting afterwards keeps them.
    again = pdp.correct(pdp.process(real_files[:2], fs=20e3, dx="7.15mm"), MODEL)
    assert isinstance(again, pdp.Profile) and again.profile[1].correction.status == "corrected"
    pandas.testing.assert_frame_equal(again.profile[1].windows, corrected.profile[1].windows)


# dict's own methods: a key of the same name is read with brackets (Result's doc says so).
DICT_METHODS = set(dir(dict))


def walk(obj, where, seen, collisions):
    """Gets every name dir(obj) lists, for pdp's own types, recursively
    through the Results a result holds; returns how many names it got."""
    if id(obj) in seen:
        return 0
    seen.add(id(obj))
    got = 0
    for name in dir(obj):
        value = getattr(obj, name)  # an AttributeError here is the bug this test is for
        got += 1
        if isinstance(obj, dict) and name in obj:
            if name in DICT_METHODS:
                collisions.add(name)
            else:
                assert value is obj[name], (where, name)
        if isinstance(value, (pdp.Result, pdp.Recording)) and not name.startswith("__"):
            got += walk(value, f"{where}.{name}", seen, collisions)
        elif isinstance(value, list) and not name.startswith("__"):
            for i, item in enumerate(value):
                if isinstance(item, (pdp.Result, pdp.Recording)):
                    got += walk(item, f"{where}.{name}[{i}]", seen, collisions)
    return got


def test_every_name_dir_lists_on_a_processed_profile_is_gettable(corrected, real_files):
    seen, collisions = set(), set()
    got = walk(corrected, "profile", seen, collisions)
    got += walk(pdp.process(real_files[3], fs=20e3, dx="7.15mm"), "recording", seen, collisions)
    got += walk(pdp.read(real_files[3], fs=20e3), "read", seen, collisions)
    for i, c in enumerate(pdp.profile_columns()):
        got += walk(c, f"profile_columns()[{i}]", seen, collisions)
    for i, o in enumerate(pdp.options()):
        got += walk(o, f"options()[{i}]", seen, collisions)
    for module in (pdp, pdp._pdp):
        for name in dir(module):
            getattr(module, name)
    assert got > 5000  # the walk reached every position's nested objects
    # The one key that is also a dict method: a column's "values" (read as c["values"]).
    assert collisions == {"values"}
    # What the issue tried: a position's windows.
    assert "windows" in dir(corrected.profile[0]) and corrected.profile[0].windows is not None
    assert "windows" not in dir(corrected)


def test_the_guide_profile_example_runs(real_files, capsys):
    """docs/guide/python.md's block after its test marker, run in the
    recordings' folder (scripts/check-docs leaves it to this test: it runs
    where the recordings are)."""
    text = (SOURCE / "docs" / "guide" / "python.md").read_text()
    marker = "<!-- python/tests/test_profile.py: the profile-to-DataFrame example -->\n```python no-check\n"
    assert text.count(marker) == 1
    block = text.split(marker)[1].split("```")[0]
    here = os.getcwd()
    os.chdir(DATA)
    try:
        names = {}
        exec(compile(block, "docs/guide/python.md", "exec"), names)
    finally:
        os.chdir(here)
    df, w = names["df"], names["w"]
    assert list(df["position"]) == POSITIONS and list(df["file"]) == [f.name for f in real_files]
    assert df["awcc_quality"].tolist()[-3:] == ["ok"] * 3
    assert int((w["fate"] == "accepted").sum()) == names["p"].profile[1].awcc.windows_accepted
    out = capsys.readouterr().out
    assert "awcc_quality" in out and "insufficient" in out

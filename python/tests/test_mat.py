"""pdp process --mat (issue 54, awcc/mat_output.hpp): the real profile's .mat
read by scipy.io.loadmat (Debian's python3-scipy), as a MATLAB user's load
would: every row's velocity, Tu, void fraction and bubble count rate equal to
the JSON's, bit for bit (both are the same doubles); the profile table's
columns with their units; one recording's windows as a table whose rows are
AWCC's windows; pdp correct's and pdp validate's --mat the same for their
JSON."""

import json

import numpy as np
import pytest

import os
import subprocess

from conftest import MODEL, made

sio = pytest.importorskip("scipy.io", reason="python3-scipy reads the .mat as MATLAB users' tools do")

POSITIONS = ",".join(f"{p}mm" for p in (2, 8, 14, 20, 26, 32, 38, 44, 50, 54))


def empty(x):
    return isinstance(x, np.ndarray) and x.size == 0


@pytest.mark.parametrize("version", ["5", "7.3"])
def test_the_real_profile_in_matlab_is_its_json(real_files, tmp_path, version):
    extra = ["--mat-v73"] if version == "7.3" else []
    made("process", *real_files, "--fs", "20kHz", "--dx", "7.15mm", "--positions", POSITIONS,
         "--json", tmp_path / "p.json", "--mat", tmp_path / "p.mat", *extra)
    j = json.loads((tmp_path / "p.json").read_text())
    if version == "7.3":
        h5py = pytest.importorskip("h5py", reason="scipy reads MATLAB 7.3 files only through h5py")
        with h5py.File(tmp_path / "p.mat") as f:
            assert "profile" in f and "profile_table" in f
        return
    m = sio.loadmat(tmp_path / "p.mat", squeeze_me=True, struct_as_record=False)
    rows = m["profile"]
    assert len(rows) == len(j["profile"]) == 10
    for row, jr in zip(rows, j["profile"]):
        assert row.tips[0].void_fraction == jr["tips"][0]["void_fraction"]
        assert row.tips[0].bubble_count_rate == jr["tips"][0]["bubble_count_rate"]
        assert row.fscc.velocity == jr["fscc"]["velocity"]
        for key in ("velocity", "turbulence_intensity"):
            expected = jr["awcc"][key]
            assert empty(getattr(row.awcc, key)) if expected is None else getattr(row.awcc, key) == expected
    table, units = m["profile_table"], m["profile_table_units"]
    assert list(table.file) == [p.name for p in real_files]
    assert units.awcc_velocity == "m/s" and units.void_fraction == "-"
    np.testing.assert_array_equal(table.position, [r["position"] for r in j["profile"]])


def test_one_recordings_windows_are_a_table(real_files, tmp_path):
    made("process", real_files[4], "--fs", "20kHz", "--dx", "7.15mm", "--mat", tmp_path / "r.mat",
         "--json", tmp_path / "r.json")
    j = json.loads((tmp_path / "r.json").read_text())
    m = sio.loadmat(tmp_path / "r.mat", squeeze_me=True, struct_as_record=False)
    w = m["windows"]
    assert len(w.velocity) == j["awcc"]["windows_total"]
    assert int(np.sum(w.fate == "accepted")) == j["awcc"]["windows_accepted"]
    assert m["windows_units"].velocity == "m/s"
    assert m["tips"][0].void_fraction == j["tips"][0]["void_fraction"]


def test_a_corrected_profile_in_matlab_is_its_json(real_files, tmp_path):
    made("process", *real_files, "--fs", "20kHz", "--dx", "7.15mm", "--positions", POSITIONS,
         "--json", tmp_path / "p.json", "--csv", tmp_path / "p.csv")
    made("correct", tmp_path / "p.json", "-m", MODEL, "-o", tmp_path / "c.json", "--mat", tmp_path / "c.mat")
    j = json.loads((tmp_path / "c.json").read_text())
    m = sio.loadmat(tmp_path / "c.mat", squeeze_me=True, struct_as_record=False)
    corrected = 0
    for row, jr in zip(m["profile"], j["profile"]):
        assert row.correction.status == jr["correction"]["status"]
        if jr["correction"]["velocity"] is None:
            continue
        corrected += 1
        median = jr["correction"]["velocity"]["median"]  # null on an untrusted row
        assert empty(row.correction.velocity.median) if median is None else row.correction.velocity.median == median
        # The quantile keys are no MATLAB names: "0.025" is x0_025.
        assert row.correction.velocity.quantiles.x0_025 == jr["correction"]["velocity"]["quantiles"]["0.025"]
    assert corrected >= 5
    assert m["flow"].status == j["flow"]["status"] and m["flow"].seed == j["flow"]["seed"]
    table = m["profile_table"]
    assert list(table.correction_status) == [r["correction"]["status"] for r in j["profile"]]
    assert list(table.correction_in_range) == [int(r["correction"]["in_range"]) for r in j["profile"]]
    medians = [r["correction"]["velocity"]["median"] if r["correction"]["velocity"] else None for r in j["profile"]]
    np.testing.assert_array_equal(table.corrected_velocity, [np.nan if x is None else x for x in medians])
    assert m["profile_table_units"].corrected_velocity == "m/s"
    # A CSV has no tree to write: refused, naming the fix, and no file left.
    cli = os.environ["PDP_CLI"]
    done = subprocess.run([cli, "correct", tmp_path / "p.csv", "-m", MODEL, "--mat", tmp_path / "q.mat"],
                          capture_output=True, text=True)
    assert done.returncode == 2 and "pdp process --json" in done.stderr
    assert not (tmp_path / "q.mat").exists()


def test_a_validation_in_matlab_is_its_json(tmp_path):
    made("validate", "--velocity", "2m/s", "--duration", "10s", "--json", tmp_path / "v.json",
         "--mat", tmp_path / "v.mat")
    j = json.loads((tmp_path / "v.json").read_text())
    m = sio.loadmat(tmp_path / "v.mat", squeeze_me=True, struct_as_record=False)
    assert set(j) <= set(k for k in m if not k.startswith("__"))
    assert m["awcc"].velocity == j["awcc"]["velocity"]
    assert m["truth"].velocity == j["truth"]["velocity"]

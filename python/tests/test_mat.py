"""pdp process --mat (issue 54, awcc/mat_output.hpp): the real profile's .mat
read by scipy.io.loadmat (Debian's python3-scipy), as a MATLAB user's load
would: every row's velocity, Tu, void fraction and bubble count rate equal to
the JSON's, bit for bit (both are the same doubles); the profile table's
columns with their units; one recording's windows as a table whose rows are
AWCC's windows."""

import json

import numpy as np
import pytest

from conftest import made

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

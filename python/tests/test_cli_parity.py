"""pdp.process gives the JSON `pdp process --json` writes: the same dict,
value for value, on the ten real recordings, on a synthetic recording, with
the bias correction, and for a profile."""

import pdp
import pytest

from conftest import MODEL, load, without_provenance


def test_each_real_recording_equals_the_cli(cli, real_files, scratch):
    for f in real_files:
        out = scratch / (f.stem + ".json")
        cli("process", f, "--fs", "20kHz", "--dx", "7.15mm", "--json", out)
        r = pdp.process(f, fs="20kHz", dx="7.15mm")
        assert without_provenance(r) == without_provenance(load(out)), f.name


def test_the_window_table_holds_the_windows_csv(cli, real_files, scratch):
    import csv

    f = real_files[6]
    out = scratch / "windows.csv"
    cli("process", f, "--fs", "20kHz", "--dx", "7.15mm", "--windows", out)
    with open(out) as fh:
        rows = list(csv.DictReader(fh))
    w = pdp.process(f, fs="20kHz", dx="7.15mm").windows
    assert list(w) == list(rows[0])
    assert len(w["velocity"]) == len(rows) > 100
    for i in (0, len(rows) // 2, len(rows) - 1):
        assert w["fate"][i] == rows[i]["fate"]
        for name in ("start_time", "velocity", "lag", "measured_velocity"):
            assert float(rows[i][name]) == pytest.approx(w[name][i], rel=1e-8, abs=1e-12)


def test_felder_preset_and_raw_correlation_equal_the_cli(cli, real_files, scratch):
    f = real_files[2]
    out = scratch / "felder.json"
    cli("process", f, "--fs", "20kHz", "--dx", "7.15mm", "--preset", "felder", "--json", out)
    r = pdp.process(f, fs=20e3, dx=7.15e-3, preset="felder")
    assert without_provenance(r) == without_provenance(load(out))
    assert r.fscc.signal == "raw"


def test_a_profile_with_positions_and_the_correction_equals_the_cli(cli, real_files, scratch):
    out = scratch / "profile.json"
    positions = [0.002 + 0.006 * i for i in range(len(real_files))]
    cli("process", *real_files, "--fs", "20kHz", "--dx", "7.15mm", "--positions",
        ",".join(f"{p!r}m" for p in positions), "--correct", MODEL, "--json", out)
    r = pdp.process(real_files, fs=20e3, dx=7.15e-3, positions=positions, correct=MODEL)
    expected = load(out)
    assert len(r.profile) == len(expected["profile"]) == len(real_files)
    for got, want in zip(r.profile, expected["profile"]):
        assert got == want, got["file"]
    # Every row but file 01 is corrected by the shipped model's AWCC forest;
    # file 01 (2 accepted windows) by its FSCC forest, with one mode since
    # issue 33 (two modes, untrusted, before: docs/validation.md).
    assert [row.correction.status for row in r.profile] == ["corrected"] * 10
    assert [row.correction.forest for row in r.profile] == ["fscc"] + ["awcc"] * 9


def test_a_synthetic_recording_equals_the_cli_and_its_arrays(cli, scratch):
    flac = scratch / "scene.flac"
    cli("synth", "-o", flac, "--velocity", "2m/s", "--void-fraction", "0.1", "--duration", "4s", "--fs", "100kHz",
        "--seed", "7", "-q")
    out = scratch / "scene.json"
    cli("process", flac, "--dx", "5mm", "--json", out)
    from_file = pdp.process(flac, dx="5mm")
    assert without_provenance(from_file) == without_provenance(load(out))
    # The same scene synthesised in memory: the same samples, so the same
    # void fraction, count rate and velocities (the threshold's scale differs:
    # the file's counts are 1/32768, the array's 1).
    s = pdp.synth(velocity="2m/s", void_fraction=0.1, duration=4, fs=100e3, seed=7)
    from_arrays = pdp.process(s.signals, fs=s.fs, dx=0.005)
    for a, b in zip(from_arrays.tips, from_file.tips):
        assert a.void_fraction == b.void_fraction
        assert a.bubble_count_rate == b.bubble_count_rate
    assert from_arrays.awcc.velocity == from_file.awcc.velocity
    assert from_arrays.fscc.velocity == from_file.fscc.velocity
    # And the truth is the sidecar's.
    sidecar = load(scratch / "scene.truth.json")
    assert s.truth["realised"] == sidecar["realised"]


def test_an_hdf5_recording_written_by_pdp_synth_equals_the_cli(cli, scratch):
    h5 = scratch / "scene.h5"
    cli("synth", "-o", h5, "--velocity", "2m/s", "--void-fraction", "0.1", "--duration", "2s", "--fs", "100kHz",
        "--seed", "3", "-q")
    out = scratch / "h5.json"
    cli("process", h5, "--dx", "5mm", "--json", out)
    r = pdp.process(h5, dx=0.005)
    assert without_provenance(r) == without_provenance(load(out))
    assert "pdp-sim" in r["format"]
    rec = pdp.read(h5)
    assert rec.data.shape == (200_000, 2) and rec.fs == 100e3

"""A profile as a flow in Python (issue 31): pdp.process(..., positions=...)
gives ``.flow``, the same object the command line writes as the profile
JSON's ``flow``; pdp.flow reads a profile JSON or CSV back to the same
quantities (the JSON exactly, the CSV to its 10 printed digits); a fitted
curve passes through (Y90, 0.9) by construction; options refused name
themselves."""

import json
import math

import numpy as np
import pandas
import pdp
import pytest

from conftest import MODEL, load, made

# The top row of the square waves (c 0.96) has no velocity, and says so each time.
pytestmark = pytest.mark.filterwarnings("ignore:r12.csv. no velocity")

# c_i = 0.08 i at y_i = 5 i mm, i = 1..12 (tests/cli/flow_cli_test.sh): exact
# square waves, Y90 = 56.25 mm between the rows of c 0.88 and 0.96.
POSITIONS = [0.005 * i for i in range(1, 13)]


@pytest.fixture(scope="module")
def square_waves(tmp_path_factory):
    d = tmp_path_factory.mktemp("flow")
    fs, n, period, lag = 10000, 20000, 100, 5
    files = []
    for i in range(1, 13):
        air = 8 * i
        lead = [1 if (k % period) < air else 0 for k in range(n)]
        trail = lead[-lag:] + lead[:-lag]
        path = d / f"r{i:02d}.csv"
        with open(path, "w") as f:
            f.write("time,lead,trail\n")
            f.writelines(f"{k / fs:.5f},{lead[k]},{trail[k]}\n" for k in range(n))
        files.append(path)
    return files


def cli_profile(files, positions, folder, *more):
    text = ",".join(f"{y!r}m" for y in positions)  # the same doubles as the Python call
    made("process", *files, "--positions", text, *more, "--json", folder / "p.json", "--csv", folder / "p.csv")
    return load(folder / "p.json")


def plain(value):
    return json.loads(json.dumps(value))


def test_flow_is_the_cli_flow_and_reads_back(square_waves, tmp_path):
    p = pdp.process(square_waves, dx="5mm", positions=POSITIONS, discharge="150l/s/m", flow_seed=3)
    cli = cli_profile(square_waves, POSITIONS, tmp_path, "--dx", "5mm", "--discharge", "150l/s/m", "--flow-seed", "3")
    assert plain(p.flow) == cli["flow"]
    assert p.flow.y90.value == pytest.approx(0.05625, abs=1e-12)
    assert isinstance(p.flow, pdp.Flow) and p.flow.discharge == pytest.approx(0.15, rel=1e-15)
    # Read back: the JSON's rows are the doubles written, the flow identical.
    assert plain(pdp.flow(tmp_path / "p.json", discharge="150l/s/m", flow_seed=3)) == cli["flow"]
    assert plain(pdp.flow(p, discharge="150l/s/m", flow_seed=3)) == cli["flow"]
    # The CSV's 10 significant digits move each row by a relative 5e-10 at
    # most; the flow's numbers follow within 1e-7 (correction/profile_rows_test).
    from_csv = plain(pdp.flow(tmp_path / "p.csv", discharge="150l/s/m", flow_seed=3))

    def same(a, b, at):
        if isinstance(b, dict):
            assert a.keys() == b.keys(), at
            for k in b:
                same(a[k], b[k], f"{at}/{k}")
        elif isinstance(b, list):
            assert len(a) == len(b), at
            for i, (x, y) in enumerate(zip(a, b)):
                same(x, y, f"{at}/{i}")
        elif isinstance(b, float):
            assert a == pytest.approx(b, rel=1e-7, abs=1e-300), at
        elif "notes" not in at:
            assert a == b, at

    same(from_csv, cli["flow"], "flow")


def test_a_fitted_curve_passes_through_y90_at_0_9(square_waves):
    f = pdp.process(square_waves, dx="5mm", positions=POSITIONS, flow_draws=200).flow
    y90 = f.y90.value
    for fit in (f.smooth_chute, f.stepped_chute):
        assert fit.value is not None and fit.residual is not None, fit
        assert fit.curve(y90) == pytest.approx(0.9, abs=1e-12)
        y = np.array([[0.01, 0.02], [0.03, y90]])
        c = fit.curve(y)
        assert c.shape == y.shape and c[1, 1] == pytest.approx(0.9, abs=1e-12)
        assert np.all(np.diff(c.ravel()) > 0)  # c grows towards the surface
        # The curve's residual is the rms over the rows up to Y90 it was fitted to.
        rows = [r for r in f.rows if 0 < r.position <= y90]
        rms = math.sqrt(np.mean([(r.void_fraction - fit.curve(r.position)) ** 2 for r in rows]))
        assert fit.points == len(rows) and rms == pytest.approx(fit.residual, rel=1e-9)


def test_the_object_table_and_report(square_waves):
    p = pdp.process(square_waves, dx="5mm", positions=POSITIONS, flow_draws=200, depth_levels="0.5")
    f = p.flow
    frame = f.to_dataframe()
    assert list(frame["quantity"]) == ["Y90", "Y50", "C_mean", "d", "N", "u90", "q_w", "q_a", "continuity_error",
                                       "D'", "D_0", "H_res"]
    y90 = frame.set_index("quantity").loc["Y90"]
    assert y90["value"] == f.y90.value and y90["ci95_lower"] == f.y90.ci95[0] and y90["unit"] == "m"
    assert frame.attrs["units"]["q_w"] == "m2/s"
    # Equal velocities everywhere: no power law, and the table says why.
    n = frame.set_index("quantity").loc["N"]
    assert math.isnan(n["value"]) and "does not grow" in n["reason"]
    assert f.status == "incomplete" and f.message and "no N" in f.message
    assert "Y90 = 56.25 mm" in f.report()
    # The top row (c 0.96) gives neither method a velocity: none, and a note says so.
    # Uncorrected, each row's velocity is the one its chord lengths use.
    expected = [e.chord_velocity_source for e in p.profile[:11]] + [None]
    assert [r.velocity_source for r in f.rows] == expected, f.rows
    assert set(expected[:11]) <= {"awcc", "fscc"} and p.profile[11].chord_velocity_source == "none"
    assert any(note == "r12.csv: no velocity (neither AWCC nor FSCC gave one)" for note in f.notes)
    assert any(note.startswith("velocity of each row") for note in f.notes)


def test_refused_options_name_themselves(square_waves, tmp_path):
    files = square_waves[:3]
    with pytest.raises(pdp.OptionError) as e:
        pdp.process(files, dx="5mm", positions=POSITIONS[:3], discharge="0.2")
    assert e.value.quantity == "discharge" and "discharge" in str(e.value)
    with pytest.raises(pdp.OptionError) as e:
        pdp.process(files, dx="5mm", positions=POSITIONS[:3], invert="below")
    assert e.value.quantity == "invert" and "invert" in str(e.value)
    with pytest.raises(pdp.OptionError) as e:
        pdp.process(files[0], dx="5mm", discharge="0.2m2/s")
    assert e.value.quantity == "discharge" and "two or more recordings with their positions" in str(e.value)
    with pytest.raises(pdp.OptionError) as e:
        pdp.process(files[:2], dx="5mm", positions=[0.005, 0.005])
    assert e.value.quantity == "positions" and "given twice (r01.csv and r02.csv)" in str(e.value)
    p = pdp.process(files, dx="5mm", positions=POSITIONS[:3])
    with pytest.raises(pdp.OptionError) as e:
        pdp.flow(p, flow_draws=5)
    assert e.value.quantity == "flow-draws" and "flow_draws" in str(e.value)
    with pytest.raises(pdp.OptionError) as e:
        pdp.flow(p, discharges="0.2m2/s")
    assert e.value.quantity == "discharges"
    # No positions: no flow, and the attribute says how to get one.
    with pytest.raises(AttributeError, match="positions"):
        pdp.process(files, dx="5mm").flow


def test_a_corrected_profile_flows_with_its_corrected_velocities(real_files, tmp_path):
    files, positions = real_files[3:7], [0.020, 0.026, 0.032, 0.038]
    p = pdp.process(files, fs=20e3, dx="7.15mm", positions=positions, correct=MODEL, flow_draws=400)
    cli = cli_profile(files, positions, tmp_path, "--fs", "20kHz", "--dx", "7.15mm", "--correct", MODEL,
                      "--flow-draws", "400")
    assert plain(p.flow) == cli["flow"]
    sources = {r.velocity_source for r in p.flow.rows}
    assert "corrected awcc" in sources, sources
    # pdp.correct of the uncorrected profile gives the same flow.
    q = pdp.process(files, fs=20e3, dx="7.15mm", positions=positions)
    assert plain(pdp.correct(q, MODEL, flow_draws=400).flow) == cli["flow"]

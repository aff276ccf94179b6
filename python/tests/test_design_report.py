"""pdp design's page (python/pdp/design_report.py) from small ranked CSVs
written here: a 2 x 2 grid of geometries with the current probe and a failed
candidate, a list of probes that is not a grid, a current probe off the grid;
the page is self-contained, names the recommended geometry, marks the current
probe, has one map per condition and quantity with blank cells where a
candidate has no value; bad input, a bad --config and an unwritable output
get the documented exit status and no page. The module is loaded from the
source tree: it needs no compiled core."""

import csv
import html.parser
import importlib.util
import os
import subprocess
import sys

import pytest

from conftest import SOURCE

SCRIPT = SOURCE / "python" / "pdp" / "design_report.py"
HEADER = ("rank,objective,ranking,values,failures,current,dx,dy,np,fs,duration,needle,seconds_awcc,condition,records,"
          "condition_failures,score,u_bias,u_spread,u_rms,tu_bias,tu_spread,tu_rms,raw_u_bias,raw_u_spread,"
          "raw_u_rms,raw_tu_bias,raw_tu_spread,raw_tu_rms,corrected_fraction,data_yield")
QUANTITIES = ["u_rms", "tu_rms", "raw_u_bias", "raw_tu_bias"]
DESIGN = """[design]
seeds = 3
[conditions.base]
velocity = "10m/s"
tu = 0.25
[conditions.wall]
velocity = ["2m/s", "4m/s"]
void-fraction = [0.02, 0.1, "log"]
[candidates]
dx = ["2mm", "5mm"]
dy = ["0mm", "1mm"]
np = [10]
[current]
dx = "5mm"
dy = "1mm"
np = 10
fs = "100kHz"
duration = "20s"
"""


@pytest.fixture(scope="module")
def report():
    spec = importlib.util.spec_from_file_location("design_report_under_test", SCRIPT)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def candidate(rank, dx_mm, dy_mm, np_=10, current=False, failed=False, objective=None, needle_mm=0):
    """One candidate: errors grow with its rank; a failed one has no value anywhere."""
    return {"rank": rank, "dx": dx_mm / 1e3, "dy": dy_mm / 1e3, "np": np_, "current": current, "failed": failed,
            "objective": objective, "needle": needle_mm / 1e3}


def write_ranked(path, candidates, conditions=("base", "wall"), needle_column=True, ranking="worst-case",
                 values_ranked="corrected"):
    """A ranked CSV as pdp design writes it (without the needle column: as it did before needles)."""
    lines = [HEADER if needle_column else HEADER.replace(",needle,", ",")]
    for c in candidates:
        e = 0.02 * c["rank"]
        scores = [2 * e * (1 + 0.5 * k) for k in range(len(conditions))]
        objective = "inf" if c["failed"] else repr(c["objective"] or max(scores))
        for k, name in enumerate(conditions):
            if c["failed"]:
                values = [""] * 12 + ["0", "0.01"]
                failures, score = 3, ""
            else:
                u, t = e, e * (1 + k)
                values = [u, 0.1 * u, u, t, 0.1 * t, t, 1.5 * u, 0.1 * u, 1.5 * u, -1.5 * t, 0.1 * t, 1.5 * t, 1, 0.8]
                values = [repr(round(v, 6)) for v in values]
                failures, score = 0, repr(round(u + t, 6))
                values.insert(0, score)
            if c["failed"]:
                values.insert(0, score)
            lines.append(",".join(map(str, [c["rank"], objective, ranking, values_ranked,
                                            3 * len(conditions) if c["failed"] else 0,
                                            int(c["current"]), c["dx"], c["dy"], c["np"], 100000, 20]
                                           + ([c["needle"]] if needle_column else [])
                                           + [0.012, name, 3, failures] + values)))
    path.write_text("\n".join(lines) + "\n")
    return path


GRID = [candidate(1, 2, 0), candidate(2, 5, 0), candidate(3, 5, 1, current=True), candidate(4, 2, 1, failed=True)]


class Page(html.parser.HTMLParser):
    """Figures, table rows, links, ids and references, and the text of elements with an id."""

    def __init__(self, text):
        super().__init__()
        self.text = text
        self.maps, self.figures, self.links, self.ids, self.references, self.rows = [], [], [], [], [], []
        self.svg_ids = set()
        self.texts, self._open = {}, []
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "figure":
            self.figures.append(a.get("data-figure"))
            if a.get("data-figure") == "map":
                self.maps.append(a)
        if tag == "tr" and "data-rank" in a:
            self.rows.append((int(a["data-rank"]), a.get("class", "")))
        for name in ("src", "href", "xlink:href"):
            if name in a:
                self.links.append((tag, a[name]))
        if "id" in a:
            self.ids.append(a["id"])
            if tag == "g":
                self.svg_ids.add(a["id"])
            else:
                self._open.append([a["id"], tag, ""])
        for name, target in a.items():
            if name in ("href", "xlink:href") and target.startswith("#"):
                self.references.append(target[1:])
            if target and "url(#" in target:
                self.references.extend(t.split(")")[0] for t in target.split("url(#")[1:])

    def handle_endtag(self, tag):
        if self._open and self._open[-1][1] == tag:
            name, _, text = self._open.pop()
            self.texts[name] = " ".join(text.split())

    def handle_data(self, data):
        for entry in self._open:
            entry[2] += data


def page_of(report, tmp_path, candidates, conditions=("base", "wall"), design=DESIGN, extra=(), needle_column=True):
    ranked = write_ranked(tmp_path / "ranked.csv", candidates, conditions, needle_column)
    args = [str(ranked), "-o", str(tmp_path / "design.html"), *extra]
    if design is not None:
        (tmp_path / "design.toml").write_text(design)
        args += ["--config", str(tmp_path / "design.toml")]
    assert report.main(args) == 0
    return Page((tmp_path / "design.html").read_text())


def check_self_contained(page):
    for tag, target in page.links:
        assert target.startswith("#") or target.startswith("data:"), (tag, target)
    assert "<script src" not in page.text and "<link" not in page.text and "@import" not in page.text
    assert "url(http" not in page.text and "<img" not in page.text
    assert len(page.ids) == len(set(page.ids)), "duplicate ids"
    assert set(page.references) <= set(page.ids), set(page.references) - set(page.ids)


def test_a_grid_with_the_current_probe_and_a_failed_candidate(report, tmp_path):
    ranked = write_ranked(tmp_path / "ranked.csv", GRID)
    (tmp_path / "design.toml").write_text(DESIGN)
    before = {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in tmp_path.iterdir()}
    assert report.main([str(ranked), "--config", str(tmp_path / "design.toml"), "-o", str(tmp_path / "design.html")]) \
        == 0
    page = Page((tmp_path / "design.html").read_text())
    check_self_contained(page)
    # Inputs untouched, nothing left beside the page.
    assert {p.name: (p.read_bytes(), p.stat().st_mtime_ns) for p in tmp_path.iterdir() if p.name != "design.html"} \
        == before
    assert sorted(p.name for p in tmp_path.iterdir()) == ["design.html", "design.toml", "ranked.csv"]
    # The recommendation and the comparisons.
    assert "dx 2 mm, dy 0 mm, Np 10, 100 kHz, 20 s" in page.texts["recommended"]
    assert "objective 6.0 %" in page.texts["recommended"]
    assert "rank 3 of 4" in page.texts["versus-current"] and "dx 5 mm, dy 1 mm" in page.texts["versus-current"]
    assert "3.0x the recommended error" in page.texts["versus-current"]
    assert "rank 4 of 4" in page.texts["versus-worst"] and "not comparable" in page.texts["versus-worst"]
    # One map per condition and quantity, each a 2 x 2 grid; the failed candidate's cell blank.
    assert [(m["data-condition"], m["data-quantity"]) for m in page.maps] == [
        (c, q) for c in ("base", "wall") for q in QUANTITIES]
    assert all(m["data-layout"] == "grid" and m["data-cells"] == "4" and m["data-blank"] == "1" for m in page.maps)
    for ci in range(2):
        for qi in range(4):
            salt = f"m{ci}-{qi}"
            # dx 2 mm is column 0, dy 1 mm row 1; the marks of the recommended and current geometries.
            assert {f"{salt}-blank-0-1", f"{salt}-recommended", f"{salt}-current"} <= page.svg_ids
            assert not any(i.startswith(f"{salt}-blank-") and i != f"{salt}-blank-0-1" for i in page.svg_ids)
    assert "objective" not in page.figures  # one Np: no objective per Np
    # The conditions described from the design file; the ranking marks the probes.
    assert "velocity 2m/s to 4m/s, void-fraction 0.02 to 0.1 (log-uniform)" in page.text
    assert page.rows[:1] == [(1, "recommended")] and (3, "current") in page.rows
    assert [r for r, _ in page.rows] == [1, 2, 3, 4]
    assert page.text.count(">no value<") >= 3  # the failed candidate's objective and scores
    # Provenance: the design file and the CSV with their SHA-256.
    import hashlib
    for name in ("design.toml", "ranked.csv"):
        assert hashlib.sha256((tmp_path / name).read_bytes()).hexdigest() in page.texts["design-provenance"]
    assert ranked.exists()


@pytest.mark.parametrize("ranking, values_ranked", [("mean", "raw"), ("worst-case", "corrected")])
def test_the_ranking_is_the_files_not_a_guess(report, tmp_path, ranking, values_ranked):
    # The objectives are the worst scores and the values differ from raw AWCC's: numbers that would have been
    # read as a worst-case ranking of corrected values; the page says what the file declares.
    ranked = write_ranked(tmp_path / "ranked.csv", GRID, ranking=ranking, values_ranked=values_ranked)
    assert report.main([str(ranked), "-o", str(tmp_path / "design.html")]) == 0
    text = (tmp_path / "design.html").read_text()
    assert ("mean over the conditions" in text) == (ranking == "mean")
    assert ("worst condition" in text) == (ranking == "worst-case")
    assert ("raw AWCC values" in text) == (values_ranked == "raw")


def test_a_probe_list_that_is_not_a_grid_is_a_scatter(report, tmp_path):
    probes = [candidate(1, 7.15, 0), candidate(2, 2, 0), candidate(3, 5, 1, current=True),
              candidate(4, 3, 0.5, failed=True)]
    page = page_of(report, tmp_path, probes, conditions=("base",), design=None, needle_column=False)
    check_self_contained(page)
    assert "dx 7.15 mm, dy 0 mm, Np 10, 100 kHz, 20 s;" in page.texts["recommended"]
    assert [m["data-quantity"] for m in page.maps] == QUANTITIES
    assert all(m["data-layout"] == "scatter" and m["data-blank"] == "1" for m in page.maps)
    assert {"m0-0-recommended", "m0-0-current", "m0-0-blank-1"} <= page.svg_ids  # probes sorted: (3, 0.5) second
    assert "not a grid" in page.text
    assert "not given" in page.texts["design-provenance"]


def test_a_current_probe_off_the_grid_and_several_np(report, tmp_path):
    cands = [candidate(1, 2, 0, np_=5), candidate(2, 5, 0, np_=5), candidate(3, 2, 0, np_=10),
             candidate(4, 5, 1, np_=5), candidate(5, 2, 1, np_=5), candidate(6, 7.15, 0.5, np_=10, current=True),
             candidate(7, 5, 0, np_=10), candidate(8, 5, 1, np_=10), candidate(9, 2, 1, np_=10),
             candidate(10, 7.15, 0.5, np_=5)]
    page = page_of(report, tmp_path, cands, conditions=("base",))
    check_self_contained(page)
    assert all(m["data-layout"] == "grid" and m["data-cells"] == "4" and m["data-blank"] == "0" for m in page.maps)
    assert "off the candidates' grid" in page.text and "current probe (7.15, 0.5) mm, off the grid" in page.text
    assert "objective" in page.figures
    assert "objective-np5-recommended" in page.svg_ids and not any("blank" in i for i in page.svg_ids)
    assert "settings-table" in page.ids


def test_needles_are_settings_of_their_own(report, tmp_path):
    cands = [candidate(1, 2, 0, needle_mm=0.8), candidate(2, 2, 0), candidate(3, 5, 0, needle_mm=0.8),
             candidate(4, 5, 0), candidate(5, 2, 1, needle_mm=0.8), candidate(6, 2, 1, current=True),
             candidate(7, 5, 1, needle_mm=0.8), candidate(8, 5, 1)]
    page = page_of(report, tmp_path, cands, conditions=("base",))
    assert "dx 2 mm, dy 0 mm, Np 10, 100 kHz, 20 s, needle 0.8 mm" in page.texts["recommended"]
    assert "needle (mm)" in page.texts["ranking-table"] and "needle (mm)" in page.texts["settings-table"]
    assert all(m["data-cells"] == "4" and m["data-blank"] == "0" for m in page.maps)
    assert "the current probe runs Np 10, 100 kHz, 20 s;" in page.text


def test_every_candidate_failed(report, tmp_path):
    cands = [candidate(1, 2, 0, failed=True), candidate(2, 5, 0, failed=True, current=True)]
    page = page_of(report, tmp_path, cands, conditions=("base",), design=None)
    assert "nothing-measured" in page.ids and "objective no value" in page.texts["recommended"]
    assert all(m["data-cells"] == m["data-blank"] == "2" for m in page.maps)


def test_top_15_the_current_probe_and_the_worst(report, tmp_path):
    cands = [candidate(r, 1 + (r - 1) % 5, 0.5 * ((r - 1) // 5), current=r == 18) for r in range(1, 21)]
    page = page_of(report, tmp_path, cands, conditions=("base",), design=None)
    assert [r for r, _ in page.rows] == list(range(1, 16)) + [18, 20]
    assert page.text.count('<tr class="gap">') == 2


def test_without_tomllib_the_design_file_is_named(report, tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "tomllib", None)  # as Python 3.10: import tomllib fails
    page = page_of(report, tmp_path, GRID[:2], conditions=("base",))
    assert "design.toml" in page.texts["design-provenance"] and "has no tomllib" in page.text


@pytest.mark.parametrize("change, message", [
    (lambda t: t.replace(",data_yield", ""), "column data_yield missing"),
    (lambda t: t.replace(",0.012,", ",fast,", 1), "not a number"),
    (lambda t: t.splitlines()[0] + "\n", "no candidate"),
    (lambda t: t.replace("\n2,", "\n1,", 1), "rank 1 is given to two candidates"),
    (lambda t: t.replace(",base,3,", ",base,2.5,", 1), "not a whole number"),
    (lambda t: t + "1,0.1,0\n", "cells"),
    (lambda t: t.replace(",worst-case,", ",worst,", 1), "line 2, column ranking: 'worst' is not one of worst-case, mean"),
    (lambda t: t.replace(",corrected,", ",median,", 1), "line 2, column values: 'median' is not one of corrected, raw"),
    (lambda t: t.replace(",worst-case,", ",mean,", 1), "line 3: ranked by worst-case of the corrected values, the rows "
                                                         "before by mean"),
    (lambda t: t.replace("objective,ranking,", "objective,", 1).replace(",worst-case,", ","),
     "column ranking missing"),
])
def test_a_bad_csv_is_bad_input_and_writes_nothing(report, tmp_path, capsys, change, message):
    ranked = write_ranked(tmp_path / "ranked.csv", GRID)
    ranked.write_text(change(ranked.read_text()))
    assert report.main([str(ranked), "-o", str(tmp_path / "design.html")]) == 1
    assert message in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ranked.csv"]


def test_usage_and_output_errors(report, tmp_path, capsys):
    ranked = write_ranked(tmp_path / "ranked.csv", GRID)
    out = str(tmp_path / "design.html")
    assert report.main([str(ranked), "-o", out, "--config", str(tmp_path / "absent.toml")]) == 2
    assert "absent.toml" in capsys.readouterr().err
    assert report.main([str(ranked)]) == 2  # no output
    assert report.main([str(ranked), "-o", str(ranked)]) == 2  # the output is the input
    assert report.main([str(ranked), "-o", out, "--no-such-option"]) == 2
    assert report.main([str(tmp_path / "absent.csv"), "-o", out]) == 1  # a missing input, as pdp report
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ranked.csv"]
    assert report.main([str(ranked), "-o", str(tmp_path / "no-folder" / "design.html")]) == 3
    assert "cannot write" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ranked.csv"]


def test_run_as_pdp_runs_it(tmp_path):
    """As pdp design --report runs it: a script with --command-line; a package missing is exit status 5."""
    ranked = write_ranked(tmp_path / "ranked.csv", GRID[:2], conditions=("base",))
    (tmp_path / "design.toml").write_text(DESIGN)
    line = "pdp design --config design.toml -o ranked.csv --report design.html"
    env = dict(os.environ, PYTHONPATH=str(SCRIPT.parent.parent))
    done = subprocess.run([sys.executable, str(SCRIPT), "--command-line", line, str(ranked), "--config",
                           str(tmp_path / "design.toml"), "-o", str(tmp_path / "design.html")], capture_output=True,
                          text=True, env=env)
    assert done.returncode == 0, done.stderr
    assert line in Page((tmp_path / "design.html").read_text()).texts["design-provenance"]
    (tmp_path / "shadow").mkdir()
    (tmp_path / "shadow" / "jinja2.py").write_text("raise ImportError('absent', name='jinja2')\n")
    env["PYTHONPATH"] = str(tmp_path / "shadow")
    done = subprocess.run([sys.executable, str(SCRIPT), str(ranked), "-o", str(tmp_path / "other.html")],
                          capture_output=True, text=True, env=env)
    assert done.returncode == 5 and "jinja2 is missing" in done.stderr and "python3-jinja2" in done.stderr
    assert not (tmp_path / "other.html").exists()


def test_pdp_design_report_end_to_end(tmp_path):
    """pdp design --report on a tiny design (one condition, two 3 s records, no model): the page of the CSV it
    ranked, with pdp's command line and version; the candidates AWCC refused are blank cells."""
    path = os.environ.get("PDP_CLI")
    if not path or not os.path.exists(path):
        pytest.skip("PDP_CLI is not set to the pdp command line (ctest sets it)")
    (tmp_path / "tiny.toml").write_text("""[design]
seeds = 2
[conditions.base]
velocity = "3m/s"
tu = 0.2
time-scale = "20ms"
void-fraction = 0.1
bubble-diameter = "2mm"
[candidates]
dx = ["2mm", "5mm"]
dy = ["0mm", "1mm"]
np = [5, 10]
fs = ["50kHz"]
duration = ["3s"]
[current]
dx = "5mm"
dy = "1mm"
np = 10
fs = "50kHz"
duration = "3s"
""")
    done = subprocess.run([path, "--log-level", "error", "design", "--config", "tiny.toml", "-o", "tiny.csv",
                           "--threads", "1", "--report", "tiny.html"], capture_output=True, text=True, cwd=tmp_path)
    assert done.returncode == 0, done.stderr
    page = Page((tmp_path / "tiny.html").read_text())
    check_self_contained(page)
    first = next(csv.DictReader((tmp_path / "tiny.csv").read_text().splitlines()))
    assert f"dx {float(first['dx']) * 1e3:g} mm, dy {float(first['dy']) * 1e3:g} mm, Np {first['np']}" \
        in page.texts["recommended"]
    assert [(m["data-condition"], m["data-quantity"]) for m in page.maps] == [("base", q) for q in QUANTITIES]
    assert "design --config tiny.toml -o tiny.csv" in page.texts["design-provenance"]
    assert "not recorded" not in page.texts["design-provenance"]  # pdp's version, from the module beside it
    assert "objective" in page.figures and (8, "current") in page.rows

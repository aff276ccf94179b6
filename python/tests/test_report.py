"""pdp report: the page of the ten real recordings and of a synthetic profile
holds every figure and per-position panel, a table whose every cell equals
the JSON (and the profile CSV the command line wrote), every gap explained,
nothing fetched from outside; it renders in headless Chromium without a
console error; bad input gets the documented exit status and no page."""

import csv
import html.parser
import json
import os
import shutil
import subprocess

import pdp
import pytest
from pdp import plotting

from conftest import MODEL, SOURCE, load

POSITIONS_MM = [2, 8, 14, 20, 26, 32, 38, 44, 50, 54]


class Page(html.parser.HTMLParser):
    """What the tests read from a report: figures, panels, table cells, gap
    notes, every src/href, the text of each element with an id."""

    def __init__(self, text):
        super().__init__()
        self.figures, self.positions, self.gids, self.links, self.scripts = [], [], set(), [], []
        self.columns = {}  # column name -> {row index: (data-value, data-gap)}
        self.texts = {}  # column name -> {row index: the cell's visible text}
        self.ids, self._column, self._open_ids, self._cell = {}, None, [], None
        self.all_ids, self.references = [], []
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if "data-figure" in a:
            self.figures.append(a["data-figure"])
        if "data-position" in a:
            self.positions.append(int(a["data-position"]))
        if tag == "g" and "id" in a:
            self.gids.add(a["id"])
        for name in ("src", "href", "xlink:href"):
            if name in a:
                self.links.append((tag, a[name]))
        if tag == "script":
            self.scripts.append(a)
        if tag == "tr" and "data-column" in a:
            self._column = self.columns.setdefault(a["data-column"], {})
            self._column_name = a["data-column"]
        if tag == "td" and "data-row" in a and self._column is not None:
            self._column[int(a["data-row"])] = (json.loads(a["data-value"]), a.get("data-gap"))
            self._cell = (self._column_name, int(a["data-row"]))
            self.texts.setdefault(self._column_name, {})[int(a["data-row"])] = ""
        if "id" in a:
            self.all_ids.append(a["id"])
        for name, target in a.items():
            if name in ("href", "xlink:href") and target.startswith("#"):
                self.references.append(target[1:])
            if target and "url(#" in target:
                self.references.extend(t.split(")")[0] for t in target.split("url(#")[1:])
        if "id" in a and tag != "g":
            self._open_ids.append([a["id"], tag, ""])
            self.ids[a["id"]] = ""

    def handle_endtag(self, tag):
        if tag == "tr":
            self._column = None
        if tag == "td":
            self._cell = None
        if self._open_ids and self._open_ids[-1][1] == tag:
            name, _, text = self._open_ids.pop()
            self.ids[name] = text

    def handle_data(self, data):
        for entry in self._open_ids:
            entry[2] += data
        if self._cell:
            self.texts[self._cell[0]][self._cell[1]] += data


def run(*args, env=None, cwd=None):
    path = os.environ.get("PDP_CLI")
    if not path or not os.path.exists(path):
        pytest.skip("PDP_CLI is not set to the pdp command line (ctest sets it)")
    return subprocess.run([path, *map(str, args)], capture_output=True, text=True, env=env, cwd=cwd)


def made(*args, cwd=None):
    done = run(*args, cwd=cwd)
    assert done.returncode == 0, done.stderr
    return done


@pytest.fixture(scope="module")
def real(tmp_path_factory, real_files):
    """The corrected ten-file profile: JSON, CSV and report (made by pdp process --report)."""
    d = tmp_path_factory.mktemp("real")
    positions = ",".join(f"{p}mm" for p in POSITIONS_MM)
    made("process", *real_files, "--fs", "20kHz", "--dx", "7.15mm", "--positions", positions, "--correct", MODEL,
         "--json", d / "profile.json", "--csv", d / "profile.csv", "--report", d / "report.html")
    return d


@pytest.fixture(scope="module")
def synthetic(tmp_path_factory):
    """A three-position synthetic profile: void fraction and velocity rising away from the bed."""
    d = tmp_path_factory.mktemp("synthetic")
    files = []
    for i, (c, u) in enumerate(((0.05, 1.5), (0.15, 2.0), (0.3, 2.5))):
        f = d / f"scene{i}.flac"
        made("synth", "-o", f, "--velocity", f"{u}m/s", "--void-fraction", str(c), "--duration", "6s", "--fs",
             "50kHz", "--seed", str(11 + i), "-q")
        files.append(f.name)
    made("process", *files, "--dx", "5mm", "--positions", "10mm,20mm,30mm", "--json", "profile.json", "--csv",
         "profile.csv", cwd=d)
    made("report", "profile.json", "-o", "report.html", cwd=d)
    return d


def page_of(folder):
    return Page((folder / "report.html").read_text())


def csv_rows(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def check_figures(page, rows, flow=False):
    """The profile figures (the bubble methods' where a row holds one, the
    flow's for a JSON with a flow object), then each position's panels."""
    assert page.figures == [key for key, _, _ in plotting.PROFILE_FIGURES] + \
        [key for key, _, _, method in plotting.BUBBLE_PROFILE_FIGURES
         if any(isinstance(r, dict) and r.get(method) is not None for r in rows)
         and (method != "sizes" or plotting.sizes_drawable([r for r in rows if isinstance(r, dict)]))] + \
        ([key for key, _, _ in plotting.FLOW_FIGURES] if flow else [])
    assert page.positions == list(range(len(rows)))
    for i in range(len(rows)):
        for key, _ in plotting.POSITION_PANELS:
            assert f"p{i}-{key}" in page.gids, (i, key)


def check_table(page, folder):
    """Every profile-CSV column is a table row; each cell holds the JSON's value
    at the column's pointer exactly, and the CSV's cell (10 significant digits)."""
    j = load(folder / "profile.json")
    rows, table = j["profile"], csv_rows(folder / "profile.csv")
    columns = pdp.profile_columns()
    assert list(page.columns) == [c["name"] for c in columns]
    names_in_csv = list(table[0])
    assert names_in_csv == [c["name"] for c in columns][:len(names_in_csv)]
    for c in columns:
        cells = page.columns[c["name"]]
        assert sorted(cells) == list(range(len(rows))), c["name"]
        for i, row in enumerate(rows):
            value, gap = cells[i]
            expected = j["provenance"]["pdp_version"] if c["name"] == "pdp_version" else pointer(row, c["pointer"])
            assert value == expected, (c["name"], i)
            if c["name"] not in table[i]:
                continue  # a correction column of an uncorrected profile
            text = table[i][c["name"]]
            if isinstance(value, bool):
                flags = {"on": True, "off": False, "true": True, "false": False, "1": True, "0": False}
                assert flags.get(text) is value, (c["name"], text)
            elif isinstance(value, (int, float)):
                assert float(text) == pytest.approx(value, rel=1e-9, abs=1e-300), (c["name"], i)
            elif value is None or value == []:
                assert text == "", (c["name"], i)
                if not (c["name"].endswith(("reason", "notes")) or c["name"] in ("warnings", "flags")):
                    assert gap, f"{c['name']} of row {i} is missing without a note saying why"
            elif isinstance(value, list):
                assert text == "; ".join(value)
            elif c["name"] == "file":  # the CSV names the file only; the JSON holds the path given
                assert text == os.path.basename(value)
            else:
                assert text == value, (c["name"], i)
    # Every gap's note exists and gives a reason, not a status.
    for cells in page.columns.values():
        for _, gap in cells.values():
            if gap:
                reason = page.ids.get(f"gap-{gap}", "")
                assert len(reason.strip()) > 10 and "status ok" not in reason, (gap, reason)
    # The visible numbers are the values, in mm and ms below 1 m and 1 s, to 4 digits.
    for c in columns:
        for i, (value, gap) in page.columns[c["name"]].items():
            text = page.texts[c["name"]][i].strip()
            if isinstance(value, bool) or not isinstance(value, (int, float)) or gap:
                continue
            shown = value
            if c["unit"] in ("m", "s") and value != 0 and abs(value) < 1:
                assert text.endswith(" m" + c["unit"]), (c["name"], text)
                text, shown = text[:-len(c["unit"]) - 2], 1e3 * value
            assert float(text) == pytest.approx(shown, rel=5e-4), (c["name"], i, text, value)


def pointer(obj, path):
    for token in path.split("/")[1:]:
        obj = obj[int(token)] if isinstance(obj, list) else obj.get(token) if isinstance(obj, dict) else None
        if obj is None:
            return None
    return obj


def check_self_contained(page, text):
    """Nothing fetched; every id unique (the SVGs of one page included) and every reference resolved."""
    for tag, target in page.links:
        assert target.startswith("#") or target.startswith("data:"), (tag, target)
    assert all("src" not in s for s in page.scripts)
    assert "<link" not in text and "@import" not in text and "url(http" not in text
    assert len(page.all_ids) == len(set(page.all_ids)), "duplicate ids"
    assert set(page.references) <= set(page.all_ids), set(page.references) - set(page.all_ids)


def check_report(folder):
    """Every figure, panel and table cell of folder/report.html, nothing external."""
    text = (folder / "report.html").read_text()
    page = Page(text)
    data = load(folder / "profile.json")
    check_figures(page, data["profile"], flow="flow" in data)
    check_table(page, folder)
    check_self_contained(page, text)
    return text


def test_the_real_profile_report_holds_every_figure_and_number(real):
    check_report(real)


def test_the_real_report_draws_each_position_from_its_recording(real):
    """Every recording was found, hash-checked and processed again: no
    position says its detail is missing, and each R12 panel marks the JSON's
    own peak."""
    text = (real / "report.html").read_text()
    assert "are not shown" not in text
    for row in load(real / "profile.json")["profile"]:
        assert f"peak: {1e3 * row['fscc']['lag']:.3g} ms, {row['fscc']['r12_max']:.3g}" in text, row["file"]


def test_an_insufficient_row_is_a_gap_with_its_reason(real):
    """Real file 01 (2 mm) has 2 accepted AWCC windows: its velocity cell is a
    gap whose note gives AWCC's reason; the FSCC forest corrects its velocity
    (one mode since issue 33), so the corrected velocity is a value, the
    forest's median, and its Tu a gap (that forest corrects no Tu)."""
    page = page_of(real)
    row0 = load(real / "profile.json")["profile"][0]
    assert row0["awcc"]["quality"] == "insufficient"
    value, gap = page.columns["awcc_velocity"][0]
    assert value is None and gap
    assert "windows accepted" in page.ids[f"gap-{gap}"]
    value, gap = page.columns["corrected_velocity"][0]
    assert row0["correction"]["status"] == "corrected" and row0["correction"]["forest"] == "fscc"
    assert not gap and value == pytest.approx(row0["correction"]["velocity"]["median"], rel=1e-3), value
    _, gap = page.columns["corrected_turbulence_intensity"][0]
    assert gap
    _, gap = page.columns["awcc_velocity_measured"][9]
    assert "no bubble-probe correction" in page.ids[f"gap-{gap}"]


def test_the_synthetic_profile_report_holds_every_figure_and_number(synthetic):
    assert "are not shown" not in check_report(synthetic)


def test_an_fscc_only_profile_renders_with_its_gaps_explained(real_files, tmp_path):
    made("process", *real_files[2:4], "--fs", "20kHz", "--dx", "7.15mm", "--method", "fscc", "--json",
         tmp_path / "profile.json", "--csv", tmp_path / "profile.csv")
    made("report", tmp_path / "profile.json", "-o", tmp_path / "report.html")
    page = page_of(tmp_path)
    check_figures(page, load(tmp_path / "profile.json")["profile"])
    check_table(page, tmp_path)
    _, gap = page.columns["awcc_velocity"][1]
    assert "AWCC not run" in page.ids[f"gap-{gap}"]
    _, gap = page.columns["position"][0]
    assert "no positions given" in page.ids[f"gap-{gap}"]
    assert "AWCC not run" in (tmp_path / "report.html").read_text().split('id="position-0"')[1]


def test_a_changed_or_missing_recording_is_named_not_drawn(synthetic, tmp_path):
    j = load(synthetic / "profile.json")
    j["provenance"]["inputs"][1]["sha256"] = "0" * 64
    (tmp_path / "changed.json").write_text(json.dumps(j))
    for f in synthetic.glob("scene*.flac"):
        shutil.copy(f, tmp_path)
    made("report", "changed.json", "-o", "report.html", cwd=tmp_path)
    text = (tmp_path / "report.html").read_text()
    positions = text.split('id="position-')
    assert "are not shown" not in positions[1] and "are not shown" not in positions[3]
    assert "SHA-256 differs" in positions[2] and "window table not available" in positions[2]
    # Moved away from its recordings: each position says where it looked.
    os.mkdir(tmp_path / "away")
    shutil.copy(synthetic / "profile.json", tmp_path / "away")
    made("report", "profile.json", "-o", "report.html", cwd=tmp_path / "away")
    assert (tmp_path / "away" / "report.html").read_text().count("not found (looked in") == 3


def test_the_page_is_the_same_for_any_number_of_drawing_processes(synthetic, tmp_path):
    pages = []
    for jobs in (1, 3):
        out = tmp_path / f"report{jobs}.html"
        done = subprocess.run(["/usr/bin/python3", "-m", "pdp.report", "profile.json", "-o", out, "--jobs", str(jobs),
                               "--command-line", "same"], cwd=synthetic, capture_output=True, text=True)
        assert done.returncode == 0, done.stderr
        pages.append([line for line in out.read_text().splitlines() if "made (UTC)" not in line])
    assert pages[0] == pages[1]


def test_process_report_without_json_leaves_no_scratch_file(real_files, tmp_path):
    made("process", real_files[8], "--fs", "20kHz", "--dx", "7.15mm", "--report", tmp_path / "one.html")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["one.html"]
    assert "the results of pdp process (no --json written)" in (tmp_path / "one.html").read_text()
    done = run("process", real_files[8], "--fs", "20kHz", "--dx", "7.15mm", "--csv", tmp_path / "x.out", "--report",
               tmp_path / "x.out")
    assert done.returncode == 2 and "--csv and --report both name" in done.stderr
    assert not (tmp_path / "x.out").exists()
    # No JSON to read the row from: pdp process gives every recording its sizes.
    check_figures(Page((tmp_path / "one.html").read_text()), [{"sizes": {}}])


@pytest.mark.parametrize("content, code, message", [
    ('{"profile": [', 1, "not JSON"),
    ('{"a": 1}', 1, "not a pdp process result"),
    ('{"profile": []}', 1, "missing or empty"),
])
def test_bad_json_is_refused_with_no_page(tmp_path, content, code, message):
    (tmp_path / "in.json").write_text(content)
    done = run("report", tmp_path / "in.json", "-o", tmp_path / "out.html")
    assert done.returncode == code and message in done.stderr and str(tmp_path / "in.json") in done.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.json"]


def test_a_value_pdp_does_not_write_is_refused_naming_file_row_and_value(synthetic, tmp_path):
    # The report reads the enums' values from the libraries' declaration
    # (pdp.profile_columns()), as pdp correct does: no value is drawn as a default.
    columns = {c["name"]: c for c in pdp.profile_columns()}
    assert columns["awcc_quality"]["values"] == ["ok", "low", "insufficient"]
    assert columns["awcc_roc"]["values"] == ["on", "off"] and columns["void_fraction"]["values"] == []
    data = load(synthetic / "profile.json")
    data["profile"][1]["awcc"]["quality"] = "good"
    (tmp_path / "in.json").write_text(json.dumps(data))
    done = run("report", tmp_path / "in.json", "-o", tmp_path / "out.html")
    assert done.returncode == 1, done.stderr
    for part in (str(tmp_path / "in.json"), "/profile/1/awcc/quality", "'good'", "ok, low, insufficient"):
        assert part in done.stderr, (part, done.stderr)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["in.json"]


def test_usage_and_output_errors_have_their_exit_status(synthetic, tmp_path):
    done = run("report", synthetic / "profile.json", "-o", tmp_path / "no" / "such" / "folder.html")
    assert done.returncode == 3 and "cannot write" in done.stderr
    done = run("report", synthetic / "profile.json", "-o", synthetic / "profile.json")
    assert done.returncode == 2 and "is the input" in done.stderr
    done = run("report", synthetic / "profile.json")
    assert done.returncode == 2


def test_a_settings_file_gives_what_the_command_line_does_not(synthetic, tmp_path):
    (tmp_path / "r.toml").write_text(f'[report]\ninput = "{synthetic / "profile.json"}"\noutput = "from-file.html"\n'
                                     'no-detail = true\njobs = 1\n')
    made("report", "--config", tmp_path / "r.toml", "-o", "given.html", cwd=tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["given.html", "r.toml"]
    page = Page((tmp_path / "given.html").read_text())
    assert page.positions == [0, 1, 2] and not any(g.startswith("p0-") for g in page.gids)
    assert (tmp_path / "given.html").read_text().count("Figures left out (pdp report --no-detail)") == 3
    # The command line wins however it spells the option.
    made("report", "--config", tmp_path / "r.toml", "--output=eq.html", cwd=tmp_path)
    assert (tmp_path / "eq.html").exists() and not (tmp_path / "from-file.html").exists()
    for text, message in (('jobs = "2"', "give a whole number"), ("job = 2", "unknown setting 'job'"),
                          ("jobs = [", "not TOML")):
        (tmp_path / "bad.toml").write_text(text + "\n")
        done = run("report", synthetic / "profile.json", "-o", tmp_path / "x.html", "--config", tmp_path / "bad.toml")
        assert done.returncode == 2 and message in done.stderr and "bad.toml" in done.stderr
    assert not (tmp_path / "x.html").exists()


def test_a_missing_python_or_package_says_what_to_install(synthetic, tmp_path):
    env = dict(os.environ, PDP_PYTHON=str(tmp_path / "no-python"))
    done = run("report", synthetic / "profile.json", "-o", tmp_path / "r.html", env=env)
    assert done.returncode == 5 and "python3-matplotlib python3-jinja2" in done.stderr
    # A jinja2 that cannot be imported, ahead of Debian's on the path.
    (tmp_path / "shadow").mkdir()
    (tmp_path / "shadow" / "jinja2.py").write_text("raise ImportError('absent', name='jinja2')\n")
    env = dict(os.environ, PYTHONPATH=str(tmp_path / "shadow"))
    done = run("report", synthetic / "profile.json", "-o", tmp_path / "r.html", env=env)
    assert done.returncode == 5 and "jinja2 is missing" in done.stderr and "python3-jinja2" in done.stderr
    assert not (tmp_path / "r.html").exists()


def test_the_real_report_renders_in_headless_chromium(real):
    """No console error or warning, not blank, a screenshot of the full page:
    its height is the document's, which holds at least the seven profile
    figures (three rows of ~300 px) and the 75-row table (~18 px a row)."""
    from browser import render

    shot = render(real / "report.html", width=1280, timeout=120)
    bad = [e for e in shot["console"] if e.get("level") in ("SEVERE", "WARNING")]
    assert not bad, bad
    assert not shot["blank"] and shot["nonwhite_fraction"] > 0.02
    dpr = shot["device_pixel_ratio"]
    assert shot["png_size"] == (round(shot["document_width"] * dpr), round(shot["document_height"] * dpr))
    assert shot["document_height"] > 3 * 300 + 75 * 18
    if os.environ.get("PDP_UPDATE_SCREENSHOT"):
        (SOURCE / "docs" / "figures" / "report-real-profile.png").write_bytes(shot["png"])


def test_printing_opens_every_position_in_print_layout(real):
    """As printed (print CSS, beforeprint), every position's figures are in
    the page: it grows by at least ten 3 x 3 panels' height (each ~700 px at
    the print layout's width) over the screen's, without a console error."""
    from browser import render

    screen = render(real / "report.html", width=1000, timeout=120)
    printed = render(real / "report.html", width=1000, timeout=120, media="print")
    assert not [e for e in printed["console"] if e.get("level") in ("SEVERE", "WARNING")]
    assert printed["document_height"] > screen["document_height"] + 10 * 500


def test_a_felder_preset_profile_is_drawn_from_its_recordings(real_files, tmp_path):
    """The preset's options are in the provenance as values: processing again
    with those that differ from the defaults gives the JSON's velocities."""
    made("process", *real_files[2:4], "--fs", "20kHz", "--dx", "7.15mm", "--preset", "felder", "--json",
         tmp_path / "profile.json", "--csv", tmp_path / "profile.csv", "--report", tmp_path / "report.html")
    assert "are not shown" not in check_report(tmp_path)

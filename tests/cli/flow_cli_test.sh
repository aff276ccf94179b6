#!/usr/bin/env bash
# A profile's flow quantities from the command line (issue 31, METHOD 12):
# twelve binary recordings of known void fraction (square waves: c exact)
# processed with their positions give Y90, Y50, C_mean and d by the
# trapezoid through the points and (Y90, 0.9), which this test computes
# independently; the JSON's "flow" object; the real profile (c <= 0.21) gives
# no Y90 and says why for every quantity that needs it, and pdp correct gives
# it its flow anew with the corrected velocities; the mistakes (a discharge
# without its unit, profile options for one recording, a position given
# twice) refused; positions not increasing sorted and said; a profile left
# with one position and c above 0.9 at the first position flagged with why.
# Usage: flow_cli_test.sh PDP SCRATCH_DIR SOURCE_DIR
set -u
pdp=$1
dir=$2/flow_cli
src=$3
data=$src/../shared/data/felder-stepped-spillway
rm -rf "$dir" && mkdir -p "$dir"
source "$(dirname "$0")/lib.sh"

# c_i = 0.08 i at y_i = 5 i mm (i = 1..12): a square wave of period 100
# samples whose air run is 8 i samples; the trailing tip 5 samples later.
/usr/bin/python3 - "$dir" <<'PY'
import sys
d = sys.argv[1]
fs, n, period, lag = 10000, 20000, 100, 5
for i in range(1, 13):
    air = 8 * i
    lead = [1 if (k % period) < air else 0 for k in range(n)]
    trail = lead[-lag:] + lead[:-lag]
    with open(f"{d}/r{i:02d}.csv", "w") as f:
        f.write("time,lead,trail\n")
        f.writelines(f"{k / fs:.5f},{lead[k]},{trail[k]}\n" for k in range(n))
PY
positions=$(/usr/bin/python3 -c "print(','.join(f'{5 * i}mm' for i in range(1, 13)))")
"$pdp" --log-level error process "$dir"/r*.csv --dx 5mm --positions "$positions" --csv "$dir/p.csv" \
  --json "$dir/p.json" --discharge 150l/s/m >"$dir/p.txt" || fail "process the synthetic profile"
/usr/bin/python3 - "$dir/p.json" <<'PY' || fail "the synthetic profile's flow quantities"
import json, sys
f = json.load(open(sys.argv[1]))["flow"]
# Y90: between y = 55 mm (c 0.88) and 60 mm (0.96): 55 + 5 (0.02 / 0.08) = 56.25 mm.
y90 = 0.05625
assert abs(f["y90"]["value"] - y90) < 1e-12, f["y90"]
levels = {l["level"]: l for l in f["levels"]}
assert abs(levels[0.5]["value"] - 0.03125) < 1e-12, levels[0.5]   # 30 + 5 (0.02 / 0.08) mm
# C_mean: c held at 0.08 below 5 mm, the trapezoid of the linear c from 5 to
# 55 mm (mean 0.48 over 50 mm), then (0.88 + 0.9) / 2 over 1.25 mm.
integral = 0.08 * 0.005 + 0.48 * 0.050 + 0.89 * 0.00125
assert abs(f["c_mean"]["value"] - integral / y90) < 1e-12, f["c_mean"]
assert abs(f["clear_water_depth"]["value"] - (y90 - integral)) < 1e-12, f["clear_water_depth"]
assert f["invert"] == "held" and abs(f["discharge"] - 0.15) < 1e-15
# Every row's c is exact and its velocity the same (no power law, no
# discharge): each quantity without a value says why.
for key in ("water_discharge", "continuity_error"):
    assert f[key]["value"] is None and f[key]["reason"], (key, f[key])
assert f["power_law"]["n"]["value"] is None and "does not grow" in f["power_law"]["n"]["reason"]
assert f["status"] == "incomplete"
PY
grep -q "Y90 = 56.25 mm" "$dir/p.txt" || fail "the summary lacks Y90: $(cat "$dir/p.txt")"

# Mistakes.
expect 2 "discharge" "$pdp" process "$dir"/r*.csv --dx 5mm --positions "$positions" --discharge 0.2 --json "$dir/x.json"
expect 2 "a profile's flow quantities need two or more recordings with their positions" \
  "$pdp" process "$dir/r01.csv" --dx 5mm --discharge 0.2m2/s --json "$dir/x.json"
expect 2 "invert" "$pdp" process "$dir"/r*.csv --dx 5mm --positions "$positions" --invert below --json "$dir/x.json"
# A position given twice: refused before any recording is read, naming both files.
expect 2 "r02.csv the same position, 5mm" "$pdp" process "$dir/r01.csv" "$dir/r02.csv" --dx 5mm \
  --positions 5mm,5mm --json "$dir/x.json"
[[ -e $dir/x.json ]] && fail "an output was written for a refused profile"

# Positions not increasing: sorted, said in the flow's notes and on stderr.
"$pdp" process "$dir/r03.csv" "$dir/r01.csv" "$dir/r02.csv" --dx 5mm --positions 15mm,5mm,10mm \
  --json "$dir/sorted.json" 2>"$dir/sorted.err" >/dev/null || fail "process an unsorted profile"
grep -q "positions did not come in increasing y: sorted by y (input rows 2, 3, 1)" "$dir/sorted.err" ||
  fail "stderr does not say the rows were sorted: $(cat "$dir/sorted.err")"
/usr/bin/python3 - "$dir/sorted.json" <<'PY' || fail "the unsorted profile's flow"
import json, sys
f = json.load(open(sys.argv[1]))["flow"]
assert any("sorted by y (input rows 2, 3, 1)" in n for n in f["notes"]), f["notes"]
assert [r["position"] for r in f["rows"]] == [0.005, 0.010, 0.015], f["rows"]
PY

# A profile of one position (the other file is no recording, skipped): the
# flow refused with its reason, the rest written.
echo "not a recording" >"$dir/notes.txt"
"$pdp" process "$dir/r01.csv" "$dir/notes.txt" --dx 5mm --positions 5mm,10mm --json "$dir/one.json" \
  2>"$dir/one.err" >/dev/null || fail "process a profile left with one position: $(cat "$dir/one.err")"
grep -q "a profile of 1 position(s)" "$dir/one.err" || fail "stderr does not say why there is no flow: $(cat "$dir/one.err")"
/usr/bin/python3 - "$dir/one.json" <<'PY' || fail "the one-position profile's flow"
import json, sys
f = json.load(open(sys.argv[1]))["flow"]
assert f["status"] == "refused" and "a profile of 1 position(s)" in f["reason"], f
PY

# c above 0.9 at the first position (0.96, 0.88, 0.80 going up): Y90 only
# bounded, flagged on stderr and in the JSON; what needs Y90 says why.
"$pdp" process "$dir/r12.csv" "$dir/r11.csv" "$dir/r10.csv" --dx 5mm --positions 5mm,10mm,15mm \
  --json "$dir/above.json" 2>"$dir/above.err" >/dev/null || fail "process a profile starting above 0.9"
grep -q "Y90 flagged: c = 0.96 > 0.9 already at the first position" "$dir/above.err" ||
  fail "stderr does not flag Y90: $(cat "$dir/above.err")"
/usr/bin/python3 - "$dir/above.json" <<'PY' || fail "the profile starting above 0.9"
import json, sys
f = json.load(open(sys.argv[1]))["flow"]
y = f["y90"]
assert y["status"] == "below_first_position" and y["position"] == 0.005 and y["value"] is None, y
assert "upper bound" in y["reason"], y
for key in ("c_mean", "clear_water_depth", "water_discharge", "air_discharge"):
    assert f[key]["value"] is None and f[key]["reason"], (key, f[key])
assert f["smooth_chute"]["value"] is None and f["smooth_chute"]["reason"], f["smooth_chute"]
PY

# The real profile stops at c = 0.21: no Y90, and every quantity needing it says so.
if [[ -d $data ]]; then
  "$pdp" --log-level error process "$data"/dc157_*.dat --fs 20kHz --dx 7.15mm \
    --positions 2mm,8mm,14mm,20mm,26mm,32mm,38mm,44mm,50mm,54mm --json "$dir/real.json" --csv "$dir/real.csv" \
    >/dev/null || fail "process the real profile"
  /usr/bin/python3 - "$dir/real.json" <<'PY' || fail "the real profile's flow quantities"
import json, sys
f = json.load(open(sys.argv[1]))["flow"]
assert f["y90"]["value"] is None and "never reaches c = 0.9" in f["y90"]["reason"], f["y90"]
for key in ("c_mean", "clear_water_depth", "water_discharge", "air_discharge"):
    assert f[key]["value"] is None and "no Y90" in f[key]["reason"], (key, f[key])
assert len(f["rows"]) == 10
PY
  # pdp correct gives a corrected profile its flow anew, with the corrected
  # velocities: the JSON's flow, and the summary on stdout; the CSV's summary
  # too. Its options are process's (a discharge without unit refused).
  model=$src/samples/model/awcc.qrf
  "$pdp" --log-level error correct "$dir/real.json" -m "$model" -o "$dir/corrected.json" --flow-seed 7 \
    >"$dir/corrected.txt" || fail "correct the real profile's JSON"
  /usr/bin/python3 - "$dir/real.json" "$dir/corrected.json" <<'PY' || fail "the corrected profile's flow"
import json, sys
before, after = (json.load(open(p)) for p in sys.argv[1:])
rows = after["flow"]["rows"]
corrected = [e for e in after["profile"]
             if e["correction"]["status"] == "corrected" and e["correction"]["forest"] == "awcc"]
assert corrected, "no row corrected by the AWCC forest"
by_position = {e["position"]: e for e in after["profile"]}
# A corrected row is leaned on unless its 95 % interval excludes FSCC's
# (METHOD 12 as docs/validation.md decides it): then its uncorrected
# velocity, and a note naming it.
notes = after["flow"]["notes"]
for r in rows:
    e = by_position[r["position"]]
    c = e["correction"]
    if c["status"] == "corrected" and c["forest"] == "awcc":
        q, f = c["velocity"]["quantiles"], e["fscc"].get("velocity_ci95")
        if f and (q["0.975"] < f[0] or q["0.025"] > f[1]):
            assert r["velocity_source"] in ("awcc", "fscc"), r
            assert any(n.startswith(r["name"] + ": the corrected AWCC velocity") for n in notes), (r, notes)
        else:
            assert r["velocity_source"] == "corrected awcc" and r["velocity"] == c["velocity"]["median"], r
    else:
        assert r["velocity_source"] != "corrected awcc", r
assert sum(n.count(": the corrected AWCC velocity") for n in notes) == 2, notes
assert after["flow"]["seed"] == 7 and before["flow"]["seed"] == 0
PY
  grep -q "profile of 10 positions" "$dir/corrected.txt" || fail "pdp correct -o prints no flow summary"
  grep -q "corrected awcc" "$dir/corrected.txt" || fail "the summary does not name the corrected velocities"
  "$pdp" --log-level error correct "$dir/real.csv" -m "$model" -o "$dir/corrected.csv" >"$dir/corrected_csv.txt" ||
    fail "correct the real profile's CSV"
  grep -q "profile of 10 positions" "$dir/corrected_csv.txt" || fail "pdp correct of a CSV prints no flow summary"
  expect 2 "discharge" "$pdp" correct "$dir/real.json" -m "$model" --discharge 0.2 -o "$dir/x.json"
  "$pdp" --log-level error process "$data/dc157_04.dat" --fs 20kHz --dx 7.15mm --json "$dir/single.json" >/dev/null ||
    fail "process one recording"
  expect 2 "one recording, not a profile" "$pdp" correct "$dir/single.json" -m "$model" --discharge 0.2m2/s \
    -o "$dir/x.json"
  [[ -e $dir/x.json ]] && fail "pdp correct wrote an output for refused options"
else
  echo "skipped the real profile: $data is absent"
fi

exit $((failures > 0))

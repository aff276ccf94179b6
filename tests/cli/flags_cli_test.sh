#!/usr/bin/env bash
# Issue 29, one list of warnings per row, the same in every output:
#  case 3: the 8 mm row (dc157_02: AWCC 1.68 m/s from 10 windows, FSCC 2.51
#    m/s) is flagged methods_disagree in the summary (stdout), the profile
#    table on stdout, the JSON and the CSV, and no other real row is;
#  case 5: the E4 warning reaches the JSON and the CSV with the text stderr
#    gives, for the five real files where it fires, and its advice fits the
#    row (file 04, 23 accepted windows: np = 6; the others: no np of 3 or more);
#  case 7 (channels beyond the tips): a four-tip recording names the
#    channels not processed in every output;
#  pdp correct reads the flagged JSON and CSV back.
# Usage: flags_cli_test.sh PDP SCRATCH_DIR SOURCE_DIR
set -u
pdp=$1
dir=$2/flags_cli
src=$3
data=$src/../shared/data/felder-stepped-spillway
rm -rf "$dir" && mkdir -p "$dir"
source "$(dirname "$0")/lib.sh"

# Case 7: four channels, the tips on 0 and 1.
"$pdp" --log-level error synth -q --config "$src/samples/four-tip.toml" --duration 4s -o "$dir/four.flac" || fail "synth four-tip"
"$pdp" process "$dir/four.flac" --dx 5mm --json "$dir/four.json" >"$dir/four.txt" 2>"$dir/four.err" || fail "process four-tip"
"$pdp" --log-level error process "$dir/four.flac" --dx 5mm --csv "$dir/four.csv" || fail "process four-tip, CSV"
four="channels 2 and 3 of 4 are not processed (a 4-tip probe?): the tip pair alone was processed, channels 0 and 1"
grep -qF "$four" "$dir/four.err" || fail "stderr lacks the ignored channels: $(cat "$dir/four.err")"
grep -qF "warning: $four" "$dir/four.txt" || fail "the summary lacks the ignored channels"
/usr/bin/python3 - "$dir/four.json" "$four" <<'PY' || fail "the JSON lacks the ignored channels"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["flags"] == ["channels_ignored"] and j["warnings"][0].startswith(sys.argv[2]), (j["flags"], j["warnings"])
PY
[[ $(column "$dir/four.csv" flags) == channels_ignored ]] || fail "the CSV's flags lack channels_ignored"
[[ $(column "$dir/four.csv" warnings) == "$four"* ]] || fail "the CSV's warnings lack the ignored channels"

if [[ -d $data ]]; then
  files=("$data"/dc157_*.dat)
  positions=2mm,8mm,14mm,20mm,26mm,32mm,38mm,44mm,50mm,54mm
  "$pdp" process "${files[@]}" --fs 20kHz --dx 7.15mm --positions $positions --json "$dir/profile.json" \
    --csv "$dir/profile.csv" 2>"$dir/profile.err" || fail "process the profile"
  "$pdp" --log-level error process "${files[@]}" --fs 20kHz --dx 7.15mm --positions $positions >"$dir/stdout.csv" ||
    fail "process the profile to stdout"

  # Case 3: only the 8 mm row is flagged, in the JSON, the CSV file and the table on stdout.
  /usr/bin/python3 - "$dir/profile.json" "$dir/profile.csv" "$dir/stdout.csv" <<'PY' || fail "case 3: the 8 mm row's flag"
import csv, json, sys
rows = json.load(open(sys.argv[1]))["profile"]
flagged = [r["position"] for r in rows if "methods_disagree" in r["flags"]]
assert flagged == [0.008], flagged
r = rows[1]
text = r["warnings"][r["flags"].index("methods_disagree")]
for part in ("AWCC's velocity 1.676 m/s", "FSCC's 2.509 m/s", "differ by 0.833 m/s", "AWCC 33 % below FSCC",
             "lags 3.75-4.65 ms", "FSCC's whole record at 2.85 ms"):
    assert part in text, (part, text)
for table in sys.argv[2:]:
    got = {row["file"]: row for row in csv.DictReader(open(table))}
    assert [f for f, row in got.items() if "methods_disagree" in row["flags"]] == ["dc157_02.dat"], table
    assert text in got["dc157_02.dat"]["warnings"], table
PY
  out=$("$pdp" --log-level error process "$data/dc157_02.dat" --fs 20kHz --dx 7.15mm) || fail "process dc157_02"
  grep -qF "warning: AWCC's velocity 1.676 m/s" <<<"$out" || fail "case 3: the summary lacks the disagreement: $out"
  grep -qF "[methods_disagree]" <<<"$out" || fail "case 3: the summary lacks the flag"
  grep -q "FSCC: velocity 2.5088 m/s (95 % sampling interval" <<<"$out" || fail "the summary lacks FSCC's interval"
  grep -qF "are 95 % sampling intervals: they cover the scatter of a finite record, not the method's bias" <<<"$out" ||
    fail "the summary does not say what the intervals cover"

  # Case 5: the E4 text of stderr, exactly, in the JSON and the CSV of the five files it fires for.
  /usr/bin/python3 - "$dir/profile.json" "$dir/profile.csv" "$dir/profile.err" <<'PY' || fail "case 5: the E4 warning in every output"
import csv, json, re, sys
rows = json.load(open(sys.argv[1])).get("profile")
table = {row["file"]: row for row in csv.DictReader(open(sys.argv[2]))}
stderr = {}
for line in open(sys.argv[3]):
    m = re.match(r"\[warning\] .*/(dc157_\d\d\.dat): (.*) \[integral_scale_short\]$", line.rstrip("\n"))
    if m:
        stderr[m.group(1)] = m.group(2)
assert sorted(stderr) == ["dc157_03.dat", "dc157_04.dat", "dc157_08.dat", "dc157_09.dat", "dc157_10.dat"], sorted(stderr)
for r in rows:
    name = r["file"].rsplit("/", 1)[-1]
    if name not in stderr:
        assert "integral_scale_short" not in r["flags"], name
        continue
    text = stderr[name]
    assert r["warnings"][r["flags"].index("integral_scale_short")] == text, name
    assert r["velocity_spectrum"]["warning"] == text, name
    assert table[name]["warnings"] == text and table[name]["flags"] == "integral_scale_short", name
    # Advice that fits the row: file 04 (ratio 1.27, 23 windows) can use np = 6; the others no np of 3 or more.
    if name == "dc157_04.dat":
        assert "np = 6 particles or fewer (now 10)" in text and "rests on 23 accepted windows" in text, text
    else:
        assert "under the 3 particles per window" in text and "particles or fewer" not in text, text
    assert "use fewer particles per window" not in text, text
PY

  # pdp correct reads the flagged outputs back.
  model=$src/samples/model/awcc.qrf
  "$pdp" --log-level error correct "$dir/profile.csv" -m "$model" --dx 7.15mm --dy 0mm --np 10 -o "$dir/corrected.csv" ||
    fail "pdp correct on the flagged CSV"
  [[ $(column "$dir/corrected.csv" flags | sed -n 2p) == methods_disagree ]] || fail "the corrected CSV lost the flags"
  "$pdp" --log-level error correct "$dir/profile.json" -m "$model" --np 10 -o "$dir/corrected.json" ||
    fail "pdp correct on the flagged JSON"
else
  echo "flags_cli_test.sh: $data absent: the real-profile checks (cases 3 and 5) are skipped"
fi

[[ $failures -eq 0 ]] && echo "flags CLI: all checks passed"
exit $((failures > 0))

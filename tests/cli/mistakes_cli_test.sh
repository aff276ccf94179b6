#!/usr/bin/env bash
# The mistakes a new user makes with real recordings (issue 12), each with
# what pdp now says: a dimensional value without its unit, an implausible
# value, a sampling rate that contradicts the file, an AWCC result from too
# few windows, swapped tips, a truncated WAV, European and LabVIEW column
# files, folders, spaces, commas and README.md among the inputs, and the
# provenance of every output. docs/reliability.md lists them.
# Usage: mistakes_cli_test.sh PDP SCRATCH_DIR SOURCE_DIR
set -u
pdp=$1
dir=$2/mistakes_cli
src=$3
data=$src/../shared/data/felder-stepped-spillway
rm -rf "$dir" && mkdir -p "$dir"
source "$(dirname "$0")/lib.sh"
py() { /usr/bin/python3 "$@"; }

"$pdp" --log-level warn synth -q --duration 2s --fs 100kHz --velocity 4m/s --dy 0mm --signal voltage -o "$dir/rec.wav" ||
  fail "synth"

# 1. Quantities need units, on the command line and in settings files; zero needs none.
expect 2 "dx: 7.15 has no unit: write 7.15mm (or the same as 0.00715m) (--dx)" "$pdp" process "$dir/rec.wav" --dx 7.15 --json "$dir/a.json"
[[ -e $dir/a.json ]] && fail "an output was written for a unit-less dx"
printf 'dx = 7.15\n' >"$dir/unitless.toml"
expect 2 "7.15 has no unit" "$pdp" process "$dir/rec.wav" --config "$dir/unitless.toml"
expect 2 "fs: 20000 has no unit: write 20000Hz (or the same as 20kHz) (--fs)" "$pdp" synth -q --fs 20000 -o "$dir/x.flac"
"$pdp" --log-level error process "$dir/rec.wav" --dx 5mm --dy 0 >/dev/null || fail "dy 0 without a unit refused"

# 2. Values implausible for a probe are refused, naming the range, unless allowed.
expect 2 "dx = 715mm lies outside 0.1 mm to 100 mm" "$pdp" process "$dir/rec.wav" --dx 715mm
expect 2 "(--allow-unusual)" "$pdp" process "$dir/rec.wav" --dx 715mm
expect 2 "outside 1 kHz to 100 MHz" "$pdp" process "$dir/rec.wav" --dx 5mm --fs 500Hz --override-fs
expect 2 "outside 0.01 m/s to 200 m/s" "$pdp" process "$dir/rec.wav" --dx 5mm --velocity-range 0.5m/s,500m/s
"$pdp" --log-level error process "$dir/rec.wav" --dx 715mm --allow-unusual >/dev/null || fail "--allow-unusual refused"

# 3. A stated rate that contradicts the file's: an error naming both; forced with --override-fs.
expect 1 "records a sampling rate of 100kHz but 2kHz was stated" "$pdp" process "$dir/rec.wav" --dx 5mm --fs 2kHz
expect 1 "(--override-fs)" "$pdp" process "$dir/rec.wav" --dx 5mm --fs 2kHz
"$pdp" --log-level error process "$dir/rec.wav" --dx 5mm --fs 100kHz >/dev/null || fail "the file's own rate refused"
"$pdp" --log-level error process "$dir/rec.wav" --dx 5mm --fs 50kHz --override-fs >/dev/null || fail "--override-fs"

# 4. An FSCC velocity above 100 m/s is warned about with the likely causes.
# (true lag 5 mm / 4 m/s = 125 samples at 100 kHz; read as 200 kHz with dx 100 mm: 160 m/s)
err=$("$pdp" process "$dir/rec.wav" --dx 100mm --fs 200kHz --override-fs --method fscc --json "$dir/fast.json" \
  2>&1 >/dev/null) ||
  fail "fast FSCC run"
grep -q "above 100 m/s, beyond air-water flows: check dx's unit" <<<"$err" || fail "no warning of a 100+ m/s velocity: $err"
[[ $(py -c "import json; print(len(json.load(open('$dir/fast.json'))['fscc']['warnings']))") == 1 ]] ||
  fail "the JSON lacks the FSCC warning"

# 5. Swapped tips: neither method reports a velocity; the message names the flags.
out=$("$pdp" process "$dir/rec.wav" --dx 5mm --leading-channel 1 --trailing-channel 0 --json "$dir/swapped.json") ||
  fail "swapped run"
grep -q "leading-channel/--trailing-channel" <<<"$out" || fail "swapped tips: no flag named: $out"
py - "$dir/swapped.json" <<'PY' || fail "swapped tips still give a velocity"
import json, sys
j = json.load(open(sys.argv[1]))
assert j["fscc"]["velocity"] is None and j["fscc"]["status"] == "tips_swapped", j["fscc"]
assert j["awcc"]["velocity"] is None and j["awcc"]["status"] == "tips_swapped", j["awcc"]["reason"]
PY

# 6. Quality levels: too few windows (a short record) is insufficient, with no velocity.
# 0.15 s at c = 0.2: about 150 bubbles, enough for FSCC to find the lag's sign, and at
# most 16 windows of 10 particles, of which 0-9 were accepted over seeds 1-8.
"$pdp" --log-level warn synth -q --duration 0.15s --fs 100kHz --void-fraction 0.2 -o "$dir/short.flac" || fail "short synth"
"$pdp" --log-level error process "$dir/short.flac" --dx 5mm --json "$dir/short.json" >/dev/null || fail "short run"
py - "$dir/short.json" <<'PY' || fail "a result from too few windows is not insufficient"
import json, sys
a = json.load(open(sys.argv[1]))["awcc"]
assert a["quality"] == "insufficient" and a["velocity"] is None and a["turbulence_intensity"] is None, a
assert "fewer than 10" in a["quality_reason"], a["quality_reason"]
PY

# 7. A WAV cut short: refused naming the promised and present durations; allowed with a warning in every output.
head -c 300000 "$dir/rec.wav" >"$dir/cut.wav"
expect 1 "promises 2.000 s of data but the file holds 0.750 s" "$pdp" process "$dir/cut.wav" --dx 5mm
expect 1 "(--allow-truncated)" "$pdp" process "$dir/cut.wav" --dx 5mm
out=$("$pdp" process "$dir/cut.wav" --dx 5mm --allow-truncated --json "$dir/cut.json" 2>&1) || fail "--allow-truncated"
grep -q "warning: the header promises" <<<"$out" || fail "the summary lacks the truncation warning: $out"
grep -q "truncated" <(py -c "import json; print(json.load(open('$dir/cut.json'))['warnings'])") ||
  fail "the JSON lacks the truncation warning"
"$pdp" --log-level error process "$dir/cut.wav" "$dir/rec.wav" --dx 5mm --allow-truncated --csv "$dir/cut.csv" ||
  fail "truncated profile"
[[ $(column "$dir/cut.csv" warnings | head -1) == *truncated* ]] || fail "the profile CSV lacks the truncation warning"

# 8. European CSV (semicolons, decimal commas, a 'Zeit [s]' column) and LabVIEW .lvm: the same numbers as the WAV.
py - "$dir/rec.wav" "$dir" <<'PY' || fail "writing the column files"
import struct, sys, wave
w = wave.open(sys.argv[1])
n, fs = w.getnframes(), w.getframerate()
raw = w.readframes(n)
v = struct.unpack("<%dh" % (2 * n), raw)
scale = 5.0 / 32768
with open(sys.argv[2] + "/euro.csv", "w") as f:
    f.write("Zeit [s];Spitze 1 [V];Spitze 2 [V]\n")
    for i in range(n):
        f.write(("%.6f;%.6f;%.6f\n" % (i / fs, v[2 * i] * scale, v[2 * i + 1] * scale)).replace(".", ","))
with open(sys.argv[2] + "/rec.lvm", "w") as f:
    f.write("LabVIEW Measurement\t\nWriter_Version\t2\nSeparator\tTab\nDecimal_Separator\t.\n***End_of_Header***\t\n\n")
    f.write("Channels\t2\t\nDelta_X\t%.9f\t%.9f\t\n***End_of_Header***\t\t\t\n" % (1 / fs, 1 / fs))
    f.write("X_Value\tUntitled\tUntitled 1\tComment\n")
    for i in range(n):
        f.write("%.6f\t%.6f\t%.6f\t\n" % (i / fs, v[2 * i] * scale, v[2 * i + 1] * scale))
PY
"$pdp" --log-level error process "$dir/rec.wav" --dx 5mm --volts-per-count 0.000152587890625V --json "$dir/wav.json" >/dev/null ||
  fail "wav run"
out=$("$pdp" process "$dir/euro.csv" --dx 5mm --json "$dir/euro.json") || fail "European CSV"
grep -q "channel 0, 'Spitze 1 \[V\]'" <<<"$out" || fail "the summary does not say which column became the leading tip: $out"
grep -q "time in 'Zeit \[s\]'" <<<"$out" || fail "the summary does not name the time column: $out"
"$pdp" --log-level error process "$dir/rec.lvm" --dx 5mm --json "$dir/lvm.json" >/dev/null || fail "LabVIEW .lvm"
py - "$dir/wav.json" "$dir/euro.json" "$dir/lvm.json" <<'PY' || fail "column files differ from the WAV"
import json, sys
ref, *others = [json.load(open(p)) for p in sys.argv[1:]]
for o in others:
    assert abs(o["fs"] - ref["fs"]) < 1e-3 * ref["fs"], (o["fs"], ref["fs"])
    for t in range(2):
        assert abs(o["tips"][t]["void_fraction"] - ref["tips"][t]["void_fraction"]) < 1e-3, (o["tips"][t]["void_fraction"], ref["tips"][t]["void_fraction"])
    assert abs(o["tips"][0]["bubble_count_rate"] / ref["tips"][0]["bubble_count_rate"] - 1) < 1e-9
PY

# A Latin-1 header (a German 'ä' not in UTF-8) still gives a JSON (the byte replaced).
{ printf 'Zeit [s];Spitze\xe4 1 [V];Spitze 2 [V]\n'; tail -n +2 "$dir/euro.csv"; } >"$dir/latin1.csv"
"$pdp" --log-level error process "$dir/latin1.csv" --dx 5mm --json "$dir/latin1.json" >/dev/null || fail "a Latin-1 header"
py -c "import json; json.load(open('$dir/latin1.json'))" || fail "the JSON of a Latin-1 header is not valid"

# 9. A folder, a README.md, a path with spaces and a file name with a comma among the inputs.
mkdir -p "$dir/a folder"
"$pdp" --log-level warn synth -q --duration 2s --fs 100kHz --velocity 4m/s --dy 0mm --signal voltage --seed 2 \
  -o "$dir/a folder/with space, and comma.wav" || fail "synth"
printf '# Notes\nThis is not a recording.\n' >"$dir/README.md"
err=$("$pdp" process "$dir/rec.wav" "$dir/a folder/with space, and comma.wav" "$dir/README.md" "$dir/a folder" \
  --dx 5mm --csv "$dir/glob.csv" --json "$dir/glob.json" 2>&1) || fail "a profile with non-recordings: $err"
grep -q "skipped: .*README.md: a .md file is not a recording" <<<"$err" || fail "README.md not skipped with a warning: $err"
grep -q "skipped: .*a folder: is a folder" <<<"$err" || fail "folder not skipped with a warning: $err"
[[ $(column "$dir/glob.csv" file | tail -1) == "with space, and comma.wav" ]] ||
  fail "a comma in a file name corrupts the profile CSV: $(cat "$dir/glob.csv" | tail -1)"
[[ $(py -c "import json; print(len(json.load(open('$dir/glob.json'))['skipped']))") == 2 ]] || fail "the JSON lacks the skipped inputs"
expect 1 "none of the 2 inputs is a recording" "$pdp" process "$dir/README.md" "$dir/a folder" --dx 5mm
expect 1 "is a folder, not a recording" "$pdp" process "$dir/a folder" --dx 5mm

# 10. Every output says how it was made.
py - "$dir/wav.json" "$dir/rec.wav" <<'PY' || fail "provenance"
import hashlib, json, os, sys
p = json.load(open(sys.argv[1]))["provenance"]
assert p["inputs"][0]["sha256"] == hashlib.sha256(open(sys.argv[2], "rb").read()).hexdigest(), p["inputs"]
assert p["inputs"][0]["bytes"] == os.path.getsize(sys.argv[2])
assert p["options"]["np"] == "10" and p["options"]["dx"] == "5mm" and p["options"]["filter-a"] == "0.4", p["options"]
assert "process" in p["command_line"] and p["pdp_version"] and p["utc_time"].endswith("Z"), p
PY
header=$(head -1 "$dir/glob.csv")
for c in dx dy np fs duration awcc_quality void_fraction_ci95_lower bubble_count_rate_ci95_upper awcc_velocity_ci95_lower \
  awcc_velocity_rms_ci95_upper awcc_turbulence_intensity_ci95_lower pdp_version; do
  grep -q "\(^\|,\)$c\(,\|$\)" <<<"$header" || fail "the profile CSV lacks $c"
done

# 11. pdp correct on the CSV other AWCC tools write, and on an unknown layout.
printf 'z [m],u [m/s],u_rms [m/s],c [-],d_32a [m]\n0.01,3.1,0.5,0.05,0.002\n0.02,3.3,0.45,0.3,0.004\n' >"$dir/tool.csv"
"$pdp" --log-level error correct "$dir/tool.csv" -m "$src/samples/model/awcc.qrf" --dx 7.15mm --dy 0mm --np 10 \
  -o "$dir/tool-corrected.csv" || fail "correct another tool's CSV"
head -1 "$dir/tool-corrected.csv" | grep -q "u_corrected \[m/s\],u_q0.025 \[m/s\]" || fail "the quantiles' header style"
[[ $(column "$dir/tool-corrected.csv" "correction_status [-]" | wc -l) == 2 ]] || fail "rows of the other tool's CSV"
printf 'a,b\n1,2\n' >"$dir/unknown.csv"
expect 1 "the CSV other AWCC tools write (columns 'u [m/s]'" "$pdp" correct "$dir/unknown.csv" -m "$src/samples/model/awcc.qrf"

# 12. The real profile: quality per row; rows are corrected down to the model's least windows (10 for
# the shipped model), whatever their quality: the six low rows (10-50 windows) by the AWCC forest; the
# insufficient one (2 windows) goes to the FSCC forest, which corrects it with one mode (issue 33; it was
# untrusted, two modes, before: tests/cli/correction_trust_test.sh); c, F and FSCC velocities as before.
if [[ -d $data ]]; then
  "$pdp" --log-level error process "$data"/dc157_*.dat --fs 20kHz --dx 7.15mm --dy 0mm \
    --correct "$src/samples/model/awcc.qrf" --csv "$dir/real.csv" || fail "real profile"
  [[ $(column "$dir/real.csv" awcc_quality | tr '\n' ' ') == "insufficient low low low low low low ok ok ok " ]] ||
    fail "real profile quality: $(column "$dir/real.csv" awcc_quality | tr '\n' ' ')"
  [[ $(column "$dir/real.csv" correction_status | tr '\n' ' ') == "$(printf 'corrected %.0s' 1 2 3 4 5 6 7 8 9 10)" ]] ||
    fail "real profile corrections: $(column "$dir/real.csv" correction_status | tr '\n' ' ')"
  [[ $(column "$dir/real.csv" correction_forest | tr '\n' ' ') == "fscc $(printf 'awcc %.0s' 1 2 3 4 5 6 7 8 9)" ]] ||
    fail "real profile forests: $(column "$dir/real.csv" correction_forest | tr '\n' ' ')"
  [[ $(column "$dir/real.csv" chord_velocity_source | head -7 | sort -u) == "fscc" ]] ||
    fail "chord lengths of rows not ok do not use FSCC's velocity"
  py - "$dir/real.csv" "$src/tests/golden/expected/profile.csv" <<'PY' || fail "c, F or FSCC velocities changed"
import csv, sys
new = {r["file"]: r for r in csv.DictReader(open(sys.argv[1]))}
for r in csv.DictReader(open(sys.argv[2])):
    for k in ("void_fraction", "bubble_count_rate", "void_fraction_trailing", "fscc_velocity"):
        assert new[r["file"]][k] == r[k], (r["file"], k, new[r["file"]][k], r[k])
PY
else
  echo "mistakes_cli_test.sh: $data absent: the real-profile checks are skipped"
fi

[[ $failures -eq 0 ]] && echo "mistakes CLI: all checks passed"
exit $((failures > 0))

#!/usr/bin/env bash
# Command-line behaviour of `pdp process`: a summary, the JSON keys of
# docs/output.md, a profile CSV, and bad input (message naming the file and
# the problem, non-zero exit, no output file).
# Usage: process_cli_test.sh PDP SCRATCH_DIR SOURCE_DIR
set -u
pdp=$1
dir=$2/process_cli
src=$3
data=$src/../shared/data/felder-stepped-spillway
rm -rf "$dir" && mkdir -p "$dir"
# shellcheck source=lib.sh
source "$src/tests/cli/lib.sh"

# A synthetic recording to process.
"$pdp" --log-level warn synth -q --duration 1s --fs 100kHz --tu 0.05 --dy 0 -o "$dir/rec.flac" || fail "synth"

# One file: summary on stdout, JSON with the documented keys.
out=$("$pdp" process "$dir/rec.flac" --dx 5mm --json "$dir/one.json") || fail "process one file"
grep -q "void fraction" <<<"$out" || fail "no summary on stdout"
grep -q "FSCC: velocity" <<<"$out" || fail "no FSCC velocity in the summary"
# Levels in volts only where the file states them (issue 53: a WAV's
# normalised samples were printed in V).
"$pdp" --log-level error synth -q --duration 1s --fs 100kHz --signal voltage -o "$dir/norm.wav" || fail "synth wav"
rm -f "$dir"/norm.wav.*json "$dir"/norm.*.json
norm=$("$pdp" --log-level error process "$dir/norm.wav" --dx 5mm) || fail "process wav"
grep "tip (channel 0)" <<<"$norm" | grep -q " V " && fail "normalised units printed as volts: $norm"
grep -q "(the file's units, not volts" <<<"$norm" || fail "the units are not said: $norm"
for key in tips threshold void_fraction bubble_count_rate chord_time_mean chord_time_median fscc velocity lag \
  r12_max t05 tau05 turbulence_intensity_chanson; do
  grep -q "\"$key\"" "$dir/one.json" || fail "JSON lacks $key"
done

# AWCC: JSON keys, the window table, and every option.
"$pdp" process "$dir/rec.flac" --dx 5mm --method awcc --json "$dir/awcc.json" --windows "$dir/windows.csv" >/dev/null ||
  fail "awcc run"
for key in awcc velocity velocity_rms turbulence_intensity velocity_ci95 turbulence_intensity_ci95 windows_total \
  windows_accepted windows_rejected_correlation windows_rejected_lag windows_rejected_roc; do
  grep -q "\"$key\"" "$dir/awcc.json" || fail "AWCC JSON lacks $key"
done
grep -q '"fscc"' "$dir/awcc.json" && fail "--method awcc also ran FSCC"
head -1 "$dir/windows.csv" | grep -q "^start_time,duration,particles,lag,velocity,r12_max,spr,void_fraction,count_rate,fate,measured_velocity$" ||
  fail "window table header"
[[ $(wc -l <"$dir/windows.csv") -gt 10 ]] || fail "window table rows"
out=$("$pdp" process "$dir/rec.flac" --dx 5mm --np 15 --filter-a 0.3 --roc off --weighting none --subsample parabolic \
  --velocity-range 2m/s,40m/s) || fail "awcc options"
grep -q "AWCC: velocity" <<<"$out" || fail "AWCC summary: $out"
# ", 0 outlier cutoff," exactly: "10 outlier cutoff" must not pass.
grep -q "lag, 0 outlier cutoff, " <<<"$out" || fail "--roc off still rejected windows: $(grep 'outlier cutoff' <<<"$out")"
"$pdp" --log-level warn synth -q --duration 0.5s --fs 100kHz --signal voltage -o "$dir/volt.wav" || fail "voltage synth"
out=$("$pdp" process "$dir/volt.wav" --dx 5mm --correlate raw) || fail "raw correlation"
grep -q "AWCC" <<<"$out" || fail "raw correlation summary"

# A profile: CSV rows on stdout, positions from the command line and a manifest.
"$pdp" --log-level warn synth -q --duration 0.5s --fs 100kHz --seed 2 -o "$dir/rec2.flac"
csv=$("$pdp" process "$dir/rec.flac" "$dir/rec2.flac" --dx 5mm --positions 2mm,8mm --json "$dir/profile.json") ||
  fail "profile"
[[ $(wc -l <<<"$csv") -eq 3 ]] || fail "profile CSV should have a header and 2 rows: $csv"
head -1 <<<"$csv" | grep -q "^file,position,void_fraction,bubble_count_rate" || fail "profile CSV header"
grep -q "^rec2.flac,0.008," <<<"$csv" || fail "profile CSV position"
grep -q '"profile"' "$dir/profile.json" || fail "profile JSON"
printf 'file,position\nrec.flac,14mm\nrec2.flac,20mm\n' >"$dir/manifest.csv"
"$pdp" process "$dir/rec.flac" "$dir/rec2.flac" --dx 5mm --manifest "$dir/manifest.csv" --csv "$dir/profile.csv" ||
  fail "manifest"
grep -q "^rec.flac,0.014," "$dir/profile.csv" || fail "manifest position not applied"
# The manifest alone names the recordings (relative to its folder; issue 53:
# it failed with "files is required"); the same rows as with the files given.
(cd / && "$pdp" --log-level error process --dx 5mm --manifest "$dir/manifest.csv" --csv "$dir/profile-alone.csv") ||
  fail "the manifest alone"
cmp -s <(cut -d, -f1-4 "$dir/profile.csv") <(cut -d, -f1-4 "$dir/profile-alone.csv") ||
  fail "the manifest alone gives other rows"
"$pdp" process --dx 5mm 2>"$dir/none.err" && fail "no recording and no manifest accepted"
grep -q "files is required: give the recordings, or --manifest FILE" "$dir/none.err" || fail "$(cat "$dir/none.err")"

# Real recordings, when they are beside the repository.
if [[ -d $data ]]; then
  "$pdp" process "$data"/dc157_0{3,4}.dat --fs 20kHz --dx 7.15mm --segments 15 --felder-lags \
    --threshold-rule felder >"$dir/real.csv" || fail "real recordings"
  [[ $(wc -l <"$dir/real.csv") -eq 3 ]] || fail "real profile rows"
  # Felder's preset: FSCC of raw voltages peaks at his 54 samples on file 03
  # (2.648148 m/s); the structure tables sit beside the profile CSV; an
  # option given as well overrides the preset.
  mkdir -p "$dir/felder"
  "$pdp" process "$data"/dc157_0{3,4}.dat --fs 20kHz --dx 7.15mm --preset felder --csv "$dir/felder/p.csv" \
    --correlation-functions "$dir/felder/cf.csv" --json "$dir/felder/p.json" || fail "felder preset"
  [[ $(column "$dir/felder/p.csv" fscc_velocity | head -1) == 2.648148* ]] || fail "felder preset velocity"
  for t in voltage_pdf chord_pdf clusters cluster_sizes arrival_classes arrivals; do
    [[ -s $dir/felder/p_$t.csv ]] || fail "felder preset: no p_$t.csv"
  done
  # Two recordings x 2 bases x 3 criteria; lags -199..999 of both functions per recording.
  [[ $(($(wc -l <"$dir/felder/p_clusters.csv") - 1)) -eq 12 ]] || fail "cluster rows"
  [[ $(($(wc -l <"$dir/felder/cf.csv") - 1)) -eq 2398 ]] || fail "correlation function rows"
  /usr/bin/python3 -c "import json,sys; j=json.load(open(sys.argv[1])); o=j['provenance']['options'];
assert o['segments']=='15' and o['felder-defects']=='on' and o['correlate']=='raw', o" "$dir/felder/p.json" ||
    fail "felder preset options not recorded"
  "$pdp" process "$data"/dc157_03.dat --fs 20kHz --dx 7.15mm --preset felder --segments 1 --json "$dir/felder/s1.json" \
    >/dev/null || fail "preset with an override"
  /usr/bin/python3 -c "import json,sys; j=json.load(open(sys.argv[1])); assert j['provenance']['options']['segments']=='1'
assert j['fscc']['segments_used']==1" "$dir/felder/s1.json" || fail "an option given does not override the preset"
  # Per-tip fixed thresholds; Kramer's rule reported as such.
  "$pdp" process "$data"/dc157_03.dat --fs 20kHz --dx 7.15mm --method fscc --threshold-rule fixed --threshold 2.70V \
    --threshold-trailing 2.60V --json "$dir/fixed.json" >/dev/null || fail "per-tip fixed thresholds"
  /usr/bin/python3 -c "import json,sys; t=json.load(open(sys.argv[1]))['tips']
assert abs(t[0]['threshold']-2.7)<1e-12 and abs(t[1]['threshold']-2.6)<1e-12, t" "$dir/fixed.json" ||
    fail "the trailing tip's own threshold not applied"
  "$pdp" process "$data"/dc157_03.dat --fs 20kHz --dx 7.15mm --method fscc --threshold-rule kramer \
    --json "$dir/kramer.json" >/dev/null || fail "kramer rule"
  /usr/bin/python3 -c "import json,sys; t=json.load(open(sys.argv[1]))['tips']
assert t[0]['threshold_rule']=='kramer' and 2.6 < t[0]['threshold'] < 2.8, t[0]['threshold']" "$dir/kramer.json" ||
    fail "kramer threshold"
fi
expect 2 "fixed rule" "$pdp" process "$dir/rec.flac" --dx 5mm --threshold-trailing 2.6V
expect 2 "use one of them" "$pdp" process "$dir/rec.flac" --dx 5mm --probe-correction --correct "$src/samples/model/awcc.qrf"
expect 2 "has no unit" "$pdp" process "$dir/rec.flac" --dx 5mm --probe-correction --probe-angle 45
expect 2 "not a preset" "$pdp" process "$dir/rec.flac" --dx 5mm --preset nope

# The structure tables of a synthetic profile: each chord PDF sums to 1 over its bins.
mkdir -p "$dir/structure"
"$pdp" process "$dir/rec.flac" "$dir/rec2.flac" --dx 5mm --csv "$dir/structure/p.csv" || fail "structure tables"
/usr/bin/python3 - "$dir/structure/p_chord_pdf.csv" <<'PY' || fail "chord PDF fractions do not sum to 1"
import csv, sys, collections
sums = collections.defaultdict(float)
for r in csv.DictReader(open(sys.argv[1])):
    sums[(r["file"], r["basis"])] += float(r["air_fraction"])
assert sums and all(abs(v - 1) < 1e-9 for v in sums.values()), sums
PY

expect_refusal() {  # name, message fragment, pdp process arguments...
  local name=$1 fragment=$2
  shift 2
  local err
  err=$("$pdp" process "$@" --json "$dir/$name.json" --csv "$dir/$name.csv" 2>&1 >/dev/null)
  local status=$?
  [[ $status -ne 0 ]] || fail "$name: exit status 0"
  grep -q -- "$fragment" <<<"$err" || fail "$name: message lacks '$fragment': $err"
  [[ ! -e $dir/$name.json && ! -e $dir/$name.csv ]] || fail "$name: wrote an output file"
  ls -a "$dir" | grep -q partial && fail "$name: left a temporary file"
}

: >"$dir/empty.wav"
expect_refusal empty "empty" "$dir/empty.wav" --dx 5mm
python3 - "$dir" <<'PY'
import struct, sys, math
d = sys.argv[1]
open(f"{d}/truncated.dat", "wb").write(struct.pack("<ii", 900000, 2) + b"\0" * 4000)
open(f"{d}/lying.dat", "wb").write(struct.pack("<ii", 10, 2) + b"\0" * 4000)
open(f"{d}/single.dat", "wb").write(struct.pack("<ii", 1000, 1) + struct.pack("<1000h", *([100] * 500 + [20000] * 500)))
open(f"{d}/nan.raw", "wb").write(struct.pack("<6f", 1.0, 2.0, float("nan"), 4.0, 5.0, 6.0))
open(f"{d}/inf.raw", "wb").write(struct.pack("<4f", 1.0, float("inf"), 3.0, 4.0))
open(f"{d}/textcell.csv", "w").write("lead,trail\n1.0,4.0\n1.1,x4.0\n")
open(f"{d}/notaudio.wav", "w").write("hello, this is not a wave file\n" * 10)
PY
expect_refusal truncated "truncated" "$dir/truncated.dat" --fs 20kHz
expect_refusal lying "does not describe the data" "$dir/lying.dat" --fs 20kHz
expect_refusal notaudio "not a readable audio file" "$dir/notaudio.wav"
expect_refusal nan "NaN" "$dir/nan.raw" --fs 1kHz --raw-type float32
expect_refusal inf "infinite" "$dir/inf.raw" --fs 1kHz --raw-type float32
expect_refusal badcell "line 3, column 2" "$dir/textcell.csv" --fs 1kHz
expect_refusal single "has 1 channel" "$dir/single.dat" --fs 20kHz
expect_refusal channel "channel 7" "$dir/rec.flac" --trailing-channel 7
expect_refusal missing_fs "--fs" "$dir/single.dat"
expect_refusal bad_unit "--dx" "$dir/rec.flac" --dx 5kg
expect_refusal windows_many "one recording" "$dir/rec.flac" "$dir/rec2.flac" --windows "$dir/w.csv"
expect_refusal bad_range "velocity-range" "$dir/rec.flac" --velocity-range 5m/s
expect_refusal positions "one per file" "$dir/rec.flac" "$dir/rec2.flac" --positions 2mm

# An output that is an input is refused and the input stays as it was.
"$pdp" process "$dir/rec.flac" --dx 5mm --csv "$dir/rec.flac" 2>/dev/null && fail "output over an input accepted"
cmp -s "$dir/rec.flac" "$dir/rec2.flac" && fail "input overwritten"
"$pdp" process "$dir/rec.flac" --dx 5mm --json "$dir/rec.flac" 2>"$dir/err.txt" && fail "json over input accepted"
grep -q "is an input recording" "$dir/err.txt" || fail "output-over-input message"

if ((failures)); then
  echo "$failures failures"
  exit 1
fi
echo "pdp process CLI: all checks passed"

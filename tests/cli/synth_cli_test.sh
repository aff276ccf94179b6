#!/usr/bin/env bash
# Command-line behaviour of `pdp synth`: help, version, units, TOML with
# overrides, the sidecar, and bad input (message, non-zero exit, no file).
# Usage: synth_cli_test.sh PDP SCRATCH_DIR SOURCE_DIR
set -u
pdp=$1
dir=$2/synth_cli
src=$3
rm -rf "$dir" && mkdir -p "$dir"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# --version and --help
"$pdp" --version | grep -q "^pdp [0-9]" || fail "--version"
help=$("$pdp" synth --help)
for field in velocity tu tu-y tu-z time-scale rho-xz void-fraction bubble-diameter dx dy dz fs duration seed; do
  grep -q -- "--$field " <<<"$help" || fail "--help does not list --$field"
done
grep -q "default: 3mm" <<<"$help" || fail "--help shows no default for bubble-diameter"
grep -q "default: 500kHz" <<<"$help" || fail "--help shows no default for fs"

# A good run: units on the command line, a summary on stdout, file and sidecar.
out=$("$pdp" --log-level warn synth --duration 0.2s --fs 100kHz --dx 5mm -o "$dir/ok.flac") || fail "good run exited non-zero"
grep -q "Synthetic probe truth" <<<"$out" || fail "no truth summary on stdout"
[[ -s $dir/ok.flac && -s $dir/ok.truth.json ]] || fail "good run wrote no file or no sidecar"
for key in imposed realised mean_velocity turbulence_intensity integral_time_scale void_fraction bubbles_pierced; do
  grep -q "\"$key\"" "$dir/ok.truth.json" || fail "sidecar lacks $key"
done

# TOML with a command-line override.
cat >"$dir/scene.toml" <<'TOML'
fs = "50kHz"
duration = "1s"
bubble-diameter = "2mm"
TOML
"$pdp" --log-level warn synth -q --config "$dir/scene.toml" --duration 0.1s -o "$dir/cfg.wav" || fail "config run"
grep -q '"duration": 0.1' "$dir/cfg.truth.json" || fail "CLI did not override the TOML duration"
grep -q '"fs": 50000' "$dir/cfg.truth.json" || fail "TOML fs not applied"
grep -q '"bubble_diameter": 0.002' "$dir/cfg.truth.json" || fail "TOML bubble-diameter not applied"

# Same seed, same bytes.
"$pdp" --log-level warn synth -q --duration 0.2s --fs 100kHz --dx 5mm -o "$dir/ok2.flac"
cmp -s "$dir/ok.flac" "$dir/ok2.flac" || fail "same seed gave different files"

# Bad input: each must name the field, exit non-zero and write nothing.
expect_refusal() {  # name, expected message fragment, pdp arguments...
  local name=$1 fragment=$2
  shift 2
  local target="$dir/$name.flac"
  local err
  err=$("$pdp" synth -q "$@" -o "$target" 2>&1 >/dev/null)
  local status=$?
  [[ $status -ne 0 ]] || fail "$name: exit status 0"
  grep -q -- "$fragment" <<<"$err" || fail "$name: message lacks '$fragment': $err"
  [[ ! -e $target && ! -e $dir/$name.truth.json ]] || fail "$name: wrote a file"
  ls -a "$dir" | grep -q partial && fail "$name: left a temporary file"
}
expect_refusal big_c "void-fraction" --void-fraction 0.995
expect_refusal zero_size "bubble-diameter" --bubble-diameter 0mm
expect_refusal neg_size "bubble-diameter" --bubble-diameter -3mm
expect_refusal zero_fs "fs" --fs 0
expect_refusal same_tips "same point" --dx 0 --dy 0
expect_refusal too_short "shorter than one sample" --duration 1us
expect_refusal bad_unit "--dx" --dx 5kg
expect_refusal bad_rho "positive definite" --rho-xy 0.9 --rho-xz 0.9 --rho-yz -0.9
expect_refusal euler "euler is unstable" --velocity-update euler --realisation-step 0.3s --duration 1s
expect_refusal flac_fast "655350" --fs 2MHz --duration 0.01s
printf 'velocity = "fast"\n' >"$dir/bad.toml"
expect_refusal bad_toml "bad.toml:1" --config "$dir/bad.toml"
err=$("$pdp" synth -q --duration 0.1s -o "$dir/x.mp3" 2>&1) && fail "unknown extension accepted"
grep -q "extension" <<<"$err" || fail "unknown extension: $err"
[[ ! -e $dir/x.mp3 ]] || fail "unknown extension wrote a file"

# Samples: the four-tip scene runs.
"$pdp" --log-level warn synth -q --config "$src/samples/four-tip.toml" --duration 0.2s -o "$dir/four.w64" || fail "four-tip sample"
grep -q '"pierced_by_both"' "$dir/four.truth.json" || fail "four-tip sidecar"

# The truth per bubble: off by default, on with --bubble-truth or a settings
# key; the CSV beside the sidecar, which names it and states the IAC truth.
[[ ! -e $dir/four.truth.bubbles.csv ]] || fail "a bubble table without bubble-truth"
grep -q '"bubble_truth": null' "$dir/four.truth.json" || fail "sidecar: bubble_truth is not null when off"
grep -q -- "--bubble-truth" <<<"$help" || fail "--help does not list --bubble-truth"
"$pdp" --log-level warn synth -q --config "$src/samples/four-tip.toml" --duration 0.5s --bubble-truth \
  -o "$dir/bt.flac" || fail "bubble-truth run"
csv=$dir/bt.truth.bubbles.csv
[[ -s $csv ]] || fail "no bubble table beside the sidecar"
head -1 "$csv" | grep -q "^id,diameter,.*,tip3_rear_normal_z$" || fail "bubble table header: $(head -1 "$csv")"
python3 - "$dir/bt.truth.json" "$csv" <<'PY' || fail "sidecar and table disagree"
import csv, json, sys
j = json.load(open(sys.argv[1]))
rows = list(csv.DictReader(open(sys.argv[2])))
assert j["bubble_truth"]["file"] == "bt.truth.bubbles.csv", j["bubble_truth"]
assert j["bubble_truth"]["bubbles"] == len(rows) > 0
for k, pierced in enumerate(j["realised"]["bubbles_pierced"]):
    assert sum(r[f"tip{k}_pierced"] == "1" for r in rows) == pierced, k
    assert j["realised"]["interfacial_area"][k] > 0
assert abs(j["imposed"]["interfacial_area"] - 6 * 0.1 / 4e-3) < 1e-9
PY
printf 'duration = "0.2s"\nbubble-truth = true\n' >"$dir/bt.toml"
"$pdp" --log-level warn synth -q --config "$dir/bt.toml" -o "$dir/bt2.wav" || fail "bubble-truth from a settings file"
[[ -s $dir/bt2.truth.bubbles.csv ]] || fail "bubble-truth = true in a settings file wrote no table"

# The spray region (issue 31): above c = 0.5 the tips pierce water droplets at
# 1 - c and air is the continuous phase; pdp process reads the record as a
# spray signal (flagged, not refused) and recovers c within its interval
# (equal-space arrivals: the expectation is c itself).
out=$("$pdp" --log-level warn synth --void-fraction 0.9 --duration 4s --fs 100kHz --bubble-diameter 6mm --dy 0 \
  --tu 0.05 --tu-y 0.025 --tu-z 0.025 --time-scale 1s --arrival equal-space -o "$dir/spray.flac") || fail "spray run"
grep -q "spray region" <<<"$out" || fail "spray: the summary does not say it is a spray region"
grep -q "droplets pierced" <<<"$out" || fail "spray: the summary does not count droplets"
grep -q '"dispersed_phase": "droplets"' "$dir/spray.truth.json" || fail "spray sidecar: dispersed_phase"
grep -q '"dispersed_phase": "bubbles"' "$dir/ok.truth.json" || fail "bubbly sidecar: dispersed_phase"
"$pdp" --log-level warn process "$dir/spray.flac" --dx 5mm --json "$dir/spray.json" >/dev/null 2>&1 ||
  fail "pdp process on the spray record"
python3 - "$dir/spray.truth.json" "$dir/spray.json" <<'PY' || fail "spray: processed c and the signal flag"
import json, sys
truth = json.load(open(sys.argv[1]))
result = json.load(open(sys.argv[2]))
for k, tip in enumerate(result["tips"]):
    assert tip["void_fraction"] == truth["realised"]["void_fraction"][k], (tip["void_fraction"], k)
    low, high = tip["void_fraction_ci95"]
    assert low <= 0.9 <= high, (low, high)
    assert tip["signal"]["status"] == "air_continuous", tip["signal"]
assert any(f == "signal_check" for f in result["flags"]), result["flags"]
assert result["awcc"]["status"] == "ok" and abs(result["awcc"]["velocity"] / truth["realised"]["mean_velocity"][0] - 1) < 0.02
PY

if ((failures)); then
  echo "$failures failures"
  exit 1
fi
echo "pdp synth CLI: all checks passed"

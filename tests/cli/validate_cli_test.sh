#!/usr/bin/env bash
# pdp validate and pdp compare: tables, JSON keys, repetitions, bad input.
# Usage: validate_cli_test.sh PDP SCRATCH_DIR
set -u
pdp=$1
dir=$2/validate_cli
rm -rf "$dir" && mkdir -p "$dir"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

out=$("$pdp" validate --duration 5s --fs 100kHz --json "$dir/one.json") || fail "validate"
for text in "mean velocity" "turbulence intensity" "void fraction" "bubble count rate" "d32" "window level" \
  "true window velocity, accepted" "true window velocity, rejected"; do
  grep -q "$text" <<<"$out" || fail "validate table lacks '$text'"
done
for key in truth fscc awcc error windows velocity turbulence_intensity void_fraction bubble_count_rate d32; do
  grep -q "\"$key\"" "$dir/one.json" || fail "validate JSON lacks $key"
done
out=$("$pdp" validate --duration 2s --fs 100kHz --repeat 3 --json "$dir/three.json") || fail "validate --repeat"
grep -q "95 % interval" <<<"$out" || fail "repeat table"
grep -q '"repeat": 3' "$dir/three.json" || fail "repeat JSON"
grep -q '"ci95"' "$dir/three.json" || fail "repeat JSON intervals"
# Same seed, same numbers.
a=$("$pdp" validate --duration 2s --fs 100kHz | head -3)
b=$("$pdp" validate --duration 2s --fs 100kHz | head -3)
[[ "$a" == "$b" ]] || fail "validate is not reproducible"

"$pdp" validate --void-fraction 0.995 -o /dev/null >/dev/null 2>&1 && fail "bad option accepted"
err=$("$pdp" validate --void-fraction 0.995 2>&1) && fail "bad scene accepted"
grep -q "void-fraction" <<<"$err" || fail "bad scene message: $err"

# Fewer than two distinct tips: a validation error naming tips, exit status 2.
err=$("$pdp" validate --tips 0,0,0 --duration 1s 2>&1)
status=$?
[[ $status -eq 2 ]] || fail "one tip: exit status $status, expected 2: $err"
grep -q "tips: the scene has 1 tip; FSCC and AWCC need two" <<<"$err" || fail "one tip: message lacks tips: $err"
err=$("$pdp" validate --tips "0,0,0;0,0,0" --duration 1s 2>&1)
status=$?
[[ $status -eq 2 ]] || fail "two tips at one point: exit status $status, expected 2: $err"
grep -q "tips: tips 0 and 1 are at the same point" <<<"$err" || fail "two tips at one point: message: $err"
"$pdp" validate --tips "0,0,0;5mm,0,0" --duration 1s --fs 100kHz >/dev/null 2>&1 || fail "two distinct tips refused"

out=$("$pdp" compare --duration 3s --fs 100kHz) || fail "compare scene"
for text in "velocity (m/s)" "turbulence intensity" "R12max" "windows kept" "run time"; do
  grep -q "$text" <<<"$out" || fail "compare lacks '$text'"
done
"$pdp" --log-level warn synth -q --duration 2s --fs 100kHz -o "$dir/rec.flac" || fail "synth"
out=$("$pdp" compare "$dir/rec.flac" --rec-dx 5mm) || fail "compare recording"
grep -q "windows kept" <<<"$out" || fail "compare recording output"
"$pdp" compare "$dir/rec.flac" 2>/dev/null && fail "compare without dx accepted"

if ((failures)); then
  echo "$failures failures"
  exit 1
fi
echo "pdp validate/compare CLI: all checks passed"

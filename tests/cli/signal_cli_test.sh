#!/usr/bin/env bash
# The signal check end to end (issue 29, case 2 "Noise read as flow"): a UQ
# .dat of Gaussian noise, as a disconnected probe records, and a real
# recording with its sign inverted are refused with exit 1, naming the file,
# the tip, what was seen and the fix, and no output is written;
# --allow-bad-signal (declared once, also a settings key) processes them with
# the failure in the JSON, the CSV and on stderr.
# Usage: signal_cli_test.sh PDP SCRATCH_DIR SOURCE_DIR
set -u
source "$(dirname "$0")/lib.sh"
pdp=$1 dir=$2/signal_cli data=$3/../shared/data/felder-stepped-spillway
rm -rf "$dir" && mkdir -p "$dir"
py() { /usr/bin/python3 "$@"; }

# 200,000 frames of two channels of Gaussian noise (sigma 6000 counts, 0.92 V).
py - "$dir/noise.dat" <<'PY' || fail "writing the noise .dat"
import random, struct, sys
rng = random.Random(7)
rows = 200000
clip = lambda v: max(-32768, min(32767, int(round(v))))
counts = [clip(rng.gauss(0.0, 6000.0)) for _ in range(2 * rows)]
with open(sys.argv[1], "wb") as f:
    f.write(struct.pack("<ii", rows, 2))
    f.write(struct.pack("<%dh" % len(counts), *counts))
PY

# Refused: exit 1, the file, the tip, what was seen, the override; no output.
expect 1 "noise.dat: channel 0 (leading tip): the voltage histogram has no flat level" \
  "$pdp" process "$dir/noise.dat" --fs 20kHz --dx 7.15mm --json "$dir/noise.json" --csv "$dir/noise.csv"
expect 1 "channel 1 (trailing tip) likewise; to process it anyway, with the failure in every output, allow a bad signal (--allow-bad-signal)" \
  "$pdp" process "$dir/noise.dat" --fs 20kHz --dx 7.15mm --json "$dir/noise.json" --csv "$dir/noise.csv"
[[ -e $dir/noise.json || -e $dir/noise.csv ]] && fail "an output was written for a noise recording"

# Allowed: processed, the failure in the JSON (per tip and in the warnings), the CSV and stderr.
err=$("$pdp" process "$dir/noise.dat" --fs 20kHz --dx 7.15mm --allow-bad-signal --json "$dir/noise.json" \
  --csv "$dir/noise.csv" 2>&1 >/dev/null) || fail "--allow-bad-signal refused: $err"
grep -q "channel 0 (leading tip): the voltage histogram has no flat level.*processed anyway, as allow-bad-signal asks" \
  <<<"$err" || fail "stderr lacks the overridden failure: $err"
py - "$dir/noise.json" <<'PY' || fail "the JSON lacks the overridden check"
import json, sys
j = json.load(open(sys.argv[1]))
for t in j["tips"]:
    s = t["signal"]
    assert s["status"] == "no_flat_level" and s["overridden"] is True, s
    assert s["flatness"] < 0.2, s
assert len(j["warnings"]) == 2 and "no flat level" in j["warnings"][0], j["warnings"]
PY
grep -q "no flat level" <(column "$dir/noise.csv" warnings) || fail "the CSV warnings column lacks the failure"

# The override is a declared option: a settings file's key too.
printf 'allow-bad-signal = "on"\n' >"$dir/allow.toml"
"$pdp" --log-level error process "$dir/noise.dat" --fs 20kHz --dx 7.15mm --config "$dir/allow.toml" >/dev/null ||
  fail "allow-bad-signal in a settings file"
"$pdp" process --help | grep -q -- "--allow-bad-signal" || fail "pdp process --help lacks --allow-bad-signal"

# Inverted polarity: a real recording with its sign inverted gives c = 0.96 as
# a conductivity probe's; refused naming both fixes. Stated optical (air the
# high level) it is the bubbly recording again, without a word.
if [[ -d $data ]]; then
  py - "$data/dc157_05.dat" "$dir/negated.dat" <<'PY' || fail "writing the negated .dat"
import struct, sys, array
raw = open(sys.argv[1], "rb").read()
counts = array.array("h", raw[8:])
counts = array.array("h", (-v for v in counts))
open(sys.argv[2], "wb").write(raw[:8] + counts.tobytes())
PY
  expect 1 "negated.dat: channel 0 (leading tip): the polarity contradicts probe = conductivity" \
    "$pdp" process "$dir/negated.dat" --fs 20kHz --dx 7.15mm --json "$dir/negated.json"
  expect 1 "(--probe/--allow-bad-signal)" "$pdp" process "$dir/negated.dat" --fs 20kHz --dx 7.15mm
  [[ -e $dir/negated.json ]] && fail "an output was written for an inverted recording"
  err=$("$pdp" process "$dir/negated.dat" --fs 20kHz --dx 7.15mm --probe optical --json "$dir/optical.json" 2>&1 >/dev/null) ||
    fail "the inverted recording stated optical is refused: $err"
  [[ -z $err ]] || fail "the inverted recording stated optical gives a word: $err"
  py -c "import json,sys; c=json.load(open(sys.argv[1]))['tips'][0]['void_fraction']; assert abs(c-0.0375)<2e-3, c" \
    "$dir/optical.json" || fail "stated optical, c is not the bubbly one"
else
  echo "signal_cli_test.sh: $data absent: the inverted-polarity checks are skipped"
fi

[[ $failures -eq 0 ]] && echo "signal_cli_test.sh: all passed"
exit $((failures > 0))

#!/usr/bin/env bash
# Writes the golden outputs of pdp into OUT_DIR: pdp process on the ten real
# recordings (profile JSON and CSV, one recording's JSON and window table),
# pdp validate on three scenes, pdp correct on a profile (CSV and JSON) and a
# small pdp sweep. golden_test.sh compares a fresh run with the committed
# copies in tests/golden/expected/ (recorded before the restructure of issue
# 11); compare.py says what "unchanged" means.
# Usage: record.sh PDP SOURCE_DIR OUT_DIR
set -euo pipefail
pdp=$1
src=$2
out=$3
mkdir -p "$out"
data=$src/../shared/data/felder-stepped-spillway
model=$src/samples/model/awcc.qrf

# Synthetic: validate on three scenes and a small sweep (no real data needed).
"$pdp" --log-level error validate --config "$src/samples/base.toml" --duration 8s --json "$out/validate-base.json" >/dev/null
"$pdp" --log-level error validate --config "$src/samples/small-bubbles.toml" --duration 8s --json "$out/validate-small-bubbles.json" >/dev/null
"$pdp" --log-level error validate --config "$src/samples/high-tu.toml" --duration 8s --repeat 2 --json "$out/validate-high-tu.json" >/dev/null
rm -f "$out/sweep.csv"
"$pdp" --log-level error sweep "$src/tests/golden/sweep.toml" -o "$out/sweep.csv" --threads 2

# Real recordings: skipped (with a message) where ../shared/data is absent.
if [[ ! -d $data ]]; then
  echo "record.sh: $data absent: real-recording golden outputs skipped" >&2
  exit 0
fi
files=("$data"/dc157_*.dat)
"$pdp" --log-level error process "${files[@]}" --fs 20kHz --dx 7.15mm --dy 0mm --method both \
  --positions 2mm,8mm,14mm,20mm,26mm,32mm,38mm,44mm,50mm,54mm --json "$out/profile.json" --csv "$out/profile.csv"
"$pdp" --log-level error process "$data/dc157_07.dat" --fs 20kHz --dx 7.15mm --method both \
  --json "$out/process-07.json" --windows "$out/windows-07.csv" >/dev/null
"$pdp" --log-level error process "$data/dc157_03.dat" --fs 20kHz --dx 7.15mm --method both --correlate raw \
  --segments 15 --felder-lags --threshold-rule felder --json "$out/process-03-felder-raw.json" >/dev/null
"$pdp" --log-level error correct "$out/profile.csv" -m "$model" --dx 7.15mm --dy 0mm --np 10 -o "$out/corrected.csv"
"$pdp" --log-level error correct "$out/profile.json" -m "$model" --np 10 -o "$out/corrected.json"

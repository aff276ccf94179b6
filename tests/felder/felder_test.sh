#!/usr/bin/env bash
# Felder parity (issue 13): pdp process --preset felder against the printed
# outputs of Felder's program for files 01-05 (length and time modes), every
# number to its printed digits (compare_felder.py).
# Usage: felder_test.sh PDP SCRATCH_DIR SOURCE_DIR
set -euo pipefail
pdp=$1
dir=$2/felder
src=$3
data=$src/../shared/data/felder-stepped-spillway
if [[ ! -d $data/program-output-01-05 ]]; then
  echo "felder_test.sh: SKIPPED: $data/program-output-01-05 is absent (CI has ../shared/data beside the repository)" >&2
  exit 77
fi
rm -rf "$dir" && mkdir -p "$dir"
/usr/bin/python3 "$src/tests/felder/compare_felder.py" "$pdp" "$data" "$data/program-output-01-05" "$dir" \
  dc157_01.dat:y002 dc157_02.dat:y008 dc157_03.dat:y014 dc157_04.dat:y020 dc157_05.dat:y026

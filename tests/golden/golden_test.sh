#!/usr/bin/env bash
# The golden-output test of issue 11: a fresh record.sh run against the
# committed outputs recorded before the restructure (compare.py says what
# "unchanged" means; changes.txt lists each value changed on purpose).
# Usage: golden_test.sh PDP SCRATCH_DIR SOURCE_DIR
set -euo pipefail
pdp=$1
dir=$2/golden
src=$3
rm -rf "$dir" && mkdir -p "$dir/actual" "$dir/expected"
bash "$src/tests/golden/record.sh" "$pdp" "$src" "$dir/actual"
cp "$src"/tests/golden/expected/* "$dir/expected/"
if [[ ! -d $src/../shared/data/felder-stepped-spillway ]]; then
  echo "golden_test.sh: ../shared/data absent: only the synthetic outputs are compared" >&2
  for f in "$dir"/expected/*; do [[ -e $dir/actual/$(basename "$f") ]] || rm "$f"; done
fi
/usr/bin/python3 "$src/tests/golden/compare.py" "$dir/expected" "$dir/actual"

#!/usr/bin/env bash
# Usage: run.sh BUILD_DIR SCRATCH CONSUMER_SOURCE CMAKE [EXTRA_FLAGS]
set -euo pipefail
build=$1 scratch=$2 source=$3 cmake=$4 flags=${5:-}
rm -rf "$scratch" && mkdir -p "$scratch"
"$cmake" --install "$build" --prefix "$scratch/prefix" >/dev/null
test -x "$scratch/prefix/bin/pdp"
test -f "$scratch/prefix/include/awcc/version.hpp"
"$cmake" -S "$source" -B "$scratch/build" -DCMAKE_PREFIX_PATH="$scratch/prefix" -DCMAKE_BUILD_TYPE=Release \
  -DCMAKE_CXX_FLAGS="$flags" -DCMAKE_EXE_LINKER_FLAGS="$flags" >/dev/null
"$cmake" --build "$scratch/build" >/dev/null
"$scratch/build/consumer" "$scratch"
test ! -e "$scratch/prefix/include/awcc/detail" || { echo "detail headers were installed"; exit 1; }
"$scratch/prefix/bin/pdp" --version
# pdp report finds the installed Python module beside the installed pdp
# (not in a sanitizer build, whose module the interpreter cannot load).
if [[ -z "$flags" ]] && find "$scratch/prefix" -path '*/pdp/report.py' | grep -q .; then
  "$scratch/prefix/bin/pdp" --log-level error synth -o "$scratch/scene.flac" --duration 2s --fs 50kHz -q
  "$scratch/prefix/bin/pdp" --log-level error process "$scratch/scene.flac" --dx 5mm --json "$scratch/scene.json" \
    >/dev/null
  (cd "$scratch" && env -u PYTHONPATH "$scratch/prefix/bin/pdp" report scene.json -o scene.html 2>/dev/null)
  grep -q 'data-figure="velocity"' "$scratch/scene.html"
fi

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

#!/usr/bin/env bash
# pdp sweep's engine on two threads gives the rows of one thread: the short
# check of the sweep engine that also runs under ThreadSanitizer (the test
# preset "tsan"), where cli.sweep's kills and MPI runs would take too long.
# Usage: sweep_threads_test.sh PDP SCRATCH_DIR
set -u
pdp=$1
dir=$2/sweep_threads
rm -rf "$dir" && mkdir -p "$dir"
source "$(dirname "$0")/lib.sh"
cat >"$dir/grid.toml" <<'TOML'
[sweep]
mode = "grid"
repeat = 2
seed = 5
[base]
duration = "1s"
fs = "50kHz"
np = 10
[grid]
tu = [0.1, 0.3]
dy = ["0mm", "1mm"]
TOML
"$pdp" --log-level warn sweep "$dir/grid.toml" -o "$dir/two.csv" --threads 2 || fail "sweep, 2 threads"
"$pdp" --log-level warn sweep "$dir/grid.toml" -o "$dir/one.csv" --threads 1 || fail "sweep, 1 thread"
[[ $(($(wc -l <"$dir/two.csv") - 1)) -eq 8 ]] || fail "expected 8 rows"
[[ "$(sweep_rows "$dir/one.csv")" == "$(sweep_rows "$dir/two.csv")" ]] || fail "1 and 2 threads differ"
((failures == 0)) && echo "sweep_threads_test: ok"
exit $((failures > 0))

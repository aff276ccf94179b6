#!/usr/bin/env bash
# The plotting script renders a figure from a bench CSV made by pdp bench,
# and one from a sweep CSV made by pdp sweep: both PNG files must exist and
# be PNG images.
# Usage: plot_test.sh PDP SCRATCH_DIR SOURCE_DIR
set -u
pdp=$1
dir=$2/plot
src=$3
rm -rf "$dir" && mkdir -p "$dir"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
png() { [[ -s $1 && $(head -c 8 "$1" | od -An -c | tr -d ' ') == '211PNG\r\n032\n' ]]; }

"$pdp" --log-level warn bench --quick --scenes base,low-c -o "$dir/bench.csv" || fail "pdp bench --quick"
/usr/bin/python3 "$src/tools/plot_study.py" bench "$dir/bench.csv" "$dir/bench.png" >"$dir/bench.md" || fail "bench figure"
png "$dir/bench.png" || fail "bench figure is not a PNG"
grep -q '^| low-c |' "$dir/bench.md" || fail "bench: no decision line for the low-c scene"
/usr/bin/python3 "$src/tools/plot_study.py" bench-bias "$dir/bench.csv" "$dir/bench-bias.png" || fail "bench-bias figure"
png "$dir/bench-bias.png" || fail "bench-bias figure is not a PNG"
# Same seeds, same numbers, whatever the thread count (the cost column aside).
"$pdp" --log-level warn bench --quick --scenes base,low-c --threads 1 -o "$dir/bench1.csv" || fail "pdp bench --threads 1"
[[ $(cut -d, -f1-6,8- "$dir/bench.csv") == $(cut -d, -f1-6,8- "$dir/bench1.csv") ]] || fail "bench: numbers depend on threads"

cat >"$dir/grid.toml" <<'TOML'
[sweep]
mode = "grid"
repeat = 2
seed = 5
[base]
duration = "2s"
fs = "100kHz"
[grid]
tu = [0.1, 0.2]
TOML
"$pdp" --log-level warn sweep "$dir/grid.toml" -o "$dir/runs.csv" || fail "sweep"
/usr/bin/python3 "$src/tools/plot_study.py" sweep "$dir/runs.csv" tu "$dir/tu.png" || fail "sweep figure"
png "$dir/tu.png" || fail "sweep figure is not a PNG"
/usr/bin/python3 "$src/tools/plot_study.py" sweep "$dir/runs.csv" no_such_column "$dir/x.png" 2>/dev/null &&
  fail "unknown column accepted"

if ((failures)); then
  echo "$failures failures"
  exit 1
fi
echo "plots: all checks passed"

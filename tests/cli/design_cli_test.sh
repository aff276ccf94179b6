#!/usr/bin/env bash
# pdp design: the same ranking whatever the thread count, sharding or MPI
# ranks; an interrupted design (a record cut short) resumes to the same
# ranking; the summary names the recommendation and the current probe; bad
# designs are refused naming the table and key, with no output.
# Usage: design_cli_test.sh PDP SCRATCH_DIR SOURCE_DIR
set -u
pdp=$1
dir=$2/design_cli
src=$3
rm -rf "$dir" && mkdir -p "$dir"
source "$src/tests/cli/lib.sh"

cat >"$dir/flow.toml" <<'TOML'
[design]
seeds = 3
seed = 5
[conditions.upper]
velocity = "6m/s"
tu = 0.2
void-fraction = 0.2
bubble-diameter = "3mm"
time-scale = "50ms"
[conditions.wall]
velocity = ["2m/s", "3m/s"]
tu = [0.1, 0.2]
void-fraction = [0.03, 0.08, "log"]
bubble-diameter = "2mm"
time-scale = "20ms"
[candidates]
dx = ["2mm", "6mm"]
dy = ["0mm", "1mm"]
np = [5, 10]
fs = ["50kHz"]
duration = ["5s"]
[current]
dx = "6mm"
dy = "1mm"
np = 10
fs = "50kHz"
duration = "5s"
TOML

# The ranking without the measured CPU seconds (which differ from run to run).
ranking() { cut -d, -f1-13,15- "$1"; }

"$pdp" --log-level warn design --config "$dir/flow.toml" -o "$dir/one.csv" --threads 1 >"$dir/one.txt" ||
  fail "design, one thread"
"$pdp" design --config "$dir/flow.toml" -o "$dir/two.csv" --threads 2 >"$dir/two.txt" 2>"$dir/two.log" ||
  fail "design, two threads"
[[ $(wc -l <"$dir/one.csv") -eq $((1 + 8 * 2)) ]] || fail "ranked CSV: not 8 candidates x 2 conditions"
[[ "$(ranking "$dir/one.csv")" == "$(ranking "$dir/two.csv")" ]] || fail "the ranking depends on the thread count"
[[ $(wc -l <"$dir/one.runs.csv") -eq $((1 + 2 * 3 * 8)) ]] || fail "runs CSV: not 6 records x 8 pairs"
grep -q "about .* on 2 threads" "$dir/two.log" || fail "no time estimate before starting: $(cat "$dir/two.log")"
grep -q "^Recommended: dx" "$dir/one.txt" || fail "summary: no recommendation: $(cat "$dir/one.txt")"
grep -q "^Current probe: dx 6 mm, dy 1 mm, Np 10" "$dir/one.txt" || fail "summary: no current probe"
grep -q "raw AWCC" "$dir/one.txt" || fail "summary: without a model it must say the ranking is of raw AWCC"
# Without a model, the corrected columns are the raw ones.
[[ "$(column "$dir/one.csv" u_rms)" == "$(column "$dir/one.csv" raw_u_rms)" ]] || fail "no model: u_rms is not raw"
# The recommended candidate is the first row, and it has the least objective.
py() { /usr/bin/python3 "$@"; }
py - "$dir/one.csv" <<'PY' || fail "ranked CSV is not sorted by failures, then objective"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
keys = [(int(r["failures"]), float(r["objective"])) for r in rows]
assert keys == sorted(keys), keys
assert rows[0]["rank"] == "1"
cur = [r for r in rows if r["current"] == "1"]
assert cur and cur[0]["dx"] == "0.006" and cur[0]["dy"] == "0.001" and cur[0]["np"] == "10", cur[:1]
PY

# Resume: the last record cut short (its rows partly written, the last line
# partial) runs again and the ranking is the same; a complete file runs nothing.
cp "$dir/flow.toml" "$dir/cut.toml"
"$pdp" --log-level error design --config "$dir/cut.toml" -o "$dir/cut.csv" --threads 2 >/dev/null || fail "cut: first run"
head -n 45 "$dir/cut.runs.csv" >"$dir/x" && head -c 40 <(sed -n 46p "$dir/cut.runs.csv") >>"$dir/x" && mv "$dir/x" "$dir/cut.runs.csv"
"$pdp" design --config "$dir/cut.toml" -o "$dir/cut.csv" --threads 2 >/dev/null 2>"$dir/cut.log" || fail "resume"
grep -q "cut short by an interruption" "$dir/cut.log" || fail "resume: the partial record is not named"
[[ $(wc -l <"$dir/cut.runs.csv") -eq $((1 + 6 * 8)) ]] || fail "resume: $(wc -l <"$dir/cut.runs.csv") lines in the runs file"
[[ "$(ranking "$dir/cut.csv")" == "$(ranking "$dir/one.csv")" ]] || fail "resumed ranking differs"
"$pdp" design --config "$dir/cut.toml" -o "$dir/cut.csv" 2>"$dir/again.log" >/dev/null || fail "complete rerun"
grep -q "(6 in" "$dir/again.log" || fail "complete rerun: records not found done: $(cat "$dir/again.log")"

# Shards: each its own runs file, then all together give the same ranking.
"$pdp" --log-level warn design --config "$dir/flow.toml" -o "$dir/s.csv" --shard 0/2 --runs "$dir/s0.csv" >/dev/null ||
  fail "shard 0"
[[ -e "$dir/s.csv" ]] && fail "shard 0 alone wrote a ranking"
"$pdp" --log-level warn design --config "$dir/flow.toml" -o "$dir/s.csv" --shard 1/2 --runs "$dir/s1.csv" >/dev/null ||
  fail "shard 1"
"$pdp" --log-level warn design --config "$dir/flow.toml" -o "$dir/s.csv" --runs "$dir/s0.csv" --runs "$dir/s1.csv" \
  >/dev/null || fail "shards together"
[[ "$(ranking "$dir/s.csv")" == "$(ranking "$dir/one.csv")" ]] || fail "sharded ranking differs"

# MPI: a writer and a worker give the threaded ranking.
if "$pdp" --version | grep -q MPI; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm_rsh_agent=
  export ASAN_OPTIONS="${ASAN_OPTIONS:-}:detect_leaks=0"
  mpirun --oversubscribe -np 2 "$pdp" --log-level warn design --config "$dir/flow.toml" -o "$dir/mpi.csv" \
    >"$dir/mpi.txt" 2>&1 || fail "mpirun design: $(tail -5 "$dir/mpi.txt")"
  [[ "$(ranking "$dir/mpi.csv")" == "$(ranking "$dir/one.csv")" ]] || fail "MPI ranking differs"
fi

# A changed definition does not mix with the old rows.
sed 's/seed = 5/seed = 6/' "$dir/flow.toml" >"$dir/other.toml"
expect 1 "a row of another design" "$pdp" design --config "$dir/other.toml" -o "$dir/one.csv" --runs "$dir/one.runs.csv"

# A file that is not a model, or not a runs file of pdp design: exit 1, the file named, nothing written.
printf 'not a model\n' >"$dir/junk.qrf"
expect 1 "junk.qrf: not a pdp model file" "$pdp" design --config "$dir/flow.toml" -o "$dir/junk.csv" --model "$dir/junk.qrf"
printf 'a,b\n1,2\n' >"$dir/foreign.csv"
expect 1 "not the runs file of pdp design" "$pdp" design --config "$dir/flow.toml" -o "$dir/junk.csv" --runs "$dir/foreign.csv"
[[ -e "$dir/junk.csv" ]] && fail "a refused design wrote its ranking"

# Bad designs: exit 2, the table and key named, nothing written.
printf '[conditions.a]\ntu = 0.2\ndx = "5mm"\n' >"$dir/bad.toml"
expect 2 "[conditions.a] dx" "$pdp" design --config "$dir/bad.toml" -o "$dir/bad.csv"
printf '[conditions.a]\ntu = 0.2\nvelocity = "0m/s"\n' >"$dir/bad3.toml"
expect 2 "condition a record 0" "$pdp" design --config "$dir/bad3.toml" -o "$dir/bad.csv"
printf '[candidates]\nnp = [5]\n' >"$dir/bad2.toml"
expect 2 "give at least one condition" "$pdp" design --config "$dir/bad2.toml" -o "$dir/bad.csv"
[[ -e "$dir/bad.csv" || -e "$dir/bad.runs.csv" ]] && fail "a bad design wrote a file"

if ((failures)); then
  echo "$failures failures"
  exit 1
fi
echo "design CLI: all checks passed"

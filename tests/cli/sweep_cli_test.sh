#!/usr/bin/env bash
# pdp sweep: same rows whatever the thread count or sharding; an interrupted
# sweep (SIGKILL, or a partial last row) resumes to exactly the rows of an
# uninterrupted one; foreign or malformed CSVs and other studies are refused.
# Usage: sweep_cli_test.sh PDP SCRATCH_DIR
set -u
pdp=$1
dir=$2/sweep_cli
rm -rf "$dir" && mkdir -p "$dir"
source "$(dirname "$0")/lib.sh"

cat >"$dir/grid.toml" <<'TOML'
[sweep]
mode = "grid"
repeat = 2
seed = 11
[base]
duration = "3s"
fs = "100kHz"
np = 10
[grid]
tu = [0.1, 0.3]
bubble-diameter = ["2mm", "4mm"]
dy = ["0mm", "1mm"]
TOML

# canonical FILE: the rows that must not depend on threads, order or
# interruptions (lib.sh's sweep_rows).
canonical() { sweep_rows "$1"; }

"$pdp" --log-level warn sweep "$dir/grid.toml" -o "$dir/two.csv" --threads 2 || fail "sweep, 2 threads"
"$pdp" --log-level warn sweep "$dir/grid.toml" -o "$dir/one.csv" --threads 1 || fail "sweep, 1 thread"
[[ $(($(wc -l <"$dir/two.csv") - 1)) -eq 16 ]] || fail "expected 16 rows"
[[ "$(canonical "$dir/one.csv")" == "$(canonical "$dir/two.csv")" ]] || fail "1 and 2 threads differ"

# Shards appended to one file give the same rows.
"$pdp" --log-level warn sweep "$dir/grid.toml" -o "$dir/shards.csv" --shard 0/3 || fail "shard 0"
"$pdp" --log-level warn sweep "$dir/grid.toml" -o "$dir/shards.csv" --shard 2/3 || fail "shard 2"
"$pdp" --log-level warn sweep "$dir/grid.toml" -o "$dir/shards.csv" --shard 1/3 || fail "shard 1"
[[ "$(canonical "$dir/shards.csv")" == "$(canonical "$dir/two.csv")" ]] || fail "shards differ"

# --first-runs N runs the runs with index below N, and a later call without
# it resumes the rest: the same rows as one call.
"$pdp" --log-level warn sweep "$dir/grid.toml" -o "$dir/first.csv" --first-runs 5 || fail "first 5 runs"
[[ $(($(wc -l <"$dir/first.csv") - 1)) -eq 5 ]] || fail "--first-runs 5 wrote $(($(wc -l <"$dir/first.csv") - 1)) rows"
runcol=$(head -1 "$dir/first.csv" | tr ',' '\n' | grep -nx run | cut -d: -f1)
[[ "$(tail -n +2 "$dir/first.csv" | cut -d, -f"$runcol" | sort -n | tr '\n' ' ')" == "0 1 2 3 4 " ]] ||
  fail "--first-runs 5 ran other runs than 0-4"
"$pdp" --log-level warn sweep "$dir/grid.toml" -o "$dir/first.csv" || fail "the rest after --first-runs"
[[ "$(canonical "$dir/first.csv")" == "$(canonical "$dir/two.csv")" ]] || fail "--first-runs then the rest differ"

# Rerunning a finished sweep adds nothing.
"$pdp" --log-level warn sweep "$dir/grid.toml" -o "$dir/two.csv" || fail "rerun"
[[ $(($(wc -l <"$dir/two.csv") - 1)) -eq 16 ]] || fail "a rerun added rows"

# SIGKILL mid-sweep, then resume: the same rows as uninterrupted. The kills
# are timed by the rows in the CSV, not by the clock: a sweep is killed once
# it has finished a given number of rows, and the kill must land before the
# study's end. The runs of kill.toml are longer (20 s records) so that a
# kill after a row has time to land before the next rows.
sed 's/duration = "3s"/duration = "20s"/' "$dir/grid.toml" >"$dir/kill.toml"
total=16
"$pdp" --log-level warn sweep "$dir/kill.toml" -o "$dir/kill_ref.csv" --threads 2 || fail "kill study, uninterrupted"
[[ $(($(wc -l <"$dir/kill_ref.csv") - 1)) -eq $total ]] || fail "kill study: expected $total rows"

# Finished rows of a sweep CSV: complete lines less the header (a partial
# last line, cut by a kill, has no newline and is not counted).
rows() {
  local n=0
  [[ -f $1 ]] && n=$(wc -l <"$1")
  echo $((n > 0 ? n - 1 : 0))
}
# True while the process runs (not after it exited, even before it is reaped).
running() {
  if [[ -r /proc/$1/stat ]]; then
    [[ $(cut -d' ' -f3 "/proc/$1/stat" 2>/dev/null) != Z ]]
  else
    kill -0 "$1" 2>/dev/null
  fi
}
# Starts kill.toml into CSV in the background and SIGKILLs it as soon as the
# CSV holds at least WANT finished rows (polled; at most 60 s). Sets
# kill_status: "landed" (killed, and the CSV holds fewer than all rows),
# "late" (killed after the last row), "ended" (the sweep finished before the
# kill), "timeout" (WANT rows never came).
kill_after_rows() {  # CSV WANT
  local csv=$1 want=$2
  "$pdp" --log-level warn sweep "$dir/kill.toml" -o "$csv" --threads 2 &
  local pid=$! deadline=$((SECONDS + 60))
  while (($(rows "$csv") < want)) && running "$pid" && ((SECONDS < deadline)); do sleep 0.01; done
  local enough=$(($(rows "$csv") >= want))
  kill -9 "$pid" 2>/dev/null
  wait "$pid" 2>/dev/null
  local status=$?
  if ((!enough)); then
    kill_status=timeout
  elif ((status != 137)); then
    kill_status=ended
  elif (($(rows "$csv") >= total)); then
    kill_status=late
  else
    kill_status=landed
  fi
}

for want in 2 6 11; do
  rm -f "$dir/killed.csv"
  kill_after_rows "$dir/killed.csv" "$want"
  [[ $kill_status == landed ]] ||
    fail "kill after $want rows did not land mid-sweep ($kill_status, $(rows "$dir/killed.csv") of $total rows)"
  echo "killed after $(rows "$dir/killed.csv") of $total rows (waited for $want)"
  "$pdp" --log-level warn sweep "$dir/kill.toml" -o "$dir/killed.csv" || fail "resume after a kill at $want rows"
  [[ "$(canonical "$dir/killed.csv")" == "$(canonical "$dir/kill_ref.csv")" ]] ||
    fail "resume after a kill at $want rows differs"
done

# Many kills of one sweep, resuming each time into the same file: each kill
# comes after at least one new row and must land before the end; only when
# at most three runs are left once the row it waits for is written (two
# threads finish them together, and a loaded machine may delay the poll by
# one more run) may the sweep end first. Then a final resume: still exactly
# the uninterrupted rows.
rm -f "$dir/many.csv"
landed=0
for attempt in $(seq 1 "$total"); do
  before=$(rows "$dir/many.csv")
  ((before < total)) || break
  kill_after_rows "$dir/many.csv" $((before + 1))
  after=$(rows "$dir/many.csv")
  case $kill_status in
    landed) landed=$((landed + 1)) ;;
    late | ended)
      ((before + 1 >= total - 3)) || fail "kill $attempt (after row $((before + 1))) missed the sweep: $kill_status at $after rows"
      ;;
    *) fail "kill $attempt: no new row within 60 s ($after rows)" ;;
  esac
done
echo "many kills: $landed landed mid-sweep"
((landed >= 5)) || fail "only $landed kills landed mid-sweep"
"$pdp" --log-level warn sweep "$dir/kill.toml" -o "$dir/many.csv" || fail "final resume after $landed kills"
[[ "$(canonical "$dir/many.csv")" == "$(canonical "$dir/kill_ref.csv")" ]] || fail "$landed kills and resumes differ"

# A partial last row (a crash while writing) is cut off and redone.
head -n 5 "$dir/two.csv" >"$dir/partial.csv"
printf '%s' "$(sed -n 6p "$dir/two.csv" | cut -c1-40)" >>"$dir/partial.csv"
"$pdp" --log-level warn sweep "$dir/grid.toml" -o "$dir/partial.csv" || fail "resume after a partial row"
[[ "$(canonical "$dir/partial.csv")" == "$(canonical "$dir/two.csv")" ]] || fail "partial row resume differs"

# Refusals: a foreign CSV, a malformed row, another study; each left untouched.
printf 'a,b,c\n1,2,3\n' >"$dir/foreign.csv"
cp "$dir/foreign.csv" "$dir/foreign.orig"
err=$("$pdp" sweep "$dir/grid.toml" -o "$dir/foreign.csv" 2>&1) && fail "foreign CSV accepted"
grep -q "not a pdp sweep CSV" <<<"$err" || fail "foreign CSV message: $err"
cmp -s "$dir/foreign.csv" "$dir/foreign.orig" || fail "foreign CSV modified"
{ head -n 3 "$dir/two.csv"; echo "garbage,row"; } >"$dir/malformed.csv"
err=$("$pdp" sweep "$dir/grid.toml" -o "$dir/malformed.csv" 2>&1) && fail "malformed CSV accepted"
grep -q "malformed row" <<<"$err" || fail "malformed message: $err"
sed 's/seed = 11/seed = 12/' "$dir/grid.toml" >"$dir/other.toml"
err=$("$pdp" sweep "$dir/other.toml" -o "$dir/two.csv" 2>&1) && fail "another study appended"
grep -q "another study" <<<"$err" || fail "other study message: $err"
# Another generator version: a sweep of version 1 (written before the column
# generator_version) and a row of another version are refused, never resumed.
# (The version is the fifth column from the end: the time-scale ratio and the
# weighting gap's three follow it.)
gap=',awcc_weighting_gap,awcc_weighting_gap_ci95_lower,awcc_weighting_gap_ci95_upper'
sed "s/,generator_version,awcc_time_scale_ratio$gap\$//; 2,\$s/,[0-9]*,[^,]*,[^,]*,[^,]*,[^,]*\$//" "$dir/two.csv" >"$dir/version1.csv"
cp "$dir/version1.csv" "$dir/version1.orig"
err=$("$pdp" sweep "$dir/grid.toml" -o "$dir/version1.csv" 2>&1) && fail "a generator-version-1 sweep resumed"
grep -q "written by pdp's generator version 1" <<<"$err" || fail "version 1 message: $err"
cmp -s "$dir/version1.csv" "$dir/version1.orig" || fail "version-1 sweep modified"
{ head -n 2 "$dir/two.csv"; sed -n 3p "$dir/two.csv" | sed 's/,[0-9]*\(,[^,]*,[^,]*,[^,]*,[^,]*\)$/,1\1/'; } >"$dir/mixed.csv"
err=$("$pdp" sweep "$dir/grid.toml" -o "$dir/mixed.csv" 2>&1) && fail "a row of another generator version resumed"
grep -q "mixed.csv:3: the run was made by generator version '1'" <<<"$err" || fail "mixed version message: $err"
# A sweep of an earlier pdp (of this generator, before the weighting gap's
# columns): refused, never resumed, the missing columns named.
sed "s/$gap\$//; 2,\$s/,[^,]*,[^,]*,[^,]*\$//" "$dir/two.csv" >"$dir/earlier.csv"
cp "$dir/earlier.csv" "$dir/earlier.orig"
err=$("$pdp" sweep "$dir/grid.toml" -o "$dir/earlier.csv" 2>&1) && fail "a sweep of an earlier pdp resumed"
grep -q "written by an earlier pdp, whose rows end before the columns awcc_weighting_gap" <<<"$err" ||
  fail "earlier pdp message: $err"
cmp -s "$dir/earlier.csv" "$dir/earlier.orig" || fail "the earlier sweep modified"
printf '[sweep]\nmode = "grid"\n[grid]\nbubble-diameter = ["3 kg"]\n' >"$dir/bad.toml"
err=$("$pdp" sweep "$dir/bad.toml" -o "$dir/bad.csv" 2>&1) && fail "bad study accepted"
grep -q "bubble-diameter" <<<"$err" || fail "bad study message: $err"
[[ ! -e $dir/bad.csv ]] || fail "bad study wrote a file"

# MPI: two ranks (one writer, one worker) give the threaded result.
if "$pdp" --version | grep -q MPI; then
  export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_plm_rsh_agent=
  # Under the sanitizer build: OpenMPI's plugins (dlopened, then closed) hold
  # allocations LeakSanitizer cannot attribute; leak checks stay on elsewhere.
  export ASAN_OPTIONS="${ASAN_OPTIONS:-}:detect_leaks=0"
  mpirun --oversubscribe -np 2 "$pdp" --log-level warn sweep "$dir/grid.toml" -o "$dir/mpi.csv" >"$dir/mpi.log" 2>&1 ||
    fail "mpirun sweep: $(tail -5 "$dir/mpi.log")"
  [[ "$(canonical "$dir/mpi.csv")" == "$(canonical "$dir/two.csv")" ]] || fail "MPI sweep differs from the threaded one"
  mpirun --oversubscribe -np 3 "$pdp" --log-level warn sweep "$dir/grid.toml" -o "$dir/mpi3.csv" >"$dir/mpi3.log" 2>&1 ||
    fail "mpirun -np 3 sweep"
  [[ "$(canonical "$dir/mpi3.csv")" == "$(canonical "$dir/two.csv")" ]] || fail "3-rank MPI sweep differs"
else
  echo "MPI not built: skipping the mpirun checks"
fi

# Monte Carlo: the drawn scenes lie in the ranges and are reproducible.
cat >"$dir/mc.toml" <<'TOML'
[sweep]
mode = "monte-carlo"
runs = 6
seed = 3
[base]
duration = "1s"
fs = "100kHz"
[ranges]
velocity = ["2m/s", "20m/s"]
bubble-diameter = ["1mm", "5mm"]
fs = ["10kHz", "1MHz", "log"]
TOML
"$pdp" --log-level warn sweep "$dir/mc.toml" -o "$dir/mc1.csv" --threads 2 || fail "monte-carlo"
"$pdp" --log-level warn sweep "$dir/mc.toml" -o "$dir/mc2.csv" --threads 1 || fail "monte-carlo again"
[[ "$(canonical "$dir/mc1.csv")" == "$(canonical "$dir/mc2.csv")" ]] || fail "monte-carlo not reproducible"
python3 - "$dir/mc1.csv" <<'PY' || fail "monte-carlo values out of range"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert len(rows) == 6
for r in rows:
    assert 2 <= float(r["velocity"]) <= 20, r["velocity"]
    assert 1e-3 <= float(r["bubble_diameter"]) <= 5e-3, r["bubble_diameter"]
    assert 1e-3 <= float(r["time_scale"]) <= 1.0, r["time_scale"]
    assert 0.005 <= float(r["void_fraction"]) <= 0.4
    assert 1e4 <= float(r["fs"]) <= 1e6, r["fs"]
PY
# Log-uniform: of 400 draws over 10 kHz-1 MHz, half lie below 100 kHz (the
# geometric middle); uniform would put 9 %. Binomial sd 2.5 %: 35-65 % is 6 sd.
printf '[sweep]\nmode = "monte-carlo"\nruns = 400\nseed = 4\n[base]\nduration = "0.05s"\n[ranges]\nfs = ["10kHz", "1MHz", "log"]\n' >"$dir/log.toml"
"$pdp" --log-level error sweep "$dir/log.toml" -o "$dir/log.csv" || fail "log-uniform sweep"
python3 - "$dir/log.csv" <<'PY' || fail "fs not log-uniform"
import csv, sys
fs = [float(r["fs"]) for r in csv.DictReader(open(sys.argv[1]))]
assert len(fs) == 400 and all(1e4 <= f <= 1e6 for f in fs)
below = sum(f < 1e5 for f in fs) / len(fs)
assert 0.35 <= below <= 0.65, below
PY
# Choices: each run takes one of the listed values, each equally likely, and
# drawing them after the ranges leaves the ranged draws of every run as they
# were without choices. Of 400 runs, a value of four is taken 100 times on
# average, binomial sd sqrt(400 x 1/4 x 3/4) = 8.7: 60-140 is 4.6 sd; one of
# two, 200 +/- 10: 150-250 is 5 sd.
printf '[sweep]\nmode = "monte-carlo"\nruns = 400\nseed = 4\n[base]\nduration = "0.05s"\n[ranges]\nfs = ["10kHz", "1MHz", "log"]\n[choices]\narrival = ["equal-time", "poisson-time", "equal-space", "poisson-space"]\noverlap-retries = [0, 30]\n' >"$dir/choices.toml"
"$pdp" --log-level error sweep "$dir/choices.toml" -o "$dir/choices.csv" || fail "sweep with choices"
python3 - "$dir/log.csv" "$dir/choices.csv" <<'PY' || fail "choices not drawn as declared"
import collections, csv, sys
plain = list(csv.DictReader(open(sys.argv[1])))
mixed = list(csv.DictReader(open(sys.argv[2])))
assert len(mixed) == 400
by_run = {r["run"]: r for r in plain}
for r in mixed:
    assert r["fs"] == by_run[r["run"]]["fs"], (r["run"], r["fs"])
arrivals = collections.Counter(r["arrival"] for r in mixed)
assert set(arrivals) == {"equal-time", "poisson-time", "equal-space", "poisson-space"}, arrivals
assert all(60 <= n <= 140 for n in arrivals.values()), arrivals
retries = collections.Counter(r["overlap_retries"] for r in mixed)
assert set(retries) == {"0", "30"} and all(150 <= n <= 250 for n in retries.values()), retries
PY
refused() {  # TOML-body (printf %b escapes) expected-message: refused, named, no CSV
  printf '%b' "$1" >"$dir/bad.toml"
  local out
  out=$("$pdp" sweep "$dir/bad.toml" -o "$dir/bad.csv" 2>&1) && fail "accepted: $1"
  [[ $out == *"$2"* ]] || fail "$1: message lacks '$2': $out"
  [[ -e $dir/bad.csv ]] && fail "$1: wrote a CSV"
}
refused '[sweep]\nmode = "monte-carlo"\nruns = 4\n[choices]\narrival = ["equal-time"]\n' 'at least two values'
refused '[sweep]\nmode = "monte-carlo"\nruns = 4\n[choices]\narrival = ["equal-time", "sometimes"]\n' 'sometimes'
refused '[sweep]\nmode = "monte-carlo"\nruns = 4\n[ranges]\ndx = ["1mm", "2mm"]\n[choices]\ndx = ["1mm", "3mm"]\n' 'in one table'
refused '[sweep]\nmode = "grid"\n[grid]\ndx = ["1mm"]\n[choices]\narrival = ["equal-time", "equal-space"]\n' 'monte-carlo sweep'
bad() { refused "[sweep]\\nmode = \"monte-carlo\"\\nruns = 4\\n[ranges]\\n$1\\n" "$2"; }  # a bad [ranges] line
bad 'fs = ["10kHz", "1MHz", "lin"]' 'or [min, max, "log"]'
bad 'fs = ["0Hz", "1MHz", "log"]' 'needs min > 0'

if ((failures)); then
  echo "$failures failures"
  exit 1
fi
echo "pdp sweep CLI: all checks passed"

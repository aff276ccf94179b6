#!/usr/bin/env bash
# --config FILE.toml on every subcommand: keys are the flags' names, at the
# top level or in a [subcommand] table; the command line overrides the file;
# a missing file, an unknown key or a bad value is an error (exit 2) naming
# the file and line. Also: pdp sweep --np applies to every run unless the
# study sets np (then it is a conflict), and the documented exit codes.
# Usage: config_cli_test.sh PDP SCRATCH_DIR SOURCE_DIR
set -u
pdp=$1
dir=$2/config_cli
src=$3
rm -rf "$dir" && mkdir -p "$dir"
source "$(dirname "$0")/lib.sh"
json() { /usr/bin/python3 -c "import json,sys; j=json.load(open(sys.argv[1])); print(eval(sys.argv[2]))" "$@"; }

# Every subcommand refuses a missing or unknown-keyed config file.
printf 'no-such-option = 1\n' >"$dir/unknown.toml"
for cmd in synth process validate compare sweep bench train correct; do
  expect 2 "missing.toml: no such settings file" "$pdp" "$cmd" --config "$dir/missing.toml"
  expect 2 "unknown.toml:1: unknown setting 'no-such-option' for pdp $cmd" "$pdp" "$cmd" --config "$dir/unknown.toml"
done

# synth: values from the file, the command line over it; a [synth] table.
cat >"$dir/synth.toml" <<'TOML'
[synth]
duration = "0.5s"
fs = "50kHz"
seed = 4
velocity = "3m/s"
quiet = true
TOML
"$pdp" --log-level warn synth --config "$dir/synth.toml" -o "$dir/a.flac" || fail "synth with config"
[[ $(json "$dir/a.truth.json" "j['scene']['fs']") == 50000.0 ]] || fail "synth: fs not from the config"
"$pdp" --log-level warn synth --config "$dir/synth.toml" --fs 40kHz -o "$dir/b.flac" || fail "synth override"
[[ $(json "$dir/b.truth.json" "j['scene']['fs']") == 40000.0 ]] || fail "synth: the command line does not win"
printf 'duration = "fast"\n' >"$dir/bad.toml"
expect 2 "bad.toml:1: duration: " "$pdp" synth --config "$dir/bad.toml" -o "$dir/c.flac"
[[ -e $dir/c.flac ]] && fail "synth wrote a file after a bad config"

# process: positional files, options and outputs from the file.
cat >"$dir/process.toml" <<TOML
files = ["$dir/a.flac"]
dx = "5mm"
dy = "1mm"
np = 7
method = "awcc"
json = "$dir/a.json"
TOML
"$pdp" --log-level warn process --config "$dir/process.toml" >/dev/null || fail "process with config"
[[ $(json "$dir/a.json" "j['dx']") == 0.005 ]] || fail "process: dx not from the config"
[[ $(json "$dir/a.json" "j['awcc']['np']") == 7 ]] || fail "process: np not from the config"
[[ $(json "$dir/a.json" "'fscc' in j") == False ]] || fail "process: method not from the config"
"$pdp" --log-level warn process --config "$dir/process.toml" --np 9 >/dev/null || fail "process override"
[[ $(json "$dir/a.json" "j['awcc']['np']") == 9 ]] || fail "process: the command line does not win"
printf 'filter-a = 2\n' >"$dir/bad-a.toml"
expect 2 "bad-a.toml:1: filter-a: A = 2 must lie in [0, 1] (--filter-a)" "$pdp" process "$dir/a.flac" --dx 5mm \
  --config "$dir/bad-a.toml"
# One value refused from the file and from the command line: the same message
# (the option's declared name, its flag), the file's adding where it came from.
from_line=$("$pdp" process "$dir/a.flac" --dx 5mm --filter-a 2 2>&1 >/dev/null)
from_file=$("$pdp" process "$dir/a.flac" --dx 5mm --config "$dir/bad-a.toml" 2>&1 >/dev/null)
[[ ${from_file/"$dir/bad-a.toml:1: "/} == "$from_line" ]] ||
  fail "the file's and the command line's messages differ: '$from_file' / '$from_line'"
printf 'preset = "nope"\n' >"$dir/bad-preset.toml"
expect 2 "bad-preset.toml:1: preset: 'nope' is not a preset" "$pdp" process "$dir/a.flac" --dx 5mm \
  --config "$dir/bad-preset.toml"
expect 2 "files is required" "$pdp" process --dx 5mm

# validate: scene fields and method options from the file.
printf 'duration = "1s"\nfs = "100kHz"\nseed = 5\nnp = 6\n' >"$dir/validate.toml"
"$pdp" --log-level warn validate --config "$dir/validate.toml" --json "$dir/v.json" >/dev/null || fail "validate with config"
[[ $(json "$dir/v.json" "j['seed']") == 5 ]] || fail "validate: seed not from the config"
"$pdp" --log-level warn validate --config "$dir/validate.toml" --seed 6 --json "$dir/v.json" >/dev/null || fail "validate override"
[[ $(json "$dir/v.json" "j['seed']") == 6 ]] || fail "validate: the command line does not win"

# compare
out=$("$pdp" --log-level warn compare --config "$dir/validate.toml") || fail "compare with config"
grep -q "seed 5" <<<"$out" || fail "compare: seed not from the config: $out"

# sweep: the study and the output from the file; --np for every run; a conflict.
cat >"$dir/study.toml" <<'TOML'
[sweep]
mode = "grid"
[base]
duration = "0.5s"
fs = "100kHz"
[grid]
seed = [1, 2]
TOML
printf 'study = "%s"\noutput = "%s"\nthreads = 1\n' "$dir/study.toml" "$dir/sweep.csv" >"$dir/sweep.toml"
"$pdp" --log-level warn sweep --config "$dir/sweep.toml" --np 4 || fail "sweep with config"
col() { /usr/bin/python3 -c "import csv,sys; print(sorted({r[sys.argv[2]] for r in csv.DictReader(open(sys.argv[1]))}))" "$@"; }
[[ $(col "$dir/sweep.csv" np) == "['4']" ]] || fail "sweep: --np not applied to every run: $(col "$dir/sweep.csv" np)"
printf '[sweep]\nmode = "grid"\n[base]\nduration = "0.5s"\nnp = 8\n[grid]\nseed = [1]\n' >"$dir/study-np.toml"
expect 2 "--np 4 conflicts with np set in" "$pdp" sweep "$dir/study-np.toml" -o "$dir/conflict.csv" --np 4
[[ -e $dir/conflict.csv ]] && fail "sweep wrote a CSV on a conflict"

# bench
printf 'quick = true\nseeds = 1\nscenes = "base"\nduration = "0.5s"\noutput = "%s"\n' "$dir/bench.csv" >"$dir/bench.toml"
"$pdp" --log-level warn bench --config "$dir/bench.toml" || fail "bench with config"
[[ -s $dir/bench.csv ]] || fail "bench: no output from the config's path"

# train: a bad value from the file names the file and line.
printf 'trees = 0\n' >"$dir/train.toml"
expect 2 "train.toml:1: trees: " "$pdp" train "$dir/sweep.csv" -o "$dir/m.qrf" --config "$dir/train.toml"

# correct: a value the file lacks, from the config.
printf 'dx = "fast"\n' >"$dir/correct.toml"
expect 2 "--dx" "$pdp" correct "$dir/a.json" -m "$dir/a.json" --config "$dir/correct.toml"

# One file may hold several subcommands' tables.
printf '[process]\ndx = "5mm"\n[correct]\nnp = 10\n' >"$dir/both.toml"
"$pdp" --log-level error process "$dir/a.flac" --config "$dir/both.toml" >/dev/null || fail "a file with two tables"

# Exit codes (README): 2 bad usage, 1 bad input data, 3 an output not written.
expect 2 "" "$pdp" process "$dir/a.flac" --no-such-flag
printf 'not a recording' >"$dir/junk.dat"
expect 1 "junk.dat" "$pdp" process "$dir/junk.dat" --fs 20kHz --dx 5mm
expect 3 "does not exist" "$pdp" process "$dir/a.flac" --dx 5mm --json "$dir/no/such/folder/a.json"
# Outputs are all written or none: a CSV into a missing folder leaves no JSON.
rm -f "$dir/b.json"
expect 3 "does not exist" "$pdp" process "$dir/a.flac" "$dir/b.flac" --dx 5mm --json "$dir/b.json" \
  --csv "$dir/no/such/folder/b.csv"
[[ -e $dir/b.json ]] && fail "a JSON was written although the CSV could not be"
printf '{"tips": [{"void_fraction": "x"}], "awcc": {"defined": true, "velocity": 1, "turbulence_intensity": 0.1, "windows_accepted": "many", "options": {"filter_a": 0.4, "roc": "on"}}}' >"$dir/typed.json"
expect 1 "no number 'void_fraction' in /tips/0" "$pdp" correct "$dir/typed.json" -m "$src/samples/model/awcc.qrf" --dx 5mm \
  --dy 0 --np 10

[[ $failures -eq 0 ]] && echo "config CLI: all checks passed"
exit $((failures > 0))

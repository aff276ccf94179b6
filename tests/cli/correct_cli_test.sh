#!/usr/bin/env bash
# pdp train, pdp correct and pdp process --correct on a small sweep: the
# model is the same for a seed whatever the threads; corrections reach the
# JSON and the CSV with the documented keys; rows outside the training ranges
# are flagged; damaged, foreign and missing inputs give a clear error, a
# non-zero exit and no output file. The shipped model loads and corrects.
# Usage: correct_cli_test.sh PDP SCRATCH_DIR SOURCE_DIR
set -u
pdp=$1
dir=$2/correct_cli
src=$3
rm -rf "$dir" && mkdir -p "$dir"
source "$(dirname "$0")/lib.sh"

cat >"$dir/mc.toml" <<'TOML'
[sweep]
mode = "monte-carlo"
runs = 48
seed = 5
[base]
duration = "4s"
fs = "100kHz"
[ranges]
velocity = ["2m/s", "8m/s"]
tu = [0.02, 0.3]
void-fraction = [0.1, 0.3]
bubble-diameter = ["1mm", "3mm"]
dx = ["3mm", "6mm"]
dy = ["0mm", "1mm"]
np = [4.5, 10.5]
TOML
"$pdp" --log-level warn sweep "$dir/mc.toml" -o "$dir/mc.csv" || fail "sweep"

# Training: a report, a model, and the same bytes for 1 and 2 threads.
"$pdp" --log-level warn train "$dir/mc.csv" -o "$dir/a.qrf" --trees 20 --folds 2 --cv-trees 5 --min-leaf 3,5 \
  --features-per-split 3,7 --min-windows 20 --calibration 0 --threads 1 --predictions "$dir/pred.csv" --learning-curve "$dir/lc.csv" \
  >"$dir/report.txt" || fail "train"
grep -q "Held out:" "$dir/report.txt" || fail "no held-out report"
grep -q "coverage 80 % / 95 %" "$dir/report.txt" || fail "no coverage in the report"
grep -q "^  velocity  *ratio" "$dir/report.txt" || fail "no CV table"
head -1 "$dir/pred.csv" | grep -q "corrected_velocity_q0.975" || fail "predictions CSV header"
head -1 "$dir/lc.csv" | grep -q "^training_runs," || fail "learning curve header"
"$pdp" --log-level warn train "$dir/mc.csv" -o "$dir/b.qrf" --trees 20 --folds 2 --cv-trees 5 --min-leaf 3,5 \
  --features-per-split 3,7 --min-windows 20 --calibration 0 --threads 2 >/dev/null || fail "train, 2 threads"
cmp -s "$dir/a.qrf" "$dir/b.qrf" || fail "models differ between 1 and 2 threads"
# pdp score: the model on every run of the sweep, none trained; the held-out
# runs' predictions are training's to the last digit (one scorer), and the
# report says what was scored.
"$pdp" --log-level warn score -m "$dir/a.qrf" "$dir/mc.csv" --predictions "$dir/score.csv" --report "$dir/score.txt" \
  >"$dir/score.out" || fail "score"
cmp -s "$dir/score.out" "$dir/score.txt" || fail "score: the report file differs from stdout"
grep -q "^pdp score a.qrf: mc.csv (study [0-9]*) (generator version 2); 48 runs read" "$dir/score.txt" ||
  fail "score header: $(head -1 "$dir/score.txt")"
grep -q "coverage 80 % / 95 %" "$dir/score.txt" || fail "no coverage in the score report"
# Runs processed otherwise than the model's training data: refused, no predictions written.
"$pdp" --log-level warn sweep "$dir/mc.toml" -o "$dir/mc-a03.csv" --filter-a 0.3 || fail "sweep, filter A 0.3"
out=$("$pdp" score -m "$dir/a.qrf" "$dir/mc-a03.csv" --predictions "$dir/score-a03.csv" 2>&1) &&
  fail "pdp score accepted runs processed with another filter A"
[[ $out == *"processed differently from the model's training data"*"filter A"* ]] || fail "score processing message: $out"
[[ -e $dir/score-a03.csv ]] && fail "pdp score wrote predictions for refused runs"
/usr/bin/python3 - "$dir/pred.csv" "$dir/score.csv" <<'PY' || fail "pdp score's predictions differ from training's held-out ones"
import csv, sys
held = list(csv.DictReader(open(sys.argv[1])))
scored = {r["run"]: r for r in csv.DictReader(open(sys.argv[2]))}
assert held and len(scored) > len(held), (len(held), len(scored))
for r in held:
    assert r == scored[r["run"]], (r, scored[r["run"]])
PY
# Scored against the imposed truth, each row's truth is its scene's velocity
# and tu (and the realised one differs: a record samples the process); the
# predictions are the same, since the features are.
"$pdp" --log-level warn score -m "$dir/a.qrf" "$dir/mc.csv" --truth imposed --predictions "$dir/score-imposed.csv" \
  >"$dir/score-imposed.out" || fail "score --truth imposed"
grep -q "^truth: imposed" "$dir/score-imposed.out" || fail "the report does not say which truth"
/usr/bin/python3 - "$dir/mc.csv" "$dir/score.csv" "$dir/score-imposed.csv" <<'PY' || fail "imposed truth not the scene's"
import csv, sys
scene = {r["run"]: r for r in csv.DictReader(open(sys.argv[1]))}
realised = {r["run"]: r for r in csv.DictReader(open(sys.argv[2]))}
imposed = list(csv.DictReader(open(sys.argv[3])))
assert len(imposed) == len(realised)
differ = 0
for r in imposed:
    s, q = scene[r["run"]], realised[r["run"]]
    assert float(r["true_velocity"]) == float(s["velocity"]), (r["true_velocity"], s["velocity"])
    assert float(r["true_turbulence_intensity"]) == float(s["tu"])
    assert float(q["true_velocity"]) == float(s["truth_velocity"])
    differ += float(q["true_velocity"]) != float(s["velocity"])
    for k in r:
        if not k.startswith("true_"):
            assert r[k] == q[k], (k, r[k], q[k])
assert differ == len(imposed), differ
PY
# Runs another AWCC processed are scored when asked, and the report names
# the difference (a foreign tool's conventions, issue 33).
"$pdp" --log-level warn score -m "$dir/a.qrf" "$dir/mc-a03.csv" --other-processing >"$dir/score-a03.out" ||
  fail "score --other-processing"
grep -q "^processed otherwise than the model's training data: .*filter A" "$dir/score-a03.out" ||
  fail "the report does not name the other processing: $(cat "$dir/score-a03.out")"
# As peers' rows (issue 33): the shipped model's reduced forest scores the
# runs with fs, duration, windows and the time-scale ratio removed, the report
# says so, and the predictions are those pdp correct gives the same rows in
# pdp-uq's layout (u, u_rms, c, d_32a with dx, dy and Np stated).
"$pdp" --log-level warn score -m "$src/samples/model/awcc.qrf" "$dir/mc.csv" --as-peer-rows --other-processing \
  --predictions "$dir/score-peer.csv" >"$dir/score-peer.out" || fail "score --as-peer-rows"
grep -q "^as peers' rows: fs, duration, windows and the time-scale ratio removed" "$dir/score-peer.out" ||
  fail "the report does not say the rows are peers': $(head -3 "$dir/score-peer.out")"
/usr/bin/python3 - "$dir/score-peer.csv" "$dir/peer-rows.csv" <<'PY' || fail "score --as-peer-rows: the rows"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert rows, "no rows"
for r in rows:
    assert float(r["fs"]) == 0 and float(r["duration"]) == 0 and int(r["windows_accepted"]) == -1, r
# One (dx, dy, Np) group in pdp-uq's layout for pdp correct.
key = lambda r: (r["dx"], r["dy"], r["np"], r["awcc_unweighted"])
first = key(rows[0])
with open(sys.argv[2], "w") as f:
    f.write("dx,dy,np,run,u [m/s],u_rms [m/s],c [-],d_32a [m]\n")
    for r in rows:
        if key(r) == first:
            u, tu = float(r["velocity"]), float(r["turbulence_intensity"])
            f.write(f"{r['dx']},{r['dy']},{r['np']},{r['run']},{r['velocity']},{u * tu!r},{r['void_fraction']},{r['d32']}\n")
PY
read -r pdx pdy pnp < <(/usr/bin/python3 -c "import csv,sys; r=next(csv.DictReader(open(sys.argv[1]))); print(r['dx'], r['dy'], r['np'])" "$dir/peer-rows.csv")
"$pdp" --log-level error correct "$dir/peer-rows.csv" -m "$src/samples/model/awcc.qrf" --dx "${pdx}m" --dy "${pdy}m" --np "$pnp" \
  --weighting duration -o "$dir/peer-corrected.csv" || fail "pdp correct of the peer rows"
/usr/bin/python3 - "$dir/score-peer.csv" "$dir/peer-corrected.csv" <<'PY' || fail "score --as-peer-rows differs from pdp correct"
import csv, sys
scored = {r["run"]: r for r in csv.DictReader(open(sys.argv[1]))}
rows = list(csv.DictReader(open(sys.argv[2])))
assert rows
for r in rows:
    assert r["correction_forest [-]"] == "awcc-reduced", r["correction_forest [-]"]
    s = scored[r["run"]]
    for q in ("0.025", "0.5", "0.975"):
        a, b = float(r[f"u_q{q} [m/s]"]), float(s[f"corrected_velocity_q{q}"])
        assert abs(a / b - 1) < 1e-9, (r["run"], q, a, b)
PY
# A model without a reduced forest scores no peers' rows: refused (exit 1),
# naming why, with no predictions written, not a report of zeros.
"$pdp" --log-level warn train "$dir/mc.csv" -o "$dir/noreduced.qrf" --feature-set extended-yield --reduced off \
  --trees 5 --folds 0 --calibration 0 --min-windows 20 >/dev/null || fail "train without a reduced forest"
out=$("$pdp" score -m "$dir/noreduced.qrf" "$dir/mc.csv" --as-peer-rows --predictions "$dir/score-noreduced.csv" 2>&1)
code=$?
[[ $code == 1 ]] || fail "score --as-peer-rows without a reduced forest: exit $code"
[[ $out == *"none of the"*"could be scored"*"this model has no reduced forest"* ]] ||
  fail "score --as-peer-rows without a reduced forest: $out"
[[ -e $dir/score-noreduced.csv ]] && fail "score wrote predictions of no run"
# Calibrating intervals (the default) needs 100 calibration runs: a small sweep is told so, and no model is written.
out=$("$pdp" train "$dir/mc.csv" -o "$dir/c.qrf" --trees 5 --folds 0 --min-windows 20 2>&1) && fail "calibrated on a few runs"
[[ $out == *"calibration runs are too few"*"set calibration to 0"* ]] || fail "calibration message: $out"
[[ -e $dir/c.qrf ]] && fail "a model written despite the error"

# A recording well inside the training ranges (mid-range in every feature:
# the ranges of 30 training runs are narrow).
"$pdp" --log-level warn synth -q --duration 4s --fs 100kHz --velocity 5m/s --tu 0.1 --void-fraction 0.2 --bubble-diameter 2mm \
  --dx 4.5mm --dy 0.5mm --seed 9 -o "$dir/rec.flac" || fail "synth"
out=$("$pdp" --log-level error process "$dir/rec.flac" --dx 4.5mm --dy 0.5mm --np 6 --method awcc --correct "$dir/a.qrf" \
  --json "$dir/rec.json") || fail "process --correct"
grep -q "correction (quantile regression forest, AWCC forest)" <<<"$out" || fail "no correction in the summary: $out"
python3 - "$dir/rec.json" <<'PY' || fail "process --correct JSON"
import json, sys
j = json.load(open(sys.argv[1]))
c = j["correction"]
assert c["in_range"] is True and c["reason"] is None, c
for q in ("velocity", "turbulence_intensity"):
    qs = c[q]["quantiles"]
    assert list(qs) == ["0.025", "0.05", "0.1", "0.25", "0.5", "0.75", "0.9", "0.95", "0.975"], list(qs)
    v = list(qs.values())
    assert v == sorted(v), v
    assert c[q]["median"] == qs["0.5"]
assert abs(c["velocity"]["median"] / j["awcc"]["velocity"] - 1) < 0.3
PY

# pdp correct on that JSON gives the same correction object.
# A count that is not a count (1e300 windows) is refused, naming the field; no output.
python3 -c "
import json; d = json.load(open('$dir/rec.json')); d['awcc']['windows_accepted'] = 1e300
json.dump(d, open('$dir/huge.json', 'w'))"
expect 1 "awcc.windows_accepted = 1e+300 is not a count" "$pdp" correct "$dir/huge.json" -m "$dir/a.qrf" -o "$dir/huge-out.json"
[[ -e $dir/huge-out.json ]] && fail "an output for a file with a bad count"
"$pdp" correct "$dir/rec.json" -m "$dir/a.qrf" -o "$dir/again.json" || fail "correct JSON"
python3 -c "
import json,sys
a=json.load(open('$dir/rec.json'))['correction']; b=json.load(open('$dir/again.json'))['correction']
sys.exit(0 if a==b else 1)" || fail "pdp correct and process --correct disagree"

# A profile CSV carries dx, dy and Np: corrected as it is (two recordings of the scene: a profile refuses one twice).
"$pdp" --log-level warn synth -q --duration 4s --fs 100kHz --velocity 5m/s --tu 0.1 --void-fraction 0.2 --bubble-diameter 2mm \
  --dx 4.5mm --dy 0.5mm --seed 10 -o "$dir/rec2.flac" || fail "synth"
"$pdp" --log-level error process "$dir/rec.flac" "$dir/rec2.flac" --dx 4.5mm --dy 0.5mm --np 6 --method awcc \
  --csv "$dir/profile.csv" || fail "profile"
"$pdp" correct "$dir/profile.csv" -m "$dir/a.qrf" -o "$dir/corrected.csv" || fail "correct CSV"
head -1 "$dir/corrected.csv" | grep -q ",correction_in_range,correction_reason,correction_forest,corrected_velocity,corrected_velocity_q0.025," ||
  fail "CSV correction columns"
[[ $(column "$dir/corrected.csv" correction_in_range | sort -u) == "1" ]] || fail "profile rows not corrected"
[[ $(column "$dir/corrected.csv" correction_status | sort -u) == "corrected" ]] || fail "profile rows' status"

# A CSV without them (another tool's, an older pdp's) is refused with the
# fix, and no output; with the options, corrected.
python3 - "$dir/profile.csv" "$dir/bare.csv" <<'PY'
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
drop = {"dx", "dy", "np"}
with open(sys.argv[2], "w", newline="") as f:
    w = csv.DictWriter(f, [k for k in rows[0] if k not in drop])
    w.writeheader()
    for r in rows:
        w.writerow({k: v for k, v in r.items() if k not in drop})
PY
err=$("$pdp" correct "$dir/bare.csv" -m "$dir/a.qrf" -o "$dir/bare-corrected.csv" 2>&1)
code=$?
[[ $code -eq 2 ]] || fail "CSV without dx: exit $code, expected 2"
grep -q "no dx in the file; state the streamwise tip separation (--dx)" <<<"$err" || fail "message without the fix: $err"
[[ -e "$dir/bare-corrected.csv" ]] && fail "output written on error"
"$pdp" correct "$dir/bare.csv" -m "$dir/a.qrf" --dx 4.5mm --dy 0.5mm --np 6 -o "$dir/bare-corrected.csv" ||
  fail "correct CSV with the options"

# Outside the training ranges (dx 20 mm): flagged, not corrected.
"$pdp" correct "$dir/bare.csv" -m "$dir/a.qrf" --dx 20mm --dy 0.5mm --np 6 -o "$dir/outside.csv" || fail "correct outside"
[[ $(column "$dir/outside.csv" correction_reason | tail -1) == "dx = 20 mm is outside the training range"* ]] ||
  fail "out-of-range row not flagged"
[[ $(column "$dir/outside.csv" correction_status | tail -1) == "outside_training_range" ]] || fail "out-of-range status"

# Results processed otherwise than the model's training data are refused,
# naming the difference: on the command line before processing (exit 2) and
# in a file (exit 1).
err=$("$pdp" process "$dir/rec.flac" --dx 4.5mm --dy 0.5mm --np 6 --filter-a 0.3 --correct "$dir/a.qrf" \
  --json "$dir/other.json" 2>&1)
code=$?
[[ $code -eq 2 ]] || fail "process --correct with another filter: exit $code, expected 2"
grep -q "filter A: model 0.4, results 0.3" <<<"$err" || fail "processing mismatch message: $err"
[[ -e "$dir/other.json" ]] && fail "JSON written with a mismatched model"
"$pdp" --log-level error process "$dir/rec.flac" --dx 4.5mm --dy 0.5mm --np 6 --weighting none --json "$dir/other.json" ||
  fail "process with no weighting"
err=$("$pdp" correct "$dir/other.json" -m "$dir/a.qrf" -o "$dir/other-corrected.json" 2>&1)
code=$?
[[ $code -eq 1 ]] || fail "correct of results processed otherwise: exit $code, expected 1"
grep -q "weighting: model duration, results none" <<<"$err" || fail "file processing mismatch message: $err"
[[ -e "$dir/other-corrected.json" ]] && fail "output written for a mismatched file"

# Damaged, foreign and version-bumped models: clear error, no output.
head -c 5000 "$dir/a.qrf" >"$dir/cut.qrf"
err=$("$pdp" process "$dir/rec.flac" --dx 4.5mm --method awcc --correct "$dir/cut.qrf" --json "$dir/x.json" 2>&1) &&
  fail "truncated model accepted"
grep -q "cut.qrf: damaged model file" <<<"$err" || fail "truncated model message: $err"
[[ -e "$dir/x.json" ]] && fail "JSON written with a damaged model"
cp "$dir/a.qrf" "$dir/flip.qrf"
printf '\x55' | dd of="$dir/flip.qrf" bs=1 seek=3000 conv=notrunc status=none
err=$("$pdp" correct "$dir/rec.json" -m "$dir/flip.qrf" 2>&1) && fail "damaged model accepted"
grep -q "checksum mismatch" <<<"$err" || fail "damaged model message: $err"
err=$("$pdp" correct "$dir/rec.json" -m "$dir/mc.csv" 2>&1) && fail "foreign model accepted"
grep -q "not a pdp model file" <<<"$err" || fail "foreign model message: $err"
err=$("$pdp" correct "$dir/mc.csv" -m "$dir/a.qrf" 2>&1) && fail "a sweep CSV corrected as a profile"
grep -q "mc.csv: no column 'bubble_count_rate'" <<<"$err" || fail "wrong input message: $err"

# The shipped model loads and corrects a lab-like record (30 s at 20 kHz: inside its ranges); the 4 s
# record above is shorter than any of its training records (20-300 s) and is refused with the reason.
shipped=$src/samples/model/awcc.qrf
if [[ -f "$shipped" ]]; then
  "$pdp" --log-level warn synth -q --duration 30s --fs 20kHz --velocity 3m/s --tu 0.2 --void-fraction 0.1 \
    --bubble-diameter 3mm --dx 5mm --seed 9 -o "$dir/lab.flac" || fail "synth lab record"
  "$pdp" --log-level error process "$dir/lab.flac" --dx 5mm --np 10 --correct "$shipped" --json "$dir/shipped.json" ||
    fail "shipped model"
  python3 -c "
import json,sys
c=json.load(open('$dir/shipped.json'))['correction']
q=c['velocity']['quantiles']; t=c['turbulence_intensity']['quantiles']
sys.exit(0 if c['in_range'] and c['forest'] == 'awcc' and q['0.025'] <= q['0.5'] <= q['0.975'] and t['0.1'] <= t['0.9'] else 1)" ||
    fail "shipped model did not correct"
  "$pdp" correct "$dir/rec.json" -m "$shipped" -o "$dir/short.json" || fail "shipped model on a short record"
  grep -q '"reason": "duration = 4 s is outside the training range' "$dir/short.json" || fail "a 4 s record is not named outside the ranges: $(grep -o '"reason": "[^"]*' "$dir/short.json")"
else
  fail "samples/model/awcc.qrf is missing"
fi

# The figures of docs/validation.md from the training outputs.
png() { [[ -s $1 && $(head -c 8 "$1" | od -An -c | tr -d ' ') == '211PNG\r\n032\n' ]]; }
/usr/bin/python3 "$src/tools/plot_study.py" correction "$dir/pred.csv" "$dir/pred.png" || fail "correction figure"
png "$dir/pred.png" || fail "correction figure is not a PNG"
/usr/bin/python3 "$src/tools/plot_study.py" learning "$dir/lc.csv" "$dir/lc.png" || fail "learning-curve figure"
png "$dir/lc.png" || fail "learning-curve figure is not a PNG"

[[ $failures -eq 0 ]] && echo "correct CLI: all checks passed"
exit $((failures > 0))

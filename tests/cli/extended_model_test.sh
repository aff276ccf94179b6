#!/usr/bin/env bash
# The extended model end to end (METHOD 7, extended domain): a Monte Carlo
# sweep over sampling rates and record lengths, pdp train --feature-set
# extended (calibrated, with its FSCC forest), then pdp process --correct on
# a recording AWCC cannot serve (too few windows for the model): its velocity
# is corrected by the FSCC forest and says so, its Tu is not corrected; a
# profile CSV without fs is refused row by row with the missing feature named.
# Usage: extended_model_test.sh PDP SCRATCH_DIR
set -u
pdp=$1
dir=$2/extended_model
rm -rf "$dir" && mkdir -p "$dir"
source "$(dirname "$0")/lib.sh"

cat >"$dir/mc.toml" <<'TOML'
[sweep]
mode = "monte-carlo"
runs = 720
seed = 11
[base]
dy = "0mm"
[ranges]
velocity = ["3m/s", "5m/s"]
bubble-diameter = ["1.5mm", "2.5mm"]
fs = ["20kHz", "200kHz", "log"]
duration = ["1s", "2s"]
tu = [0.05, 0.2]
void-fraction = [0.1, 0.3]
dx = ["3mm", "6mm"]
np = [7.5, 12.5]
time-scale = ["10ms", "100ms"]
TOML
"$pdp" --log-level error sweep "$dir/mc.toml" -o "$dir/mc.csv" || fail "sweep"
"$pdp" --log-level warn train "$dir/mc.csv" -o "$dir/x.qrf" --feature-set extended --min-windows 10 --trees 20 \
  --folds 0 --min-leaf 5 --features-per-split 3 >"$dir/report.txt" || fail "train"
grep -q "fs, duration, windows_accepted" "$dir/report.txt" || fail "report: no extended features"
grep -q "FSCC forest (velocity of rows without a usable AWCC result; features fscc_velocity, r12_max, void_fraction, fscc_d32, dx, dy, fs, duration): trained on" "$dir/report.txt" ||
  fail "report: no FSCC forest"
grep -q "set aside to calibrate the intervals" "$dir/report.txt" || fail "report: no calibration"
grep -q "^  windows 10-29 " "$dir/report.txt" || fail "report: no coverage by band of windows"

# A recording inside the ranges; Np 60 leaves AWCC a handful of windows, below the model's 10.
"$pdp" --log-level warn synth -q --duration 1.5s --fs 60kHz --velocity 4m/s --tu 0.15 --void-fraction 0.2 \
  --bubble-diameter 2mm --dx 4.5mm --dy 0mm --seed 3 -o "$dir/rec.flac" || fail "synth"
"$pdp" --log-level error process "$dir/rec.flac" --dx 4.5mm --dy 0mm --np 60 --correct "$dir/x.qrf" \
  --json "$dir/r.json" --csv "$dir/r.csv" || fail "process --correct"
/usr/bin/python3 - "$dir/r.json" <<'PY' || fail "the FSCC forest did not correct the row as documented"
import json, sys
r = json.load(open(sys.argv[1]))
r = r["profile"][0] if "profile" in r else r
c = r["correction"]
assert c["status"] == "corrected", c
assert c["forest"] == "fscc", c
assert c["turbulence_intensity"] is None, c
q = c["velocity"]["quantiles"]
assert q["0.025"] <= q["0.1"] <= q["0.5"] <= q["0.9"] <= q["0.975"], q
assert abs(c["velocity"]["measured"] - r["fscc"]["velocity"]) < 1e-9, (c, r["fscc"])
assert 2.0 < c["velocity"]["median"] < 8.0, c
PY
[[ $(column "$dir/r.csv" correction_forest) == fscc ]] || fail "CSV: correction_forest is not fscc"

# Without fs the extended model cannot correct: each row says which feature is missing.
/usr/bin/python3 - "$dir/r.csv" "$dir/nofs.csv" <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
i = rows[0].index("fs")
keep = [[c for j, c in enumerate(r) if j != i] for r in rows]
keep = [[c for c, h in zip(r, rows[0][:i] + rows[0][i + 1:]) if not h.startswith("correction") and not h.startswith("corrected")]
        for r in keep]
csv.writer(open(sys.argv[2], "w", newline="")).writerows(keep)
PY
"$pdp" --log-level error correct "$dir/nofs.csv" -m "$dir/x.qrf" -o "$dir/nofs-corrected.csv" || fail "correct without fs"
[[ $(column "$dir/nofs-corrected.csv" correction_status) != corrected ]] ||
  fail "no fs: corrected all the same"
grep -q "fs" <<<"$(column "$dir/nofs-corrected.csv" correction_reason)" || fail "no fs: the reason does not name fs"
grep -q -- "the fs stated for the whole file" <<<"$(column "$dir/nofs-corrected.csv" correction_reason)" || fail "no fs: the reason does not say how to give it"
# Stated for the whole file, the record's fs gives back the same correction.
"$pdp" --log-level error correct "$dir/nofs.csv" -m "$dir/x.qrf" --fs 60kHz -o "$dir/fs-given.csv" || fail "correct --fs"
[[ $(column "$dir/fs-given.csv" corrected_velocity_q0.9) == $(column "$dir/r.csv" corrected_velocity_q0.9) ]] ||
  fail "--fs: not the correction of the file that records fs"
"$pdp" --log-level error correct "$dir/nofs.csv" -m "$dir/x.qrf" --fs 60 -o "$dir/bad.csv" 2>/dev/null &&
  fail "--fs without a unit accepted"
[[ -e "$dir/bad.csv" ]] && fail "--fs without a unit: output written"

# FSCC feature set 2 (c / F and FSCC's lag for FSCC's Sauter diameter): the
# FSCC forest of such a model takes the same row, and the file names them.
"$pdp" --log-level warn train "$dir/mc.csv" -o "$dir/x2.qrf" --feature-set extended --min-windows 10 --trees 20 \
  --folds 0 --min-leaf 5 --features-per-split 3 --fscc-feature-set fscc-2 --reduced off >"$dir/report2.txt" ||
  fail "train --fscc-feature-set fscc-2"
grep -q "chord_time" "$dir/report2.txt" || fail "report: FSCC set 2 not named"
"$pdp" --log-level error process "$dir/rec.flac" --dx 4.5mm --dy 0mm --np 60 --correct "$dir/x2.qrf" \
  --csv "$dir/r2.csv" || fail "process --correct, FSCC set 2"
[[ $(column "$dir/r2.csv" correction_forest) == fscc && $(column "$dir/r2.csv" correction_status) == corrected ]] ||
  fail "FSCC set 2: $(column "$dir/r2.csv" correction_status) $(column "$dir/r2.csv" correction_reason)"

# Peers' rows (issue 33): the reduced model trained beside the extended one
# corrects a row that states neither fs, nor the duration, nor the windows,
# and the output names its forest; the report scores it on the held-out runs
# with those features removed.
grep -q "^Reduced model (rows without fs, duration or windows: peers' files)" "$dir/report.txt" ||
  fail "report: no reduced model"
"$pdp" --log-level error process "$dir/rec.flac" --dx 4.5mm --dy 0mm --np 10 --csv "$dir/r10.csv" || fail "process, Np 10"
/usr/bin/python3 - "$dir/r10.csv" "$dir/peer.csv" <<'PY'
import csv, sys
r = next(csv.DictReader(open(sys.argv[1])))
u, c, F = float(r["awcc_velocity"]), float(r["void_fraction"]), float(r["bubble_count_rate"])
with open(sys.argv[2], "w") as out:  # pdp-uq's layout: no fs, duration or windows
    out.write("u [m/s],u_rms [m/s],c [-],d_32a [m]\n")
    out.write(f"{u!r},{float(r['awcc_velocity_rms'])!r},{c!r},{1.5 * u * c / F!r}\n")
PY
"$pdp" --log-level error correct "$dir/peer.csv" -m "$dir/x.qrf" --dx 4.5mm --dy 0mm --np 10 \
  -o "$dir/peer-corrected.csv" || fail "correct a peer's row"
[[ $(column "$dir/peer-corrected.csv" "correction_status [-]") == corrected ]] ||
  fail "peer's row: $(cat "$dir/peer-corrected.csv")"
[[ $(column "$dir/peer-corrected.csv" "correction_forest [-]") == awcc-reduced ]] || fail "peer's row: the forest is not named"
grep -q "not known for this row: corrected by the reduced forest" <<<"$(column "$dir/peer-corrected.csv" "correction_notes [-]")" ||
  fail "peer's row: no note"
"$pdp" --log-level warn train "$dir/mc.csv" -o "$dir/noreduced.qrf" --feature-set extended --min-windows 10 --trees 20 \
  --folds 0 --min-leaf 5 --features-per-split 3 --reduced off >"$dir/noreduced.txt" || fail "train --reduced off"
grep -q "^Reduced model" "$dir/noreduced.txt" && fail "--reduced off: a reduced model all the same"
[[ $(stat -c %s "$dir/noreduced.qrf") -lt $(stat -c %s "$dir/x.qrf") ]] || fail "--reduced off: the file is not smaller"

# The AWCC weighting as a feature (issue 33): every run trains twice, its
# duration-weighted and its unweighted measurement side by side in one part
# of the split; a recording processed either way is corrected (no refusal for
# the weighting), as its own; a peer's row of unknown weighting gets both
# answers mixed, and a note that says how to state it.
"$pdp" --log-level warn train "$dir/mc.csv" -o "$dir/xw.qrf" --feature-set extended+weighting --min-windows 10 \
  --trees 20 --folds 2 --cv-trees 5 --min-leaf 5 --features-per-split 3 --predictions "$dir/xw-pred.csv" \
  >"$dir/xw.txt" || fail "train extended+weighting"
/usr/bin/python3 - "$dir/xw-pred.csv" <<'PY' || fail "weighting twins: not side by side in the held-out runs"
import csv, sys, collections
rows = list(csv.DictReader(open(sys.argv[1])))
by_run = collections.defaultdict(list)
for r in rows:
    by_run[r["run"]].append(r["awcc_unweighted"])
assert by_run and all(sorted(v) == ["0", "1"] for v in by_run.values()), list(by_run.items())[:5]
PY
for w in duration none; do
  "$pdp" --log-level error process "$dir/rec.flac" --dx 4.5mm --dy 0mm --np 10 --weighting $w --correct "$dir/xw.qrf" \
    --csv "$dir/w-$w.csv" || fail "process --weighting $w --correct (a model with the weighting feature)"
  [[ $(column "$dir/w-$w.csv" correction_status) == corrected ]] || fail "weighting $w: $(column "$dir/w-$w.csv" correction_reason)"
done
[[ $(column "$dir/w-none.csv" corrected_velocity) != $(column "$dir/w-duration.csv" corrected_velocity) ]] ||
  fail "the weighting feature made no difference"
"$pdp" --log-level error correct "$dir/peer.csv" -m "$dir/xw.qrf" --dx 4.5mm --dy 0mm --np 10 \
  -o "$dir/peer-w.csv" || fail "correct a peer's row, weighting unknown"
grep -q "answers for duration-weighted and unweighted moments are mixed" <<<"$(column "$dir/peer-w.csv" "correction_notes [-]")" ||
  fail "unknown weighting: no note"
"$pdp" --log-level error correct "$dir/peer.csv" -m "$dir/xw.qrf" --dx 4.5mm --dy 0mm --np 10 --weighting none \
  -o "$dir/peer-none.csv" || fail "correct a peer's row, --weighting none"
grep -q "mixed" <<<"$(column "$dir/peer-none.csv" "correction_notes [-]")" && fail "--weighting none: mixed all the same"

if ((failures)); then
  echo "$failures failures"
  exit 1
fi
echo "extended model CLI: all checks passed"

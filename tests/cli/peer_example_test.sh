#!/usr/bin/env bash
# A peer's profile corrected by the shipped model (issue 33, "keep the pdp-uq
# example profile within the agreement shown in docs/validation.md"; now
# docs/history/correction-foreign-conventions.md, "Peers' rows: the
# reduced model" and "The model of the complete campaign, shipped"):
# pdp-uq's example (Bürgler et al. 2024; its example/pdp_data.csv, a
# stepped-spillway profile in pdp-uq's layout: u, u_rms, c, d_32a, no fs,
# duration or windows; dx 5 mm, dy 1 mm, Np 10, unweighted moments) with
# pdp-uq's own published 2.5 / 50 / 97.5 % quantiles beside it (its
# example/pdp_data_uq.csv; pdp-uq corrects the ten rows with c <= 0.4).
#   - every row with c up to 0.6 (pdp's training range) is corrected by the
#     reduced forest, which the output names; the rows beyond are refused
#     as outside the training range, naming c;
#   - on the ten rows both correct, each model's median u lies inside the
#     other's 95 % interval, and pdp-uq's median Tu inside pdp's. pdp's
#     median Tu is not required inside pdp-uq's interval: pdp-uq's training
#     ended at Tu 0.35, so its intervals stop below it (the first row: raw Tu
#     0.318, pdp 0.44, pdp-uq's 97.5 % 0.347). Where the raw Tu itself is
#     within a tenth of that end (the first row only), pdp-uq's answer is its
#     training range's edge, not a reading of the row: there the two 95 %
#     intervals must meet (pdp's from 0.327, pdp-uq's to 0.347; pdp-uq's
#     median 0.316 is below pdp's 2.5 % quantile with the campaign's complete
#     model, issue 33);
#   - the two medians of u differ by at most 6 % (4.7 % at the first row).
# A reader that took u_rms for Tu, d_32a in mm, or lost the weighting, or a
# model that moved the profile, fails these.
# Usage: peer_example_test.sh PDP SCRATCH_DIR SOURCE_DIR
set -u
pdp=$1
dir=$2/peer_example
src=$3
rm -rf "$dir" && mkdir -p "$dir"
source "$(dirname "$0")/lib.sh"

"$pdp" --log-level error correct "$src/tests/cli/pdp-uq-example.csv" -m "$src/samples/model/awcc.qrf" \
  --dx 5mm --dy 1mm --np 10 --weighting none -o "$dir/corrected.csv" || fail "pdp correct of pdp-uq's example"
/usr/bin/python3 - "$dir/corrected.csv" <<'PY' || fail "pdp-uq's example: see above"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
assert len(rows) == 22, len(rows)
pdp_uq_tu_end = 0.35  # the largest Tu of pdp-uq's training runs
bad = []
both = 0
for i, r in enumerate(rows, 1):
    c = float(r["c [-]"])
    status = r["correction_status [-]"]
    if c <= 0.6:
        if status != "corrected" or r["correction_forest [-]"] != "awcc-reduced":
            bad.append(f"row {i} (c {c}): {status}, forest {r['correction_forest [-]']}")
            continue
    else:
        if status != "outside_training_range" or "void_fraction" not in r["correction_reason [-]"]:
            bad.append(f"row {i} (c {c}): {status}, {r['correction_reason [-]']}")
        continue
    if not r["pdp_uq_u_q0.5 [m/s]"]:
        continue
    both += 1
    f = lambda name: float(r[name])
    u, lo, hi = f("u_q0.5 [m/s]"), f("u_q0.025 [m/s]"), f("u_q0.975 [m/s]")
    uq, uq_lo, uq_hi = f("pdp_uq_u_q0.5 [m/s]"), f("pdp_uq_u_q0.025 [m/s]"), f("pdp_uq_u_q0.975 [m/s]")
    if not uq_lo <= u <= uq_hi:
        bad.append(f"row {i}: pdp's u {u:.3f} outside pdp-uq's [{uq_lo}, {uq_hi}]")
    if not lo <= uq <= hi:
        bad.append(f"row {i}: pdp-uq's u {uq} outside pdp's [{lo:.3f}, {hi:.3f}]")
    if abs(u / uq - 1) > 0.06:
        bad.append(f"row {i}: u medians differ by {100 * (u / uq - 1):+.1f} %")
    tu_lo, tu_hi, tu_uq = f("Tu_q0.025 [-]"), f("Tu_q0.975 [-]"), f("pdp_uq_Tu_q0.5 [-]")
    uq_tu_lo, uq_tu_hi = f("pdp_uq_Tu_q0.025 [-]"), f("pdp_uq_Tu_q0.975 [-]")
    raw_tu = f("u_rms [m/s]") / f("u [m/s]")
    if raw_tu < 0.9 * pdp_uq_tu_end:
        if not tu_lo <= tu_uq <= tu_hi:
            bad.append(f"row {i}: pdp-uq's Tu {tu_uq} outside pdp's [{tu_lo:.3f}, {tu_hi:.3f}]")
    elif not (tu_lo <= uq_tu_hi and uq_tu_lo <= tu_hi):
        bad.append(f"row {i}: pdp's Tu interval [{tu_lo:.3f}, {tu_hi:.3f}] and pdp-uq's [{uq_tu_lo}, {uq_tu_hi}] do not meet")
assert both == 10, both
if bad:
    print("\n".join(bad))
    sys.exit(1)
PY
# The same file without --weighting: both weightings' answers mixed, and a
# note that says so; still corrected.
"$pdp" --log-level error correct "$src/tests/cli/pdp-uq-example.csv" -m "$src/samples/model/awcc.qrf" \
  --dx 5mm --dy 1mm --np 10 -o "$dir/mixed.csv" || fail "pdp correct without --weighting"
[[ $(column "$dir/mixed.csv" "correction_status [-]" | grep -c '^corrected$') -eq 12 ]] ||
  fail "without --weighting: not 12 rows corrected"
((failures == 0)) && echo "pdp-uq's example profile: all checks passed"
exit $((failures > 0))

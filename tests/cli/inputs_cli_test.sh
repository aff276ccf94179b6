#!/usr/bin/env bash
# Inputs that are half-read, typos, and quality levels (issue 29, cases 4, 7
# and 8), and the mistakes found by trying pdp as a new user would: each is
# refused with a message naming the file, the field and the fix, the
# documented exit code and no output file, or read as it should be.
# docs/reliability.md lists them.
# Usage: inputs_cli_test.sh PDP SCRATCH_DIR SOURCE_DIR
set -u
source "$(dirname "$0")/lib.sh"
pdp=$1 dir=$2/inputs_cli src=$3
data=$src/../shared/data/felder-stepped-spillway
rm -rf "$dir" && mkdir -p "$dir"
py() { /usr/bin/python3 "$@"; }
# refused CODE TEXT CMD...: as expect, and the --json the command names is not written.
refused() {
  rm -f "$dir/out.json"
  expect "$@"
  [[ -e $dir/out.json ]] && fail "$*: an output was written"
}

"$pdp" --log-level warn synth -q --duration 2s --fs 100kHz --velocity 4m/s --dy 0mm --signal voltage -o "$dir/rec.wav" ||
  fail "synth"
"$pdp" --log-level warn synth -q --duration 2s --fs 100kHz --velocity 3m/s --dy 0mm --signal voltage --seed 2 \
  -o "$dir/rec2.wav" || fail "synth"

# --- Case 7: a header whose channel count contradicts the data --------------
# The WAV's two tips as a UQ .dat; the same bytes under a header of 3 channels
# (rows x 3 = the samples: the sizes agree); 3-channel data under a header of 2.
py - "$dir/rec.wav" "$dir" <<'PY' || fail "writing .dat files"
import struct, sys, wave
w = wave.open(sys.argv[1])
n = w.getnframes()
v = struct.unpack("<%dh" % (2 * n), w.readframes(n))
body = struct.pack("<%dh" % (2 * n), *v)
open(sys.argv[2] + "/two.dat", "wb").write(struct.pack("<ii", n, 2) + body)
open(sys.argv[2] + "/three-over-two.dat", "wb").write(struct.pack("<ii", 2 * n // 3, 3) + body[: 2 * (2 * n // 3 * 3)])
three = []
for t in range(n):
    three += [v[2 * t], v[2 * t + 1], 100]  # a third channel: a dead one
open(sys.argv[2] + "/two-over-three.dat", "wb").write(struct.pack("<ii", 3 * n // 2, 2) + struct.pack("<%dh" % (3 * n), *three))
open(sys.argv[2] + "/three.dat", "wb").write(struct.pack("<ii", n, 3) + struct.pack("<%dh" % (3 * n), *three))
PY
"$pdp" --log-level error process "$dir/two.dat" --fs 100kHz --dx 5mm >/dev/null || fail "the true .dat refused"
"$pdp" --log-level error process "$dir/three.dat" --fs 100kHz --dx 5mm >/dev/null || fail "a true 3-channel .dat refused"
refused 1 "three-over-two.dat: the .dat header's channel count (bytes 4-7) says 3 channels, but the samples repeat as 2 channels" \
  "$pdp" process "$dir/three-over-two.dat" --fs 100kHz --dx 5mm --json "$dir/out.json"
refused 1 "correct the header to 2 channels" "$pdp" process "$dir/three-over-two.dat" --fs 100kHz --dx 5mm --json "$dir/out.json"
err=$("$pdp" process "$dir/three-over-two.dat" --fs 100kHz --dx 5mm 2>&1)
grep -q "swapped" <<<"$err" && fail "a header lie is still blamed on swapped tips: $err"
refused 1 "says 2 channels, but the samples repeat as 3 channels" \
  "$pdp" process "$dir/two-over-three.dat" --fs 100kHz --dx 5mm --json "$dir/out.json"
# The same lie through a stated raw layout.
tail -c +9 "$dir/three-over-two.dat" >"$dir/two.raw"  # whole 3-sample frames
refused 1 "the stated raw layout (raw-channels) says 3 channels, but the samples repeat as 2 channels" \
  "$pdp" process "$dir/two.raw" --fs 100kHz --dx 5mm --raw-channels 3 --json "$dir/out.json"
refused 1 "state raw-channels 2 (--raw-channels)" \
  "$pdp" process "$dir/two.raw" --fs 100kHz --dx 5mm --raw-channels 3 --json "$dir/out.json"
# A real recording under a header of 3 channels (the issue's case), when the recordings are here.
if [[ -f $data/dc157_05.dat ]]; then
  py - "$data/dc157_05.dat" "$dir/real-three.dat" <<'PY' || fail "writing the real .dat"
import struct, sys
d = open(sys.argv[1], "rb").read()
rows, channels = struct.unpack("<ii", d[:8])
open(sys.argv[2], "wb").write(struct.pack("<ii", rows * channels // 3, 3) + d[8:])
PY
  refused 1 "real-three.dat: the .dat header's channel count (bytes 4-7) says 3 channels, but the samples repeat as 2 channels" \
    "$pdp" process "$dir/real-three.dat" --fs 20kHz --dx 7.15mm --json "$dir/out.json"
else
  echo "inputs_cli_test.sh: $data absent: the real-recording check is skipped"
fi

# --- Case 7: one recording at two positions ---------------------------------
cp "$dir/rec.wav" "$dir/copy.wav"
ln -sf "$dir/rec.wav" "$dir/link.wav"
refused 2 "$dir/rec.wav and $dir/rec.wav (files 1 and 2) are one file" \
  "$pdp" process "$dir/rec.wav" "$dir/rec.wav" --dx 5mm --json "$dir/out.json"
refused 2 "$dir/rec.wav and $dir/link.wav (files 1 and 3) are one file" \
  "$pdp" process "$dir/rec.wav" "$dir/rec2.wav" "$dir/link.wav" --dx 5mm --json "$dir/out.json"
refused 2 "$dir/rec.wav and $dir/copy.wav (files 1 and 3) hold the same bytes" \
  "$pdp" process "$dir/rec.wav" "$dir/rec2.wav" "$dir/copy.wav" --dx 5mm --json "$dir/out.json"
"$pdp" --log-level error process "$dir/rec.wav" "$dir/rec2.wav" --dx 5mm --csv "$dir/two.csv" || fail "two recordings refused"

# --- Case 7: LabVIEW .lvm as LabVIEW writes it -----------------------------
# The full header, Windows line ends, a comment on the first row; rows with the
# (empty) Comment cell, rows without it, and the file in two segments (LabVIEW
# starts one at every write): each reads as the WAV's samples.
py - "$dir/rec.wav" "$dir" <<'PY' || fail "writing the .lvm files"
import struct, sys, wave
w = wave.open(sys.argv[1])
n, fs = w.getnframes(), w.getframerate()
v = struct.unpack("<%dh" % (2 * n), w.readframes(n))
s = 5.0 / 32768
head = ["LabVIEW Measurement\t", "Writer_Version\t2", "Reader_Version\t2", "Separator\tTab", "Decimal_Separator\t.",
        "Multi_Headings\tNo", "X_Columns\tOne", "Time_Pref\tRelative", "Operator\tlab", "Date\t2024/03/05",
        "Time\t10:15:02.4973711967468261719", "***End_of_Header***\t", "\t"]
segment = ["Channels\t2\t\t", "Samples\t%d\t%d\t" % (n, n), "Date\t2024/03/05\t2024/03/05\t",
           "Time\t10:15:02.4973711967468261719\t10:15:02.4973711967468261719\t", "Y_Unit_Label\tVolts\tVolts\t",
           "X_Dimension\tTime\tTime\t", "X0\t0.0000000000000000E+0\t0.0000000000000000E+0\t",
           "Delta_X\t%.6f\t%.6f\t" % (1 / fs, 1 / fs), "***End_of_Header***\t\t\t", "X_Value\tUntitled\tUntitled 1\tComment"]
def write(name, comment, split=None):
    with open(sys.argv[2] + "/" + name, "w", newline="") as f:
        for line in head + segment:
            f.write(line + "\r\n")
        for i in range(n):
            if i == split:
                for line in segment:
                    f.write(line + "\r\n")
            cell = ("\tprobe at 8 mm" if i == 0 else "\t") if comment else ""
            f.write("%.6f\t%.6f\t%.6f%s\r\n" % (i / fs, v[2 * i] * s, v[2 * i + 1] * s, cell))
write("comment.lvm", True)
write("no-comment.lvm", False)
write("segments.lvm", True, split=n // 2)
PY
"$pdp" --log-level error process "$dir/rec.wav" --dx 5mm --volts-per-count 0.000152587890625V --json "$dir/wav.json" >/dev/null ||
  fail "wav run"
for f in comment no-comment segments; do
  "$pdp" --log-level error process "$dir/$f.lvm" --dx 5mm --json "$dir/$f.json" >/dev/null || fail "LabVIEW $f.lvm refused"
done
# The three .lvm forms hold the same printed values: identical results; the
# WAV's within the printing's rounding (6 decimals of a volt).
py - "$dir/wav.json" "$dir/comment.json" "$dir/no-comment.json" "$dir/segments.json" <<'PY' || fail "the .lvm files differ"
import json, sys
wav, lvm, *others = [json.load(open(p)) for p in sys.argv[1:]]
for o in others:
    assert o["fs"] == lvm["fs"] and o["tips"] == lvm["tips"], "the .lvm forms differ"
assert abs(lvm["fs"] / wav["fs"] - 1) < 1e-6, (lvm["fs"], wav["fs"])
for t in range(2):
    assert abs(lvm["tips"][t]["void_fraction"] - wav["tips"][t]["void_fraction"]) < 1e-3, (lvm["tips"][t], wav["tips"][t])
PY
# A Channels line that contradicts the columns.
sed 's/^Channels\t2/Channels\t3/' "$dir/no-comment.lvm" >"$dir/channels3.lvm"
refused 1 "channels3.lvm: its header's Channels line says 3 channels, but its rows hold 2 data columns ('Untitled', 'Untitled 1')" \
  "$pdp" process "$dir/channels3.lvm" --dx 5mm --json "$dir/out.json"

# --- Case 8: typos answered as typos ----------------------------------------
refused 2 "unknown option --nq for pdp process: did you mean --np?" \
  "$pdp" process "$dir/rec.wav" --nq 3 --dx 5mm --json "$dir/out.json"
refused 2 "unknown option --nq for pdp process: did you mean --np?" \
  "$pdp" process --nq 3 "$dir/rec.wav" --dx 5mm --json "$dir/out.json"
refused 2 "unknown option --filtera for pdp process: did you mean --filter-a?" \
  "$pdp" process "$dir/rec.wav" --filtera 0.5 --dx 5mm --json "$dir/out.json"
err=$("$pdp" process "$dir/rec.wav" --nq 3 --dx 5mm 2>&1)
grep -q "does not exist" <<<"$err" && fail "--nq's value is still taken for a file: $err"
# pdp's own options work after the subcommand.
err=$("$pdp" process "$dir/rec.wav" --dx 5mm --json "$dir/debug.json" --log-level debug 2>&1 >/dev/null) ||
  fail "--log-level after the subcommand refused: $err"
grep -q "^\[debug\]" <<<"$err" || fail "--log-level debug after the subcommand has no effect: $err"
[[ -s $dir/debug.json ]] || fail "no output with --log-level after the subcommand"
err=$("$pdp" process "$dir/rec.wav" --dx 5mm --log-level=error 2>&1 >/dev/null) || fail "--log-level=error after the subcommand"
[[ -z $err ]] || fail "--log-level=error after the subcommand still logs: $err"
# A file named like an option is still a file.
cp "$dir/rec.wav" "$dir/--odd.wav"
(cd "$dir" && "$pdp" --log-level error process ./--odd.wav --dx 5mm >/dev/null) || fail "a file named like an option refused"

# Settings files: paths from the file's folder, whatever the current folder.
mkdir -p "$dir/study/recordings" "$dir/elsewhere"
cp "$dir/rec.wav" "$dir/study/recordings/a.wav"
cp "$dir/rec2.wav" "$dir/study/recordings/b.wav"
printf 'file,position\na.wav,2mm\nb.wav,8mm\n' >"$dir/study/positions.csv"
cat >"$dir/study/run.toml" <<'TOML'
[process]
files = ["recordings/a.wav", "recordings/b.wav"]
manifest = "positions.csv"
dx = "5mm"
csv = "profile.csv"
json = "profile.json"
TOML
(cd "$dir/elsewhere" && "$pdp" --log-level error process --config ../study/run.toml) ||
  fail "a settings file's relative paths are not taken from its folder"
[[ $(column "$dir/study/profile.csv" position | tr '\n' ' ') == "0.002 0.008 " ]] ||
  fail "settings-file profile: $(column "$dir/study/profile.csv" position | tr '\n' ' ')"
[[ -s $dir/study/profile.json && ! -e $dir/elsewhere/profile.json ]] || fail "the settings file's json went elsewhere"
printf 'dxx = "5mm"\n' >"$dir/typo.toml"
refused 2 "typo.toml:1: unknown setting 'dxx' for pdp process: did you mean dx?" \
  "$pdp" process "$dir/rec.wav" --config "$dir/typo.toml" --json "$dir/out.json"

# --- Case 4: quality levels where a user reads them -------------------------
out=$("$pdp" --log-level error compare --config "$src/samples/small-bubbles.toml") || fail "compare small-bubbles"
py - "$out" <<'PY' || fail "compare prints AWCC values without their status and quality: $out"
import sys
lines = sys.argv[1].splitlines()
at = next(i for i, l in enumerate(lines) if l.startswith("AWCC: status "))
table = next(i for i, l in enumerate(lines) if l.startswith("velocity (m/s)"))
assert at < table, "the quality comes after the values"
import re
# 0.5 mm bubbles 10 mm apart: 19 of 22,772 windows pass (0.08 %), what
# signals that share no bubble give by chance, and AWCC reads 74 m/s for a
# 10 m/s flow: the reason says so (awcc::chance_data_yield).
assert re.match(r"AWCC: status ok, quality low \(its values are flagged\): a chance yield: \d+ of \d+ windows accepted \(0\.0\d+ %, below 0\.1 %\)", lines[at]), lines[at]
assert any(l.startswith("FSCC: status ") for l in lines[:table]), lines
PY
"$pdp" --log-level error validate --config "$src/samples/small-bubbles.toml" --duration 8s --json "$dir/v.json" >"$dir/v.txt" ||
  fail "validate"
py - "$dir/v.json" "$dir/v.txt" <<'PY' || fail "validate: quality missing"
import json, sys
j = json.load(open(sys.argv[1]))
a = j["awcc"]
assert a["quality"] in ("ok", "low", "insufficient"), a
assert (a["quality_reason"] is None) == (a["quality"] == "ok"), a
text = open(sys.argv[2]).read()
assert "AWCC: status %s, quality %s" % (a["status"], a["quality"]) in text, text
if a["quality"] == "insufficient":
    assert a["velocity"] is None
    row = next(l for l in text.splitlines() if l.startswith("mean velocity"))
    assert row.split()[-2:] == ["n/a", "n/a"], row
PY
"$pdp" --log-level error validate --duration 1s --fs 100kHz --repeat 3 --json "$dir/v3.json" >"$dir/v3.txt" ||
  fail "validate --repeat"
py - "$dir/v3.json" "$dir/v3.txt" <<'PY' || fail "validate --repeat: quality counts"
import json, sys
j = json.load(open(sys.argv[1]))
q = j["awcc_quality"]
assert q["ok"] + q["low"] + q["insufficient"] == 3, q
assert [r["awcc"]["quality"] for r in j["runs"]].count("insufficient") == q["insufficient"], q
for key, e in j["error"].items():
    assert (e["mean"] is None) == (e["runs"] == 0), (key, e)
assert "AWCC quality: %d runs ok, %d low, %d insufficient" % (q["ok"], q["low"], q["insufficient"]) in open(sys.argv[2]).read()
PY
# Insufficient: no number where AWCC's values would be, the level and why.
out=$("$pdp" --log-level error compare --duration 0.05s --fs 100kHz --void-fraction 0.05) || fail "compare short"
grep -q "^AWCC: status too_few_[a-z]*, quality insufficient, no velocity: " <<<"$out" || fail "compare: insufficient not said: $out"
[[ $(grep "^velocity (m/s)" <<<"$out" | awk '{print $4}') == "n/a" ]] || fail "compare: an insufficient AWCC velocity printed: $out"

# --- New mistakes --------------------------------------------------------------
# 1. A subcommand misspelt, and a subcommand's option before it.
refused 2 "unknown command 'proces': did you mean process?" "$pdp" proces "$dir/rec.wav" --dx 5mm --json "$dir/out.json"
refused 2 "--dx is an option of pdp process: give it after 'process'" \
  "$pdp" --dx 5mm process "$dir/rec.wav" --json "$dir/out.json"
# 2. A .dat of 0 rows (an acquisition stopped before its first sample).
printf '\0\0\0\0\2\0\0\0' >"$dir/empty-acquisition.dat"
refused 1 "empty-acquisition.dat: the .dat header says 0 rows of 2 channels and no sample follows: the acquisition recorded nothing" \
  "$pdp" process "$dir/empty-acquisition.dat" --fs 20kHz --dx 5mm --json "$dir/out.json"
# 3. An output path that is a folder (the temporary file's name was the message).
expect 3 "$dir/elsewhere: is a folder, not a file" "$pdp" process "$dir/rec.wav" --dx 5mm --json "$dir/elsewhere"
printf '[sweep]\nmode = "grid"\n[base]\nduration = "0.2s"\nfs = "100kHz"\n[grid]\nseed = [1]\n' >"$dir/sweep.toml"
expect 3 "$dir/elsewhere: is a folder, not a file" "$pdp" sweep "$dir/sweep.toml" -o "$dir/elsewhere"
# 4. One position for two recordings (in mixed units), one recording positioned twice, two sources of positions.
refused 2 "--positions gives $dir/rec.wav and $dir/rec2.wav the same position, 2mm" \
  "$pdp" process "$dir/rec.wav" "$dir/rec2.wav" --dx 5mm --positions 2mm,0.002m --json "$dir/out.json"
printf 'file,position\nrec.wav,2mm\nrec2.wav,8mm\nrec.wav,14mm\n' >"$dir/twice.csv"
refused 2 "twice.csv: lines 2 and 4 both position rec.wav; keep one" \
  "$pdp" process "$dir/rec.wav" "$dir/rec2.wav" --dx 5mm --manifest "$dir/twice.csv" --json "$dir/out.json"
printf 'file,position\nrec.wav,2mm\nrec2.wav,8mm\n' >"$dir/manifest.csv"
refused 2 "--positions and --manifest both give the positions; give one of them" \
  "$pdp" process "$dir/rec.wav" "$dir/rec2.wav" --dx 5mm --manifest "$dir/manifest.csv" --positions 20mm,30mm \
  --json "$dir/out.json"
# 5. A decimal comma, a unit in the wrong case, a list where one value belongs.
refused 2 "dx: '7,15mm' is not a length: its decimal separator is a comma; write 7.15mm (--dx)" \
  "$pdp" process "$dir/rec.wav" --dx 7,15mm --json "$dir/out.json"
refused 2 "unknown unit 'khz' (units are case-sensitive: did you mean kHz?)" \
  "$pdp" process "$dir/rec.wav" --dx 5mm --fs 100khz --override-fs --json "$dir/out.json"
printf 'dx = ["5mm", "6mm"]\n' >"$dir/list.toml"
refused 2 "list.toml:1: dx: '5mm,6mm' is not a length: it is a list; give one value" \
  "$pdp" process "$dir/rec.wav" --config "$dir/list.toml" --json "$dir/out.json"
# Interface times at the threshold crossing reach only bubble-by-bubble lags:
# without event detection or a multi-tip probe the option touched nothing.
refused 2 "interface-times = crossing times the interfaces of event detection and of the multi-tip pairing, and this run does neither" \
  "$pdp" process "$dir/rec.wav" --dx 5mm --interface-times crossing --json "$dir/out.json"
refused 2 "add events to the method (method = events, or awcc+events)" \
  "$pdp" process "$dir/rec.wav" --dx 5mm --method fscc --interface-times crossing --json "$dir/out.json"
"$pdp" --log-level error process "$dir/rec.wav" --dx 5mm --method awcc+events --interface-times crossing \
  --json "$dir/out.json" || fail "interface-times crossing with events refused"
[[ $(py -c "import json; print(json.load(open('$dir/out.json'))['events']['interface_times'])") == crossing ]] ||
  fail "events.interface_times is not crossing"

[[ $failures -eq 0 ]] && echo "inputs CLI: all checks passed"
exit $((failures > 0))

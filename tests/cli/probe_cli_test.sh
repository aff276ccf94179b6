#!/usr/bin/env bash
# A probe's tips declared once (issue 30): --tips with a unit on each value,
# the [probe] table of a settings file (the form pdp synth takes), the
# mistakes refused naming the tip, channel and file, and a four-tip pdp synth
# .h5 processed without any declaration (its tips travel in the file).
# Usage: probe_cli_test.sh PDP SCRATCH_DIR SOURCE_DIR
set -u
pdp=$1
dir=$2/probe_cli
src=$3
rm -rf "$dir" && mkdir -p "$dir"
source "$(dirname "$0")/lib.sh"
result() { /usr/bin/python3 -c "import json,sys; j=json.load(open(sys.argv[1])); j.pop('provenance', None); j.pop('options', None); j.pop('seconds', None); print(json.dumps(j, sort_keys=True))" "$1"; }

"$pdp" --log-level warn synth -q --duration 2s --fs 100kHz --dx 5mm --dy 1mm -o "$dir/two.flac" || fail "synth two"
"$pdp" --log-level warn synth -q --config "$src/samples/four-tip.toml" --duration 2s -o "$dir/four.h5" || fail "synth four h5"
"$pdp" --log-level warn synth -q --config "$src/samples/four-tip.toml" --duration 2s -o "$dir/four.flac" || fail "synth four flac"

# 1. A two-tip declaration gives the numbers of dx and dy.
"$pdp" --log-level error process "$dir/two.flac" --dx 5mm --dy 1mm --json "$dir/dx.json" >/dev/null || fail "dx"
"$pdp" --log-level error process "$dir/two.flac" --tips "0,0,0;5mm,1mm,0" --json "$dir/tips.json" >/dev/null || fail "--tips"
[[ "$(result "$dir/dx.json")" == "$(result "$dir/tips.json")" ]] || fail "--tips 0,0,0;5mm,1mm,0 differs from --dx 5mm --dy 1mm"

# 2. The [probe] table, as pdp synth's tips are written; the four-tip file's first pair on the channels mapped.
cat >"$dir/probe.toml" <<'TOML'
[probe]
tips = [["0mm", "0mm", "0mm"], ["5mm", "1.5mm", "0mm"], ["5mm", "0mm", "0mm"], ["5mm", "0mm", "1.5mm"]]
tip-channels = [0, 2, 1, 3]
TOML
"$pdp" --log-level error process "$dir/four.flac" --config "$dir/probe.toml" --method both --json "$dir/table.json" >/dev/null ||
  fail "[probe]"
"$pdp" --log-level error process "$dir/four.flac" --dx 5mm --dy 1.5mm --trailing-channel 2 --method both --json "$dir/pair.json" >/dev/null ||
  fail "pair"
[[ "$(result "$dir/table.json")" == "$(result "$dir/pair.json")" ]] || fail "[probe] with tip-channels differs from its pair"
printf '[probe]\ntips = [["0mm", "0mm", "0mm"], ["5mm", "0mm", "0mm"]]\nnp = 10\n' >"$dir/stray.toml"
expect 2 "stray.toml:3: [probe] holds tips, leading-tip, tip-channels; 'np' belongs at the top level or in [process]" \
  "$pdp" process "$dir/two.flac" --config "$dir/stray.toml"
printf 'tips = "0,0,0;5mm,0,0"\n[probe]\ntips = [["0mm", "0mm", "0mm"], ["5mm", "0mm", "0mm"]]\n' >"$dir/twice.toml"
expect 2 "twice.toml:1: tips is given again in [probe] (line 3); keep one" "$pdp" process "$dir/two.flac" --config "$dir/twice.toml"

# 3. Mistakes, each named with its fix; nothing written.
expect 2 "tips: point 1 '5,0,0', coordinate x: 5 has no unit: write 5mm (or the same as 0.005m) (--tips)" \
  "$pdp" process "$dir/two.flac" --tips "0,0,0;5,0,0" --json "$dir/x.json"
printf '[probe]\ntips = [["0mm", "0mm", "0mm"], ["5mm", "0mm", "0mm"], ["5mm", "0mm", "0mm"]]\n' >"$dir/twice_tip.toml"
expect 2 "twice_tip.toml:2: tips: tips 1 and 2 are both at (5mm, 0mm, 0mm) (tips are numbered from 0): a tip listed twice" \
  "$pdp" process "$dir/four.flac" --config "$dir/twice_tip.toml" --json "$dir/x.json"
expect 2 "dx (or dy) and tips both declare the probe's geometry" \
  "$pdp" process "$dir/two.flac" --tips "0,0,0;5mm,0,0" --dx 5mm --json "$dir/x.json"
expect 1 "two.flac: 4 tips are declared but the recording holds 2 channels: tip 2 has no channel" \
  "$pdp" process "$dir/two.flac" --tips "0,0,0;5mm,0,0;5mm,1.5mm,0;5mm,0,1.5mm" --json "$dir/x.json"
expect 1 "two.flac: tip 1 is mapped to channel 3, but the recording holds 2 channels (numbered from 0): correct its channel (--tip-channels)" \
  "$pdp" process "$dir/two.flac" --tips "0,0,0;5mm,0,0" --tip-channels 0,3 --json "$dir/x.json"
expect 2 "tip-channels: tips 0 and 1 are both mapped to channel 0" \
  "$pdp" process "$dir/two.flac" --tips "0,0,0;5mm,0,0" --tip-channels 0,0 --json "$dir/x.json"
[[ -e $dir/x.json ]] && fail "an output was written for a refused probe"

# 4. pdp synth's four-tip .h5 carries its tips: processed without them, refused when told otherwise.
"$pdp" --log-level error process "$dir/four.h5" --json "$dir/h5.json" >/dev/null || fail "four.h5 without a declaration"
/usr/bin/python3 -c "import json,sys; j=json.load(open(sys.argv[1])); assert abs(j['dx']-0.005)<1e-12, j['dx']" "$dir/h5.json" ||
  fail "four.h5: dx is not the file's 5 mm"
expect 1 "four.h5: tip 3 (channel 3, sensor 3) is (5mm, 0mm, 1.6mm) from the leading tip as declared (tips), but (5mm, 0mm, 1.5mm) as the file states" \
  "$pdp" process "$dir/four.h5" --tips "0,0,0;5mm,0,0;5mm,1.5mm,0;5mm,0,1.6mm"

exit $((failures > 0))

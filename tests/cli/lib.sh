# Helpers of the CLI test scripts (sourced): a failure counter, expected
# refusals, CSV columns by name.
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
# expect CODE TEXT CMD...: the command exits with CODE and its stderr holds TEXT.
expect() {
  local code=$1 text=$2
  shift 2
  local err
  err=$("$@" 2>&1 >/dev/null)
  local got=$?
  [[ $got -eq $code ]] || fail "$*: exit $got, expected $code ($err)"
  grep -qF -- "$text" <<<"$err" || fail "$*: message lacks '$text': $err"
}
# column FILE NAME: the cells of a named CSV column, header excluded.
column() {
  /usr/bin/python3 -c "import csv,sys; [print(r[sys.argv[2]]) for r in csv.DictReader(open(sys.argv[1]))]" "$1" "$2" 2>/dev/null
}
# sweep_rows FILE: a sweep CSV's rows without the run-time columns, sorted by
# run: what must not depend on threads, order or interruptions.
sweep_rows() {
  /usr/bin/python3 - "$1" <<'PY'
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
header, body = rows[0], rows[1:]
keep = [i for i, h in enumerate(header) if not h.startswith("seconds_")]
for r in sorted(body, key=lambda r: int(r[1])):
    print(",".join(r[i] for i in keep))
PY
}

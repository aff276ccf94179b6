#!/usr/bin/env python3
"""Compares fresh pdp outputs with the golden copies recorded before the
restructure of issue 11 (tests/golden/expected/).

"Unchanged" means: every key of a golden JSON and every column of a golden
CSV is still there with the same value (numbers to 1e-9 relative, text
exactly); outputs may gain keys and columns (they say more, not something
else). Run times (keys and columns starting with "seconds") are not compared;
"file" is compared by its base name (the tree may sit elsewhere). CSV rows are
matched by their key (file, or study and run) because a sweep writes rows in
the order they finish.

A value that changed on purpose is listed in changes.txt beside this script as
"FILE PATH  # why", PATH being a JSON path (/profile/3/awcc/reason, * for any
part) or a CSV column (all rows) or ROW/COLUMN (one row, by its key); each
such change is a defect named by issue 11 or a decision of issue 12.

Usage: compare.py EXPECTED_DIR ACTUAL_DIR
"""
import csv
import fnmatch
import json
import math
import os
import sys

REL = 1e-9


def load_changes():
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "changes.txt")
    allowed = []
    if os.path.exists(path):
        for line in open(path, encoding="utf-8"):
            line = line.split("#", 1)[0].strip()
            if line:
                name, pattern = line.split(None, 1)
                allowed.append((name, pattern.strip()))
    return allowed


ALLOWED = load_changes()


def allowed(name, path):
    return any(n == name and fnmatch.fnmatchcase(path, p) for n, p in ALLOWED)


def same_number(a, b):
    if a == b:
        return True
    if isinstance(a, bool) or isinstance(b, bool):
        return False
    if math.isnan(a) and math.isnan(b):
        return True
    return abs(a - b) <= REL * max(abs(a), abs(b)) + 1e-300


def compare_json(name, e, a, path, problems):
    key = path.rsplit("/", 1)[-1]
    if key.startswith("seconds"):
        return
    if allowed(name, path):
        return
    if isinstance(e, dict):
        if not isinstance(a, dict):
            problems.append(f"{name} {path}: was an object, now {type(a).__name__}")
            return
        for k, v in e.items():
            if k not in a:
                if not allowed(name, f"{path}/{k}"):
                    problems.append(f"{name} {path}/{k}: missing")
                continue
            compare_json(name, v, a[k], f"{path}/{k}", problems)
    elif isinstance(e, list):
        if not isinstance(a, list) or len(a) != len(e):
            problems.append(f"{name} {path}: list of {len(e)} became {a if not isinstance(a, list) else len(a)}")
            return
        for i, (x, y) in enumerate(zip(e, a)):
            compare_json(name, x, y, f"{path}/{i}", problems)
    elif isinstance(e, (int, float)) and not isinstance(e, bool):
        if not isinstance(a, (int, float)) or isinstance(a, bool) or not same_number(e, a):
            problems.append(f"{name} {path}: {e!r} became {a!r}")
    elif key == "file" and isinstance(e, str) and isinstance(a, str):
        if os.path.basename(e) != os.path.basename(a):
            problems.append(f"{name} {path}: {e!r} became {a!r}")
    elif e != a:
        problems.append(f"{name} {path}: {e!r} became {a!r}")


def number(text):
    try:
        return float(text)
    except ValueError:
        return None


def compare_csv(name, expected, actual, problems):
    e_rows = list(csv.DictReader(open(expected, newline="", encoding="utf-8")))
    a_rows = list(csv.DictReader(open(actual, newline="", encoding="utf-8")))
    if len(e_rows) != len(a_rows):
        problems.append(f"{name}: {len(e_rows)} rows became {len(a_rows)}")
        return
    if not e_rows:
        return

    def key(row, i):
        if "study" in row and "run" in row:
            return (row["study"], row["run"])
        if "file" in row:
            return os.path.basename(row["file"])
        return i

    a_by_key = {key(r, i): r for i, r in enumerate(a_rows)}
    for i, e in enumerate(e_rows):
        k = key(e, i)
        if k not in a_by_key:
            problems.append(f"{name}: row {k} missing")
            continue
        a = a_by_key[k]
        for column, ev in e.items():
            if column.startswith("seconds") or allowed(name, column) or allowed(name, f"{k}/{column}"):
                continue
            if column not in a:
                problems.append(f"{name}: column {column} missing")
                return
            av = a[column]
            en, an = number(ev), number(av)
            if en is not None and an is not None:
                if not same_number(en, an):
                    problems.append(f"{name} row {k} {column}: {ev} became {av}")
            elif ev != av:
                problems.append(f"{name} row {k} {column}: {ev!r} became {av!r}")


def main():
    expected_dir, actual_dir = sys.argv[1], sys.argv[2]
    problems, compared = [], 0
    for name in sorted(os.listdir(expected_dir)):
        expected = os.path.join(expected_dir, name)
        actual = os.path.join(actual_dir, name)
        if not os.path.exists(actual):
            problems.append(f"{name}: not written")
            continue
        if name.endswith(".json"):
            compare_json(name, json.load(open(expected)), json.load(open(actual)), "", problems)
        else:
            compare_csv(name, expected, actual, problems)
        compared += 1
    for p in problems[:200]:
        print("DIFF:", p)
    print(f"golden: {compared} files compared, {len(problems)} differences")
    return 1 if problems or compared == 0 else 0


if __name__ == "__main__":
    sys.exit(main())

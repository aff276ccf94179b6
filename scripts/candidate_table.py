#!/usr/bin/env python3
"""One row per trained candidate of scripts/time-prior-candidates, from the
must-show.md that scripts/train-time-prior-model wrote in its directory:
the base case's mean u error at 60 / 300 s, then for each foreign set under
the time prior (the full forest; the control also by the reduced forest)
"median |u error|, Tu bias, mean u error by band of true Tu".

Usage: candidate_table.py DIR...
"""
import os
import sys

SETS = [("control", "new full"), ("all-time", "new full"), ("poisson-time", "new full"), ("euler", "new full"),
        ("overlap", "new full"), ("ellipsoids", "new full"), ("lognormal", "new full"),
        ("control", "new reduced")]


def table_rows(path):
    """The must-show table's rows by (set, model), cells stripped of their marks."""
    out = {}
    with open(path, encoding="utf-8") as f:
        for line in f:
            cells = [c.strip().replace(" ✗", "").replace(" ✓", "") for c in line.strip().strip("|").split("|")]
            if len(cells) >= 7 and cells[0] not in ("set", "---"):
                out[(cells[0], cells[1])] = cells
    return out


def main(dirs):
    if not dirs:
        sys.exit(__doc__)
    present = []
    tables = {}
    for d in dirs:
        path = os.path.join(d, "must-show.md")
        if not os.path.exists(path):
            sys.exit(f"candidate_table.py: {path}: no must-show table (was the training run?)")
        tables[d] = table_rows(path)
    for key in SETS:
        if any(key in t for t in tables.values()):
            present.append(key)
    head = ["candidate", "base case u 60 / 300 s"] + [f"{s}{'' if m == 'new full' else ' (reduced)'}" for s, m in present]
    print("| " + " | ".join(head) + " |")
    print("|" + "---|" * len(head))
    for d, t in tables.items():
        def mean_u(name):
            row = t.get((name, "new"))
            return row[4] if row else "-"
        cells = [os.path.basename(d.rstrip("/")), f"{mean_u('base case 60 s')} / {mean_u('base case 300 s')} %"]
        for key in present:
            row = t.get(key)
            cells.append(f"{row[3].split('->')[-1].strip()} %, {row[5]}, {row[6]}" if row else "-")
        print("| " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main(sys.argv[1:])

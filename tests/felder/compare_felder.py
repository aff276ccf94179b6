#!/usr/bin/python3
"""Felder parity: `pdp process --preset felder` against the printed outputs of
Felder's program (felder-program.md), digit for digit.

Each number his program printed is compared with pdp's value formatted to the
same number of decimals (Fortran's F edit descriptor rounds the binary value
to nearest, as printf does). His sentinels (97, 98, 99 for a scale not
reached) must be empty values in pdp; his NaN (0/0) likewise.

usage: compare_felder.py PDP DATA_DIR REFERENCE_DIR WORK_DIR FILE:LABEL ...
  REFERENCE_DIR holds length/ and time/ as his program writes them.
Exit 0 when every number agrees, 1 with a list of the disagreements.
"""
import json
import math
import os
import re
import subprocess
import sys


def decimals(token):
    return len(token.split(".")[1]) if "." in token else 0


class Checker:
    def __init__(self):
        self.compared = 0
        self.failures = []

    def number(self, where, token, ours, scale=1.0):
        """his printed token against our value (times scale)."""
        self.compared += 1
        if token.upper() == "NAN":
            if ours is not None and not (isinstance(ours, float) and math.isnan(ours)):
                self.failures.append(f"{where}: his NaN, ours {ours}")
            return
        if ours is None:
            self.failures.append(f"{where}: his {token}, ours empty")
            return
        mine = "%.*f" % (decimals(token), ours * scale)
        if mine == "-" + token.lstrip("-") and float(token) == 0.0:
            mine = token  # -0.00 and 0.00
        if mine.lstrip() != token.lstrip() and not (float(mine) == 0.0 and float(token) == 0.0):
            self.failures.append(f"{where}: his {token}, ours {mine} ({ours * scale!r})")

    def sentinel(self, where, token, ours, sentinel, scale=1.0):
        if float(token) == sentinel:
            self.compared += 1
            if ours is not None:
                self.failures.append(f"{where}: his sentinel {token} (not reached), ours {ours}")
        else:
            self.number(where, token, ours, scale)


def rows(path):
    with open(path) as f:
        return [line.split() for line in f if line.strip()]


def block_of(table, label):
    """The rows of a position's block: from the row naming it to the next position row."""
    for i, row in enumerate(table):
        if row and (row[0] == label or row[0] == label + ":" or (len(row) > 1 and row[1] in (label, label + ":"))):
            return i
    raise KeyError(label)


def main():
    pdp, data, reference, work = sys.argv[1:5]
    files = [a.split(":") for a in sys.argv[5:]]
    os.makedirs(work, exist_ok=True)
    out = os.path.join(work, "felder.json")
    subprocess.run([pdp, "process", *[os.path.join(data, f) for f, _ in files], "--fs", "20kHz", "--dx", "7.15mm",
                    "--preset", "felder", "--json", out,
                    "--correlation-functions", os.path.join(work, "functions.csv"), "--csv", os.path.join(work, "felder.csv")], check=True,
                   stdout=subprocess.DEVNULL)
    with open(out) as f:
        doc = json.load(f)
    results = doc["profile"] if "profile" in doc else [doc]
    check = Checker()
    for (name, label), r in zip(files, results):
        fs = r["fscc"]
        s = r["structure"]
        ref = os.path.join(reference, "length")
        # Correlation scales and velocity.
        tu = rows(os.path.join(ref, "Tu_V_summary.txt"))
        row = tu[block_of(tu, label)][1:]
        # His columns in order: (name, our key, his sentinel for "not reached" or None).
        columns = [("T0.5", "t05", None), ("T(Rxx=0)", "t_r11_zero", 99), ("T(Min(Rxx))", "t_r11_min", None),
                   ("Min(Rxx)", "r11_min", None), ("Txx", "txx", None), ("(Rxz)max", "r12_max", None),
                   ("T(Rxz)max", "lag", None), ("T(Rxz=0)", "t_r12_zero", 98), ("T(Min(Rxz))", "t_r12_min", None),
                   ("Min(Rxz)", "r12_min", None), ("T(0.5(Rxz)max)", "t_half", None), ("Txz", "txy", None),
                   ("Tu", "turbulence_intensity_chanson", 97), ("V", "velocity", None)]
        for token, (column, key, sentinel) in zip(row, columns):
            where = f"{label} Tu_V_summary {column}"
            if sentinel is None:
                check.number(where, token, fs[key])
            else:
                check.sentinel(where, token, fs[key], sentinel)
        # C and F of both tips.
        basics = rows(os.path.join(ref, "basics_summary.txt"))
        row = basics[block_of(basics, label)][1:]
        for k, (tip, key) in enumerate([(0, "void_fraction"), (0, "bubble_count_rate"), (1, "void_fraction"),
                                        (1, "bubble_count_rate")]):
            check.number(f"{label} basics {k}", row[k], s["felder_counts"][tip][key])
        # Correlation functions.
        for fname, key, first in ((f"{label}_autocor.txt", "r11", 0), (f"{label}_crosscor.txt", "r12", -199)):
            table = rows(os.path.join(ref, fname))[1:]
            functions = functions_of(work, name)
            for i, row in enumerate(table):
                lag = first + i
                check.number(f"{fname} lag {lag}", row[1], functions[key].get(lag))
        # Voltage PDFs.
        table = rows(os.path.join(ref, f"{label}_PDF_V.txt"))[1:]
        for i, row in enumerate(table):
            check.number(f"{label}_PDF_V upper edge {i}", row[0], s["voltage_pdf"]["leading"]["upper"][i])
            check.number(f"{label}_PDF_V leading {i}", row[1], s["voltage_pdf"]["leading"]["fraction"][i])
            check.number(f"{label}_PDF_V trailing {i}", row[2], s["voltage_pdf"]["trailing"]["fraction"][i])
        # Chord PDFs.
        for fname, key, scale in (("chordlength_summary.txt", "chord_length_pdf", 1e3),
                                  ("chordtime_summary.txt", "chord_time_pdf", 1e3)):
            table = rows(os.path.join(ref, fname))
            i = block_of(table, label)
            pdf = s[key]
            for k, token in enumerate(table[i][1:]):
                check.number(f"{label} {fname} label {k}", token, pdf["lower_edges"][k], scale)
            for k, token in enumerate(table[i + 1][1:]):
                check.number(f"{label} {fname} f(a) {k}", token, pdf["air_fraction"][k])
            for k, token in enumerate(table[i + 2][1:]):
                check.number(f"{label} {fname} f(w) {k}", token, pdf["water_fraction"][k])
        # Clusters and arrivals, length and time.
        for mode, suffix in (("length", ""), ("time", "_time")):
            ref = os.path.join(reference, mode)
            clusters = s["clusters"][mode]
            for criterion, stem in (("median", "cluster_summary"), ("constant", "cluster_summary_constant_criterion_1mm"),
                                    ("near_wake", "cluster_summary_wake_criterion")):
                table = rows(os.path.join(ref, stem + suffix + ".txt"))
                i = block_of(table, label)
                w = f"{label} {stem}{suffix}"
                if "no" in table[i] and "cluster" in " ".join(table[i]):
                    check.compared += 1
                    if clusters["status"] != "intermediate_void_fraction":
                        check.failures.append(f"{w}: his 'no cluster analyses', ours {clusters['status']}")
                    continue
                c = clusters["criteria"][criterion]
                row = table[i][1:]
                check.number(w + " C", row[0], s["felder_counts"][0]["void_fraction"])
                # His nine values after C: (name, our key, scale to his units).
                summary = [("No_in_cluster", "n_in_clusters", 1), ("%", "pct_in_clusters", 1),
                           ("No_of_clusters", "n_clusters", 1), ("per_s", "clusters_per_s", 1),
                           ("ave_no", "mean_particles_per_cluster", 1), ("ave_size", "mean_chord_in_cluster", 1e3),
                           ("ratio", "ratio_cluster_chord_to_mean_chord", 1),
                           ("lead", "ratio_lead_to_cluster_mean_chord", 1)]
                for token, (column, key, scale) in zip(row[1:], summary):
                    check.number(f"{w} {column}", token, c[key], scale)
                pdf_stem = stem.replace("cluster_summary", "cluster_no_PDF")
                table = rows(os.path.join(ref, pdf_stem + suffix + ".txt"))
                i = block_of(table, label)
                for k, token in enumerate(table[i + 1][1:]):
                    check.number(f"{w} size PDF {k}", token, None if c["size_pdf"] is None else c["size_pdf"][k])
            table = rows(os.path.join(ref, f"interparticle_arrival_time_summary{suffix}.txt"))
            i = block_of(table, label)
            w = f"{label} interparticle{suffix}"
            arrivals = s["arrivals"][mode]
            if "no" in table[i]:
                check.compared += 1
                if arrivals["status"] != "intermediate_void_fraction":
                    check.failures.append(f"{w}: his 'no interparticle analyses', ours {arrivals['status']}")
                continue
            for k, cls in enumerate(arrivals["classes"]):
                observed, poisson = table[i + 1 + 2 * k], table[i + 2 + 2 * k]
                check.number(f"{w} class {k} N", observed[1], cls["particles"])
                for m in range(100):
                    check.number(f"{w} class {k} PDF bin {m + 1}", observed[2 + m],
                                 None if cls["pdf"] is None else cls["pdf"][m])
                    check.number(f"{w} class {k} Poisson bin {m + 1}", poisson[2 + m],
                                 None if cls["reference"] is None else cls["reference"][m])
    for line in check.failures[:60]:
        print("DIFF:", line)
    print(f"felder parity: {check.compared} printed numbers compared, {len(check.failures)} differ")
    return 1 if check.failures else 0


_functions = {}


def functions_of(work, name):
    """R11 and R12 by lag (samples) from pdp's --correlation-functions CSV."""
    if not _functions:
        with open(os.path.join(work, "functions.csv")) as f:
            next(f)
            for line in f:
                file, lag, r11, r12 = line.rstrip("\n").split(",")
                entry = _functions.setdefault(file, {"r11": {}, "r12": {}})
                k = round(float(lag) * 20000)
                if r11:
                    entry["r11"][k] = float(r11)
                if r12:
                    entry["r12"][k] = float(r12)
    return _functions[os.path.basename(name)]


if __name__ == "__main__":
    sys.exit(main())

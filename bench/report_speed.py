"""pdp report on the ten-file real profile (docs/performance.md): the whole
command, its parts, and pdp process with and without --report. Usage:
/usr/bin/python3 bench/report_speed.py build/tools/pdp ../shared/data/felder-stepped-spillway [SCRATCH]"""
import glob
import os
import statistics
import subprocess
import sys
import tempfile
import time

cli, data = sys.argv[1], sys.argv[2]
scratch = sys.argv[3] if len(sys.argv) > 3 else tempfile.mkdtemp(prefix="pdp-report-bench-")
files = sorted(glob.glob(f"{data}/dc157_*.dat"))
positions = "2mm,8mm,14mm,20mm,26mm,32mm,38mm,44mm,50mm,54mm"
process = [cli, "--log-level", "error", "process", *files, "--fs", "20kHz", "--dx", "7.15mm", "--positions", positions,
           "--correct", "samples/model/awcc.qrf", "--csv", os.devnull]
profile = os.path.join(scratch, "profile.json")
page = os.path.join(scratch, "report.html")


def times(command, repeat):
    out = []
    for _ in range(repeat):
        start = time.perf_counter()
        subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        out.append(time.perf_counter() - start)
    return out


def show(name, t):
    print(f"{name:58s} median {statistics.median(t):.2f} s, range {min(t):.2f}-{max(t):.2f} s (n={len(t)})")


subprocess.run(process + ["--json", profile], check=True)  # the profile, and a warm page cache
show("pdp process, ten files, corrected (no report)", times(process + ["--json", profile], 9))
show("pdp process ... --report (processing and the report)", times(process + ["--report", page], 5))
show("pdp report PROFILE.json (ten positions drawn)", times([cli, "report", profile, "-o", page], 5))
show("pdp report PROFILE.json --no-detail (profile figures only)", times([cli, "report", profile, "-o", page,
                                                                          "--no-detail"], 5))
show("pdp report PROFILE.json --jobs 1 (one drawing process)", times([cli, "report", profile, "-o", page, "--jobs",
                                                                      "1"], 3))
print(f"page: {os.path.getsize(page) / 1e6:.2f} MB, cores: {os.cpu_count()}")

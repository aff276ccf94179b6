"""The Python module's call overhead against the command line on the ten real
recordings (docs/performance.md). Usage:
PYTHONPATH=build/python /usr/bin/python3 bench/python_overhead.py build/tools/pdp ../shared/data/felder-stepped-spillway"""
import glob
import subprocess
import sys
import time

import pdp

cli, data = sys.argv[1], sys.argv[2]
files = sorted(glob.glob(f"{data}/dc157_*.dat"))
args = dict(fs=20e3, dx=7.15e-3)


def best(run, repeat=5):
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        run()
        times.append(time.perf_counter() - start)
    return min(times)


pdp.process(files[0], **args)  # warm-up: pages, FFT plans
t_cli = best(lambda: subprocess.run([cli, "--log-level", "error", "process", *files, "--fs", "20kHz", "--dx", "7.15mm",
                                     "--json", "/dev/null", "--csv", "/dev/null"], check=True))
t_py = best(lambda: pdp.process(files, **args))
print(f"pdp process (whole command): {t_cli:.3f} s")
print(f"pdp.process in Python:       {t_py:.3f} s ({100 * (t_py - t_cli) / t_cli:+.1f} %)")

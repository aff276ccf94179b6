"""samples/python/profile.py runs on the real profile and draws its figure."""

import os
import subprocess
import sys

from conftest import SOURCE


def test_the_profile_sample_runs(real_files, scratch):
    png = scratch / "profile.png"
    out = subprocess.run([sys.executable, SOURCE / "samples" / "python" / "profile.py", real_files[0].parent, png],
                         check=True, capture_output=True, text=True, env=os.environ).stdout
    lines = out.splitlines()
    assert len(lines) == len(real_files)
    # The three deepest positions are corrected (quality ok), as the CLI reports.
    assert [line.split()[-1] for line in lines[-3:]] == ["corrected"] * 3
    assert png.stat().st_size > 10_000 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"

"""Fixtures of the pytest suite: the pdp command line built beside the
module (PDP_CLI), the real recordings (../shared/data) and a scratch folder."""

import json
import os
import pathlib
import subprocess

import pytest

SOURCE = pathlib.Path(os.environ.get("PDP_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
DATA = SOURCE.parent / "shared" / "data" / "felder-stepped-spillway"
MODEL = SOURCE / "samples" / "model" / "awcc.qrf"


@pytest.fixture(scope="session")
def cli():
    path = os.environ.get("PDP_CLI")
    if not path or not os.path.exists(path):
        pytest.skip("PDP_CLI is not set to the pdp command line (ctest sets it)")

    def run(*args):
        """Runs pdp with args; returns the JSON it wrote with --json."""
        subprocess.run([path, "--log-level", "error", *map(str, args)], check=True, stdout=subprocess.DEVNULL)

    return run


def made(*args, cwd=None):
    """Runs pdp with args (quiet) and asserts it succeeded; skips without PDP_CLI."""
    path = os.environ.get("PDP_CLI")
    if not path or not os.path.exists(path):
        pytest.skip("PDP_CLI is not set to the pdp command line (ctest sets it)")
    done = subprocess.run([path, "--log-level", "error", *map(str, args)], capture_output=True, text=True, cwd=cwd)
    assert done.returncode == 0, done.stderr


@pytest.fixture(scope="session")
def real_files():
    if not DATA.is_dir():
        pytest.skip(f"{DATA} is absent: the real recordings are not compared")
    return sorted(DATA.glob("dc157_*.dat"))


@pytest.fixture()
def scratch(tmp_path):
    return tmp_path


def load(path):
    with open(path) as f:
        return json.load(f)


def without_provenance(j):
    j = dict(j)
    j.pop("provenance", None)
    return j

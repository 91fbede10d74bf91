"""Shared fixtures of the Python tests (run by CTest with Debian's /usr/bin/python3.11).

HOMESH_BUILD_DIR points at the CMake build tree; its staged workbench folder Mod/HOMesh holds
the `homesh` package with the compiled core.
"""

import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BUILD = Path(os.environ.get("HOMESH_BUILD_DIR", ROOT / "build"))
sys.path.insert(0, str(BUILD / "Mod" / "HOMesh"))
DATA = ROOT / "tests" / "data"


@pytest.fixture(scope="session")
def homesh_bin():
    path = BUILD / "bin" / "homesh"
    assert path.is_file(), "build the project first: %s is missing" % path
    return str(path)


@pytest.fixture(scope="session")
def data():
    return DATA


def run(args, **kwargs):
    """Runs a command, returning the CompletedProcess (text mode, never raises on failure)."""
    kwargs.setdefault("timeout", 600)
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, **kwargs)


def stages_run(stderr):
    """The stages the CLI reported timings for ("homesh: linear        0.051 s" lines): a test
    matching a stage's name anywhere in stderr would also match it in a temporary path."""
    return re.findall(r"^homesh: (\w+(?: \d+)?) +[0-9.]+ s$", stderr, re.M)

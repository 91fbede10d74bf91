"""Shared fixtures of the Python tests (run by CTest with Debian's /usr/bin/python3.11).

HOMESH_BUILD_DIR points at the CMake build tree; its staged workbench folder Mod/HOMesh holds
the `homesh` package with the compiled core.
"""

import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
BUILD = Path(os.environ.get("HOMESH_BUILD_DIR", ROOT / "build"))
sys.path.insert(0, str(BUILD / "Mod" / "HOMesh"))
DATA = ROOT / "tests" / "data"

# NekMesh's peer files (another project's test data, never in the repository): looked up at run
# time, $HOMESH_SHARED_DIR first, then the `shared` folder beside the clone. Tests that need them
# call needs_peer_files() and are reported skipped, naming the folder, where it is absent; each
# has a sibling on data the repository holds or the test makes.
SHARED = Path(os.environ.get("HOMESH_SHARED_DIR") or (ROOT.parent / "shared"))
PEER_CASES = SHARED / "peer-cases" / "nekmesh"


def needs_peer_files():
    """Skips the calling test when the peer folder is absent (a missing file inside a present
    folder is left to fail: it is the test's error, not the machine's)."""
    if not PEER_CASES.is_dir():
        pytest.skip("NekMesh's peer files are not here: %s not found (put the shared folder "
                    "beside the clone or set HOMESH_SHARED_DIR)" % PEER_CASES)


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
    # A timeout here only turns a hang into a failure; it is never a speed bound, so it is at
    # least 900 s whatever the test asks (a loaded 2-core machine runs its commands several
    # times slower than an idle one).
    kwargs["timeout"] = max(kwargs.get("timeout", 0), 900)
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, **kwargs)


def stages_run(stderr):
    """The stages the CLI reported timings for ("homesh: linear        0.051 s" lines): a test
    matching a stage's name anywhere in stderr would also match it in a temporary path."""
    return re.findall(r"^homesh: (\w+(?: \d+)?) +[0-9.]+ s$", stderr, re.M)


def gmsh_worst(path, dim=3):
    """Gmsh's own verdict on a mesh file: the worst min J / max J over its elements of dimension
    `dim`, from Debian's `gmsh` running its Plugin(AnalyseMeshQuality) (Bezier bounds, so it
    cannot miss a negative Jacobian between sample points): an independent judge of what we
    certify. Fails, naming the file, where Gmsh cannot analyse it."""
    with tempfile.TemporaryDirectory(prefix="homesh-gmsh-verdict-") as folder:
        script = Path(folder) / "verdict.geo"
        script.write_text('Merge "%s";\n' % Path(path).resolve()
                          + "Plugin(AnalyseMeshQuality).JacobianDeterminant = 1;\n"
                          + "Plugin(AnalyseMeshQuality).IGEMeasure = 0;\n"
                          + "Plugin(AnalyseMeshQuality).ICNMeasure = 0;\n"
                          + "Plugin(AnalyseMeshQuality).DimensionOfElements = %d;\n" % dim
                          + "Plugin(AnalyseMeshQuality).CreateView = 0;\n"
                          + "Plugin(AnalyseMeshQuality).Run;\n")
        out = run(["gmsh", script, "-0", "-nopopup"])
    found = re.findall(r"minJ/maxJ\s*=\s*([-+0-9.eE]+).*\(worst, avg, best\)", out.stdout + out.stderr)
    assert found, "Gmsh could not analyse %s: %s" % (path, (out.stdout + out.stderr)[-2000:])
    return float(found[-1])

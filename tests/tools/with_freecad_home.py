#!/usr/bin/python3
"""Runs a command with a throw-away FreeCAD user folder that has the HOMesh workbench in it.

usage: with_freecad_home.py BUILD_DIR COMMAND [ARGS...]

HOME and FREECAD_USER_HOME point at a fresh temporary folder whose Mod/HOMesh is a symlink to
the staged workbench (BUILD_DIR/Mod/HOMesh), so tests neither read nor write the user's FreeCAD
configuration, and TMPDIR points at a folder inside it, so that what FreeCAD and HOMesh write
there (and what a test finds there) is this run's alone, whatever runs beside it. The command's exit status is returned; the folder is removed afterwards unless
HOMESH_KEEP_HOME is set.
"""

import os
import shutil
import subprocess
import sys
import tempfile


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    build = os.path.abspath(sys.argv[1])
    workbench = os.path.join(build, "Mod", "HOMesh")
    if not os.path.isfile(os.path.join(workbench, "InitGui.py")):
        sys.exit("no staged workbench in %s: build the project first" % workbench)
    home = tempfile.mkdtemp(prefix="homesh-freecad-home-")
    try:
        os.makedirs(os.path.join(home, "Mod"))
        os.makedirs(os.path.join(home, "tmp"))
        os.symlink(workbench, os.path.join(home, "Mod", "HOMesh"))
        env = dict(os.environ, HOME=home, FREECAD_USER_HOME=home, HOMESH_BUILD_DIR=build,
                   TMPDIR=os.path.join(home, "tmp"),
                   QTWEBENGINE_CHROMIUM_FLAGS="--no-sandbox")
        return subprocess.call(sys.argv[2:], env=env)
    finally:
        if not os.environ.get("HOMESH_KEEP_HOME"):
            shutil.rmtree(home, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())

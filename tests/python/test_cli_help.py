"""`homesh --man` is the manual page of every command, made from the same help texts (which
list the parameter table's options with their ranges: tests/cpp/cli/test_arguments.cpp), and a
page man reads."""

import shutil
import subprocess

import pytest

from conftest import run


def _one_line(text):
    return " ".join(text.split())  # a range may be wrapped over two lines


def test_the_manual_page_is_every_commands_help(homesh_bin, tmp_path):
    r = run([homesh_bin, "--man"])
    assert r.returncode == 0, r.stderr
    assert r.stdout.startswith(".TH HOMESH 1")
    for command in ("mesh", "predict", "quality", "convert", "optimise"):
        assert '.SH "HOMESH %s"' % command in r.stdout
    if shutil.which("man") is None:
        pytest.skip("man is not installed (scripts/install-deps.sh installs man-db)")
    page = tmp_path / "homesh.1"
    page.write_text(r.stdout)
    shown = subprocess.run(["man", "-l", str(page)], capture_output=True, text=True,
                           env={"MANWIDTH": "100", "PATH": "/usr/bin:/bin", "MANPAGER": "cat"},
                           timeout=120)
    assert shown.returncode == 0, shown.stderr
    text = _one_line(shown.stdout)
    assert "--order N" in text and "an integer from 1 to 10" in text
    assert "troff" not in shown.stderr and "warning" not in shown.stderr, shown.stderr

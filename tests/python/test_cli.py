"""`homesh mesh` end to end: files that Gmsh and meshio read, nodes on the CAD, report counts
that match the files, and clear errors with non-zero exit codes."""

import json
import os
import shutil

import meshio
import numpy as np
import pytest

from conftest import run


@pytest.fixture(scope="module")
def sphere_run(tmp_path_factory, homesh_bin, data):
    out = tmp_path_factory.mktemp("sphere")
    msh, vtu, report = out / "sphere.msh", out / "sphere.vtu", out / "report.json"
    result = run([homesh_bin, "mesh", data / "sphere.brep", "--order", "4", "--size", "0.3",
                  "-o", msh, "-o", vtu, "--report", report])
    assert result.returncode == 0, result.stderr
    return {"msh": msh, "vtu": vtu, "report": json.loads(report.read_text()), "dir": out}


def test_gmsh_opens_the_msh_and_sees_the_same_elements(sphere_run):
    gmsh = shutil.which("gmsh")
    assert gmsh, "Debian's gmsh package is needed"
    copy = sphere_run["dir"] / "resaved.msh"
    result = run([gmsh, sphere_run["msh"], "-0", "-o", copy, "-format", "msh41"])
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Error" not in result.stdout + result.stderr
    resaved = meshio.read(copy)
    original = meshio.read(sphere_run["msh"])
    assert {c.type: len(c.data) for c in resaved.cells} == \
        {c.type: len(c.data) for c in original.cells}
    assert len(resaved.points) == len(original.points)


def test_boundary_nodes_lie_on_the_sphere(sphere_run):
    mesh = meshio.read(sphere_run["msh"])
    boundary = np.unique(np.concatenate(
        [c.data.ravel() for c in mesh.cells if c.type.startswith("triangle")]))
    assert len(boundary) > 1000  # 2850 measured; Gmsh's count moves by a few % with last bits
    # Points of OCCT's sphere, written with 17 digits: 1 to rounding (~1e-15); 1e-7 is slack.
    radius = np.linalg.norm(mesh.points[boundary], axis=1)
    assert np.max(np.abs(radius - 1.0)) < 1e-7
    # Interior nodes are inside.
    assert np.max(np.linalg.norm(mesh.points, axis=1)) < 1.0 + 1e-7


def test_report_counts_match_the_file(sphere_run):
    report = sphere_run["report"]
    mesh = meshio.read(sphere_run["msh"])
    cells = {c.type: len(c.data) for c in mesh.cells}
    assert report["order"] == 4
    assert report["nodes"] == len(mesh.points)
    assert report["elements"]["tet"] == cells["tetra35"]
    assert report["boundary"]["tri"] == cells["triangle15"]
    for key in ("prism", "pyramid", "hex", "tri", "quad"):
        assert report["elements"][key] == 0
    quality = report["quality"]
    assert quality["invalid_elements"] == 0
    assert 0.0 < quality["scaled_jacobian"]["min"] <= quality["scaled_jacobian"]["mean"] <= 1.0
    assert set(report["timings_s"]) >= {"cad", "linear", "high_order", "geometry", "output"}
    # The worst boundary point lies max_distance off the unit sphere (closed form), to the CAD
    # projection's precision (1e-9 of the diagonal).
    geometry = report["geometry"]
    worst = np.linalg.norm(geometry["worst_point"])
    assert abs(worst - 1.0) == pytest.approx(geometry["max_distance"],
                                             abs=1e-9 * geometry["diagonal"])
    assert geometry["worst_entity"] == "Face1" or geometry["worst_entity"].startswith("Edge")
    # The per-element field in the file is the one the report summarises.
    # The same double, in the MSH file with 17 digits and in the JSON with 15 (5e-16 relative).
    field = np.asarray(mesh.cell_data["scaled_jacobian"][
        [c.type for c in mesh.cells].index("tetra35")])
    assert abs(field.min() - quality["scaled_jacobian"]["min"]) <= 1e-14 * abs(field.min())


def test_meshio_reads_the_vtu(sphere_run):
    mesh = meshio.read(sphere_run["vtu"])
    assert len(mesh.points) == sphere_run["report"]["nodes"]
    assert sum(len(c.data) for c in mesh.cells) == sphere_run["report"]["elements"]["tet"]
    assert "scaled_jacobian" in mesh.cell_data


def test_stdout_report_and_quiet(homesh_bin, data):
    result = run([homesh_bin, "mesh", data / "box_hole.step", "--order", "2", "--size", "1",
                  "--report", "-", "-q"])
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""
    assert json.loads(result.stdout)["elements"]["tet"] > 0


def _expect_failure(result, code, *words):
    assert result.returncode == code, (result.returncode, result.stderr)
    lines = result.stderr.strip().splitlines()
    errors = [line for line in lines if "error" in line]
    assert errors == lines[-1:], result.stderr  # one error line, the last one
    assert errors[0].startswith("homesh: error: ")
    for word in words:
        assert word in errors[0], errors[0]


def test_bad_inputs_give_one_line_errors(homesh_bin, data, tmp_path):
    _expect_failure(run([homesh_bin, "mesh", tmp_path / "missing.step"]), 1,
                    "missing.step", "does not exist")
    fake = tmp_path / "notes.step"
    fake.write_text("just some text\n")
    _expect_failure(run([homesh_bin, "mesh", fake]), 1, "notes.step", "not a readable STEP")
    _expect_failure(run([homesh_bin, "mesh", data / "sphere.brep", "--order", "0"]), 2, "--order")
    _expect_failure(run([homesh_bin, "mesh", data / "sphere.brep", "--size", "-1"]), 2, "--size")
    # Bad output paths are refused before any meshing is done.
    result = run([homesh_bin, "mesh", data / "sphere.brep", "-o", tmp_path / "x.stl"])
    _expect_failure(result, 1, "x.stl", "unknown mesh format")
    assert len(result.stderr.strip().splitlines()) == 1
    _expect_failure(run([homesh_bin, "mesh", data / "sphere.brep", "-o", tmp_path / "no" / "x.msh"]),
                    1, "does not exist")
    _expect_failure(run([homesh_bin, "mesh", data / "sphere.brep", "--size", "1e-6"]), 2,
                    "too small")
    _expect_failure(run([homesh_bin, "frobnicate"]), 2, "frobnicate")
    assert not (tmp_path / "x.stl").exists()


def test_fifos_and_folders_are_refused_not_waited_on(homesh_bin, tmp_path):
    # Opening a FIFO blocks until another process writes to it: every reader must refuse it at
    # once (the timeout turns a hang into a failure).
    for name, command in [("in.step", "mesh"), ("in.msh", "quality"), ("in.mcf", "mesh")]:
        fifo = tmp_path / name
        os.mkfifo(fifo)
        _expect_failure(run([homesh_bin, command, fifo], timeout=30), 1, name,
                        "not a regular file")
    _expect_failure(run([homesh_bin, "mesh", tmp_path]), 1, "is a directory")


def test_verbose_gmsh_output_stays_off_stdout(homesh_bin, data):
    result = run([homesh_bin, "mesh", data / "sphere.brep", "--size", "0.5", "--order", "2",
                  "-vv", "--report", "-"])
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["order"] == 2
    assert "gmsh: " in result.stderr


def test_bad_report_path_fails_before_meshing(homesh_bin, data, tmp_path):
    out = tmp_path / "mesh.msh"
    result = run([homesh_bin, "mesh", data / "sphere.brep", "-o", out,
                  "--report", tmp_path / "nowhere" / "r.json"])
    _expect_failure(result, 1, "nowhere")
    assert not out.exists()


def test_numbers_are_strict_and_sizes_sane(homesh_bin, data):
    _expect_failure(run([homesh_bin, "mesh", data / "sphere.brep", "--size", "0x10"]), 2,
                    "--size")
    _expect_failure(run([homesh_bin, "mesh", data / "sphere.brep", "--size", "inf"]), 2, "--size")
    _expect_failure(run([homesh_bin, "mesh", data / "sphere.brep", "-j", "100000"]), 2,
                    "--threads")
    _expect_failure(run([homesh_bin, "mesh", data / "sphere.brep", "--size", "5"]), 2,
                    "not smaller than")


def test_help_and_version(homesh_bin):
    assert run([homesh_bin, "--help"]).returncode == 0
    assert "--order" in run([homesh_bin, "mesh", "--help"]).stdout
    assert run([homesh_bin, "--version"]).stdout.startswith("homesh ")

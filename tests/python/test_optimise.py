"""`homesh optimise` and `HighOrderMesh.optimise`: the per-sweep log, the report's "optimiser"
record, Gmsh's independent verdict on the result, untangling the sphere in a box that Gmsh
leaves invalid at order 4, fixed boundaries, and clear errors."""

import gzip
import json
import re
import subprocess
from pathlib import Path

import meshio
import numpy as np
import pytest

from conftest import run
from homesh import ParameterError, read

SHARED = Path(__file__).resolve().parents[3] / "shared"
PEERS = SHARED / "peer-cases" / "nekmesh" / "optimiser"
NACA = PEERS / "varopti_naca.msh"
CUBE_SPHERE = PEERS / "varopti_cube_sphere.msh"
GMSH_VERDICT = SHARED / "tools" / "gmsh-worst-quality"

# How tests/data/sphere_in_box_p4.msh.gz was made (gmsh t.geo -3, Gmsh 4.8.4). The file is
# stored because Gmsh's mesh of this .geo changes with the last bits of its input: with the
# sphere's radius 1 - 1e-12 it is an untangled mesh of 1211 elements, not this tangled one of
# 1194 (bench/tolerance_sensitivity.cpp, docs/testing.md).
SPHERE_IN_BOX = """SetFactory("OpenCASCADE");
Box(1) = {-2, -2, -2, 4, 4, 4};
Sphere(2) = {0, 0, 0, 1};
BooleanFragments{ Volume{1}; Delete; }{ Volume{2}; Delete; }
Mesh.MeshSizeMax = 1.2;
Mesh.ElementOrder = 4;
Mesh.HighOrderOptimize = 0;
Mesh.MshFileVersion = 4.1;
"""


def gmsh_worst(path, dim=3):
    out = subprocess.run([str(GMSH_VERDICT), str(path), str(dim)], capture_output=True, text=True,
                         check=True).stdout
    return float(re.search(r"minJ/maxJ\s*=\s*([-+0-9.eE]+)", out).group(1))


@pytest.fixture(scope="module")
def tangled(tmp_path_factory, data):
    """Gmsh's order-4 sphere in a box (SPHERE_IN_BOX): boundary nodes on the sphere, negative
    Jacobians inside."""
    path = tmp_path_factory.mktemp("tangled") / "t.msh"
    path.write_bytes(gzip.decompress((data / "sphere_in_box_p4.msh.gz").read_bytes()))
    return path


def test_optimise_command_logs_each_sweep_and_reports(homesh_bin, tmp_path):
    out, report = tmp_path / "naca.msh", tmp_path / "r.json"
    r = run([homesh_bin, "optimise", str(NACA), "-f", "linearelastic", "-n", "5", "-j", "2",
             "-o", str(out), "--report", str(report)])
    assert r.returncode == 0, r.stderr
    sweeps = [l for l in r.stderr.splitlines() if re.search(r"iteration +\d+ +worst scaled", l)]
    assert len(sweeps) == 5 and all("invalid 0" in l for l in sweeps)
    rep = json.loads(report.read_text())
    o = rep["optimiser"]
    for key in ("functional", "iterations", "worst_before", "worst_after", "invalid_before",
                "invalid_after", "seconds"):
        assert key in o
    assert o["functional"] == "linearelastic" and o["iterations"] == 5
    assert o["invalid_after"] == 0 and len(o["history"]) == 5
    # NekMesh's regression value (at the nodes; its .tst: 0.872585, tolerance 5e-3); ours is
    # 0.8840 and moves by 6e-12 with the input's last bits or the thread count.
    assert o["nodal_worst_after"] >= 0.8726
    assert o["worst_after"] > o["worst_before"] + 0.4  # measured 0.527, spread 1e-12
    # The same double printed twice with %.15g: equal (the slack is the format's 5e-16).
    assert rep["quality"]["scaled_jacobian"]["min"] == pytest.approx(o["worst_after"], abs=1e-12)
    # Gmsh's own Bezier-bounded verdict on the written file agrees: both are lower bounds
    # within 1e-3 (relative to max J) of the same minimum, refined independently.
    assert gmsh_worst(out, 2) == pytest.approx(o["worst_after"], abs=1e-3)
    mesh = meshio.read(out)
    assert sum(len(c.data) for c in mesh.cells if c.type.startswith("triangle")) == 524


def test_cube_sphere_order_3_like_nekmesh(homesh_bin, tmp_path):
    """NekMesh's test varopti:hyperelastic:maxiter=5:nq=4 expects 0.6664 (tolerance 2e-2); ours
    is 0.6897 at the nodes, 0.6864 certified, each moving by 2e-11 with the last bits."""
    report = tmp_path / "r.json"
    r = run([homesh_bin, "optimise", str(CUBE_SPHERE), "--order", "3", "-n", "5", "-j", "2",
             "--report", str(report), "-q"])
    assert r.returncode == 0, r.stderr
    rep = json.loads(report.read_text())
    assert rep["order"] == 3
    assert rep["optimiser"]["nodal_worst_after"] >= 0.666
    assert rep["optimiser"]["worst_after"] >= 0.666


def test_tangled_sphere_in_box_becomes_valid_with_free_interfaces(homesh_bin, tmp_path, tangled):
    assert gmsh_worst(tangled) < 0  # Gmsh itself says it is invalid
    out, report = tmp_path / "opt.msh", tmp_path / "r.json"
    r = run([homesh_bin, "optimise", str(tangled), "--free-interfaces", "-n", "10", "-j", "2",
             "-o", str(out), "--report", str(report)])
    assert r.returncode == 0, r.stderr
    o = json.loads(report.read_text())["optimiser"]
    assert o["invalid_before"] >= 1 and o["worst_before"] < 0  # 4 elements, -3.77
    # Measured 0.798 after 10 sweeps, valid from sweep 3; a 1e-12 change of the input moves the
    # former by 1e-5 and leaves the latter.
    assert o["invalid_after"] == 0 and o["worst_after"] > 0.3
    first_valid = next(h["iteration"] for h in o["history"] if h["invalid"] == 0)
    assert first_valid <= 4  # NekMesh needs 4 iterations on this mesh
    assert gmsh_worst(out) == pytest.approx(o["worst_after"], abs=1e-3)  # both within 1e-3
    # The box's faces stayed where they were.
    before, after = meshio.read(tangled).points, meshio.read(out).points
    on_box = (np.abs(np.abs(before) - 2.0) < 1e-12).any(axis=1)
    assert on_box.sum() > 4000
    assert np.array_equal(before[on_box], after[on_box])


def test_fixed_interfaces_keep_the_sphere_and_never_get_worse(homesh_bin, tmp_path, tangled):
    out, report = tmp_path / "opt.msh", tmp_path / "r.json"
    r = run([homesh_bin, "optimise", str(tangled), "-n", "6", "-j", "2", "-o", str(out),
             "--report", str(report), "-q"])
    assert r.returncode == 0, r.stderr
    o = json.loads(report.read_text())["optimiser"]
    assert o["invalid_after"] <= o["invalid_before"]
    assert o["worst_after"] >= o["worst_before"]
    assert o["kept_iteration"] >= 1
    before, after = meshio.read(tangled).points, meshio.read(out).points
    on_sphere = np.abs(np.linalg.norm(before, axis=1) - 1.0) < 1e-9
    assert on_sphere.sum() > 500
    assert np.array_equal(before[on_sphere], after[on_sphere])
    moved = np.linalg.norm(after - before, axis=1) > 0
    assert moved.sum() > 5000


def test_python_optimise_in_place():
    mesh = read(CUBE_SPHERE)
    before = mesh.nodes.copy()
    record = mesh.optimise(maxiter=3, threads=2)
    assert record["iterations"] == 3 and record["functional"] == "hyperelastic"
    assert record["worst_after"] > record["worst_before"]
    assert not np.array_equal(before, mesh.nodes)
    assert mesh.quality()["min"] == pytest.approx(record["worst_after"], abs=1e-12)
    with pytest.raises(ParameterError, match="functional"):
        mesh.optimise(functional="spring")
    with pytest.raises(ParameterError, match="region"):
        mesh.optimise(region=2.0)


def test_optimise_errors(homesh_bin, tmp_path):
    r = run([homesh_bin, "optimise", str(NACA), "-f", "spring"])
    assert r.returncode == 2 and "functional" in r.stderr and len(r.stderr.splitlines()) == 1
    r = run([homesh_bin, "optimise", str(tmp_path / "missing.msh")])
    assert r.returncode == 1 and "missing.msh" in r.stderr
    r = run([homesh_bin, "optimise", str(NACA), "--maxiter", "-2"])
    assert r.returncode == 2 and "--maxiter" in r.stderr
    r = run([homesh_bin, "optimise", str(NACA), "--region", "0"])
    assert r.returncode == 2 and "--region" in r.stderr
    r = run([homesh_bin, "optimise", str(NACA), "--layers", "3"])
    assert r.returncode == 2 and "--layers needs --region" in r.stderr


def test_python_optimise_slides_on_the_cad(data):
    from homesh import mesh as make_mesh
    m = make_mesh(str(data / "sphere.brep"), order=4, size=0.5)
    before = m.quality()["min"]
    record = m.optimise(maxiter=5, threads=2)
    assert record["worst_after"] > before
    on_cad = m.node_cad_dim < 3
    assert on_cad.sum() > 500  # 1029 .. 1061 over 1e-12 perturbations of the CAD
    radii = np.linalg.norm(m.nodes[on_cad], axis=1)
    assert np.abs(radii - 1.0).max() < 1e-7  # points of OCCT's sphere: 1 to rounding
    assert not np.array_equal(m.nodes[on_cad], make_mesh(str(data / "sphere.brep"), order=4,
                                                         size=0.5).nodes[on_cad])


def test_python_optimise_takes_the_facet_weight(data):
    # The same curved sphere optimised in place with and without the boundary facets' term: the
    # term is applied (the sliding nodes end elsewhere), they stay on the sphere, and a bad
    # weight is named.
    from homesh import mesh as make_mesh
    plain = make_mesh(str(data / "sphere.brep"), order=4, size=0.5)
    facets = make_mesh(str(data / "sphere.brep"), order=4, size=0.5)
    assert np.array_equal(plain.nodes, facets.nodes)
    plain.optimise(maxiter=10, threads=2)
    record = facets.optimise(maxiter=10, threads=2, facet_weight=1.0)
    assert record["invalid_after"] == 0
    on_cad = facets.node_cad_dim < 3
    assert not np.array_equal(plain.nodes[on_cad], facets.nodes[on_cad])
    radii = np.linalg.norm(facets.nodes[on_cad], axis=1)
    assert np.abs(radii - 1.0).max() < 1e-7  # points of OCCT's sphere: 1 to rounding
    with pytest.raises(ParameterError, match="facet weight must be a number from 0 to 100"):
        facets.optimise(maxiter=1, facet_weight=101.0)
    with pytest.raises(ParameterError, match="facet_weight must be a number"):
        facets.optimise(maxiter=1, facet_weight="1")


def test_mesh_command_with_optimise(homesh_bin, data, tmp_path):
    report = tmp_path / "r.json"
    r = run([homesh_bin, "mesh", str(data / "sphere.brep"), "--order", "4", "--size", "0.5",
             "--optimise", "-n", "5", "--report", str(report), "-q"])
    assert r.returncode == 0, r.stderr
    rep = json.loads(report.read_text())
    # `mesh --optimise` stops early once the mesh is valid and a sweep gains < 1e-3, and the
    # gains depend on Gmsh's mesh, which moves with the CAD's last bits (smallest gain 0.008 to
    # 0.025 over 1e-12 perturbations): any count up to the limit is right.
    assert 1 <= rep["optimiser"]["iterations"] <= 5
    assert len(rep["optimiser"]["history"]) == rep["optimiser"]["iterations"]
    assert "optimise" in rep["timings_s"]
    # The same double, printed twice with %.15g.
    assert rep["quality"]["scaled_jacobian"]["min"] == rep["optimiser"]["worst_after"]
    r = run([homesh_bin, "mesh", str(data / "sphere.brep"), "-n", "5"])
    assert r.returncode == 2 and "--optimise" in r.stderr

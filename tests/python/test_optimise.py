"""`homesh optimise` and `HighOrderMesh.optimise`: the per-sweep log, the report's "optimiser"
record, Gmsh's independent verdict on the result, untangling the sphere in a box that Gmsh
leaves invalid at order 4, fixed boundaries, and clear errors.

NekMesh's meshes live in ../shared, beside the clone: the tests that need them skip where it is
absent, and each has a sibling on meshes the tests make (`homesh mesh` of tests/data/sphere.brep,
of a NACA case file written here) or on tests/data/sphere_in_box_p4.msh.gz. Gmsh's verdict
comes from Debian's gmsh itself (conftest.gmsh_worst)."""

import gzip
import json
import re

import meshio
import numpy as np
import pytest

from conftest import PEER_CASES, gmsh_worst, needs_peer_files, run
from homesh import ParameterError, read

PEERS = PEER_CASES / "optimiser"
NACA = PEERS / "varopti_naca.msh"
CUBE_SPHERE = PEERS / "varopti_cube_sphere.msh"

# A NACA 0012 case (NekMesh's .mcf format) with this file's own values: a 2D mesh of order 3
# like NekMesh's varopti_naca.
NACA_CASE = """<NEKTAR>
<MESHING>
<INFORMATION><I PROPERTY="CADFile" VALUE="0012"/><I PROPERTY="MeshType" VALUE="2D"/></INFORMATION>
<PARAMETERS>
<P PARAM="Xmin" VALUE="-1"/><P PARAM="Ymin" VALUE="-2"/><P PARAM="Xmax" VALUE="3"/>
<P PARAM="Ymax" VALUE="2"/><P PARAM="AOA" VALUE="15"/><P PARAM="MinDelta" VALUE="0.1"/>
<P PARAM="MaxDelta" VALUE="0.5"/><P PARAM="EPS" VALUE="0.1"/><P PARAM="Order" VALUE="3"/>
</PARAMETERS>
</MESHING>
</NEKTAR>
"""

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


@pytest.fixture(scope="module")
def made_naca(tmp_path_factory, homesh_bin):
    """The NACA case meshed by `homesh mesh` at order 3, not optimised (2D, proven valid)."""
    folder = tmp_path_factory.mktemp("naca")
    (folder / "naca.mcf").write_text(NACA_CASE)
    r = run([homesh_bin, "mesh", folder / "naca.mcf", "--size", "0.4", "-o", folder / "naca.msh",
             "-q"])
    assert r.returncode == 0, r.stderr
    return folder / "naca.msh"


@pytest.fixture(scope="module")
def made_sphere(tmp_path_factory, homesh_bin, data):
    """tests/data/sphere.brep meshed by `homesh mesh` at order 4, not optimised (proven valid)."""
    path = tmp_path_factory.mktemp("sphere") / "sphere.msh"
    r = run([homesh_bin, "mesh", data / "sphere.brep", "--order", "4", "--size", "0.5", "-o", path,
             "-q"])
    assert r.returncode == 0, r.stderr
    return path


@pytest.fixture(scope="module")
def tangled(tmp_path_factory, data):
    """Gmsh's order-4 sphere in a box (SPHERE_IN_BOX): boundary nodes on the sphere, negative
    Jacobians inside."""
    path = tmp_path_factory.mktemp("tangled") / "t.msh"
    path.write_bytes(gzip.decompress((data / "sphere_in_box_p4.msh.gz").read_bytes()))
    return path


def optimise_naca_like(homesh_bin, tmp_path, source):
    """`homesh optimise` of a 2D order-3 mesh, linear elastic, 5 sweeps: the log has one line
    per sweep and the report the optimiser's record, which agrees with the report's quality.
    Returns the report and the written mesh."""
    out, report = tmp_path / "naca.msh", tmp_path / "r.json"
    r = run([homesh_bin, "optimise", str(source), "-f", "linearelastic", "-n", "5", "-j", "2",
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
    # The same double printed twice with %.15g: equal (the slack is the format's 5e-16).
    assert rep["quality"]["scaled_jacobian"]["min"] == pytest.approx(o["worst_after"], abs=1e-12)
    # min J / max J at the nodes (NekMesh's measure) bounds the element's own ratio from above,
    # and the certified value bounds it from below.
    assert o["nodal_worst_after"] >= o["worst_after"]
    return rep, out


def test_optimise_command_logs_each_sweep_and_reports(homesh_bin, tmp_path):
    needs_peer_files()
    rep, out = optimise_naca_like(homesh_bin, tmp_path, NACA)
    o = rep["optimiser"]
    # NekMesh's regression value (at the nodes; its .tst: 0.872585, tolerance 5e-3); ours is
    # 0.8840 and moves by 6e-12 with the input's last bits or the thread count.
    assert o["nodal_worst_after"] >= 0.8726
    assert o["worst_after"] > o["worst_before"] + 0.4  # measured 0.527, spread 1e-12
    # Gmsh's own Bezier-bounded verdict on the written file agrees: both are lower bounds
    # within 1e-3 (relative to max J) of the same minimum, refined independently.
    assert gmsh_worst(out, 2) == pytest.approx(o["worst_after"], abs=1e-3)
    mesh = meshio.read(out)
    assert sum(len(c.data) for c in mesh.cells if c.type.startswith("triangle")) == 524


def test_optimise_command_on_a_made_naca_mesh(homesh_bin, tmp_path, made_naca):
    """The sibling of the test above on a NACA mesh made here: the same log and report, never
    worse, every triangle written (as meshio reads the input and the output), Gmsh's verdict."""
    rep, out = optimise_naca_like(homesh_bin, tmp_path, made_naca)
    o = rep["optimiser"]
    assert o["invalid_before"] == 0 and o["worst_after"] > o["worst_before"]
    assert rep["order"] == 3

    def triangles(path):
        return sum(len(c.data) for c in meshio.read(path).cells if c.type == "triangle10")
    assert triangles(out) == triangles(made_naca) > 0
    # Read back, the written file has the quality reported (17 digits keep every double; the
    # report prints it with %.15g).
    assert read(out).quality()["min"] == pytest.approx(rep["quality"]["scaled_jacobian"]["min"],
                                                       abs=1e-12)
    # Gmsh's own verdict agrees, as on NekMesh's mesh above.
    assert gmsh_worst(out, 2) == pytest.approx(o["worst_after"], abs=1e-3)


def test_cube_sphere_order_3_like_nekmesh(homesh_bin, tmp_path):
    """NekMesh's test varopti:hyperelastic:maxiter=5:nq=4 expects 0.6664 (tolerance 2e-2); ours
    is 0.6897 at the nodes, 0.6864 certified, each moving by 2e-11 with the last bits."""
    needs_peer_files()
    report = tmp_path / "r.json"
    r = run([homesh_bin, "optimise", str(CUBE_SPHERE), "--order", "3", "-n", "5", "-j", "2",
             "--report", str(report), "-q"])
    assert r.returncode == 0, r.stderr
    rep = json.loads(report.read_text())
    assert rep["order"] == 3
    assert rep["optimiser"]["nodal_worst_after"] >= 0.666
    assert rep["optimiser"]["worst_after"] >= 0.666


def test_order_3_of_a_made_mesh(homesh_bin, tmp_path, made_sphere):
    """The sibling of the test above: an order-4 mesh made here, re-interpolated at order 3 and
    optimised for at most 5 sweeps: the report says order 3, the elements are all there, and the
    result is proven valid and no worse than the re-interpolated mesh."""
    report = tmp_path / "r.json"
    r = run([homesh_bin, "optimise", made_sphere, "--order", "3", "-n", "5", "-j", "2",
             "--report", report, "-q"])
    assert r.returncode == 0, r.stderr
    rep = json.loads(report.read_text())
    assert rep["order"] == 3
    assert rep["elements"]["tet"] == read(made_sphere).num_elements
    o = rep["optimiser"]
    assert 1 <= o["iterations"] <= 5 and len(o["history"]) == o["iterations"]
    assert o["invalid_after"] == 0 and o["worst_after"] >= o["worst_before"]
    assert o["nodal_worst_after"] >= o["worst_after"]  # see optimise_naca_like


@pytest.fixture(scope="module")
def untangled(tmp_path_factory, homesh_bin, tangled):
    """The tangled sphere in a box after 10 sweeps with free interfaces: (mesh, optimiser
    record)."""
    folder = tmp_path_factory.mktemp("untangled")
    out, report = folder / "opt.msh", folder / "r.json"
    r = run([homesh_bin, "optimise", str(tangled), "--free-interfaces", "-n", "10", "-j", "2",
             "-o", str(out), "--report", str(report)])
    assert r.returncode == 0, r.stderr
    return out, json.loads(report.read_text())["optimiser"]


def test_tangled_sphere_in_box_becomes_valid_with_free_interfaces(tangled, untangled):
    out, o = untangled
    assert o["invalid_before"] >= 1 and o["worst_before"] < 0  # 4 elements, -3.77
    # Measured 0.798 after 10 sweeps, valid from sweep 3; a 1e-12 change of the input moves the
    # former by 1e-5 and leaves the latter.
    assert o["invalid_after"] == 0 and o["worst_after"] > 0.3
    first_valid = next(h["iteration"] for h in o["history"] if h["invalid"] == 0)
    assert first_valid <= 4  # NekMesh needs 4 iterations on this mesh
    # The box's faces stayed where they were.
    before, after = meshio.read(tangled).points, meshio.read(out).points
    on_box = (np.abs(np.abs(before) - 2.0) < 1e-12).any(axis=1)
    assert on_box.sum() > 4000
    assert np.array_equal(before[on_box], after[on_box])


def test_gmsh_agrees_on_the_tangled_and_the_untangled_sphere_in_box(tangled, untangled):
    out, o = untangled
    assert gmsh_worst(tangled) < 0  # Gmsh itself says it is invalid
    assert gmsh_worst(out) == pytest.approx(o["worst_after"], abs=1e-3)  # both within 1e-3


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


def python_optimise_in_place(path):
    mesh = read(path)
    before = mesh.nodes.copy()
    record = mesh.optimise(optimise=3, threads=2)
    assert record["iterations"] == 3 and record["functional"] == "hyperelastic"
    assert record["worst_after"] > record["worst_before"]
    assert not np.array_equal(before, mesh.nodes)
    assert mesh.quality()["min"] == pytest.approx(record["worst_after"], abs=1e-12)
    with pytest.raises(ParameterError, match="functional"):
        mesh.optimise(functional="spring")
    with pytest.raises(ParameterError, match="region"):
        mesh.optimise(region=2.0)


def test_python_optimise_in_place():
    needs_peer_files()
    python_optimise_in_place(CUBE_SPHERE)


def test_python_optimise_in_place_on_a_made_mesh(made_sphere):
    python_optimise_in_place(made_sphere)


def test_optimise_errors(homesh_bin, tmp_path, tangled):
    mesh_file = tangled  # any mesh file: the arguments are refused before it is optimised
    r = run([homesh_bin, "optimise", str(mesh_file), "-f", "spring"])
    assert r.returncode == 2 and "functional" in r.stderr and len(r.stderr.splitlines()) == 1
    r = run([homesh_bin, "optimise", str(tmp_path / "missing.msh")])
    assert r.returncode == 1 and "missing.msh" in r.stderr
    r = run([homesh_bin, "optimise", str(mesh_file), "--maxiter", "-2"])
    assert r.returncode == 2 and "--maxiter" in r.stderr
    r = run([homesh_bin, "optimise", str(mesh_file), "--region", "1.5"])  # 0: everywhere
    assert r.returncode == 2 and "--region" in r.stderr
    r = run([homesh_bin, "optimise", str(mesh_file), "--layers", "3"])
    assert r.returncode == 2 and "region layers need a region" in r.stderr


def test_python_optimise_slides_on_the_cad(data):
    from homesh import mesh as make_mesh
    m = make_mesh(str(data / "sphere.brep"), order=4, size=0.5)
    before = m.quality()["min"]
    record = m.optimise(optimise=5, threads=2)
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
    plain.optimise(optimise=10, threads=2)
    record = facets.optimise(optimise=10, threads=2, facet_weight=1.0)
    assert record["invalid_after"] == 0
    on_cad = facets.node_cad_dim < 3
    assert not np.array_equal(plain.nodes[on_cad], facets.nodes[on_cad])
    radii = np.linalg.norm(facets.nodes[on_cad], axis=1)
    assert np.abs(radii - 1.0).max() < 1e-7  # points of OCCT's sphere: 1 to rounding
    with pytest.raises(ParameterError, match="facet weight must be a number from 0 to 100"):
        facets.optimise(optimise=1, facet_weight=101.0)
    with pytest.raises(ParameterError, match="facet weight must be .*, got '1'"):
        facets.optimise(optimise=1, facet_weight="1")


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
    # The boundary fit after the optimiser keeps every element within 0.1 % of the lower of its
    # own value and the worst before it (pipeline/boundary_fidelity.hpp): the worst may rise.
    assert "boundary_fit" in rep
    assert rep["quality"]["scaled_jacobian"]["min"] >= (1 - 1e-3) * rep["optimiser"]["worst_after"]
    r = run([homesh_bin, "mesh", str(data / "sphere.brep"), "-n", "5"])
    assert r.returncode == 2 and "--optimise" in r.stderr

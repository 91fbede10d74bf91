"""`homesh quality` and `homesh convert`: the JSON quality report, --strict on a certified-invalid
mesh, conversions between MSH, Nektar++ XML and VTU that keep every node, and third-party
readers (Gmsh, meshio) on the binary and appended outputs.

NekMesh's meshes live in ../shared, beside the clone: the tests that read them skip where it is
absent, and each has a sibling on a mesh made here (`homesh mesh` of tests/data/sphere.brep) or
on tests/data/sphere_in_box_p4.msh.gz, Gmsh's tangled order-4 sphere in a box."""

import gzip
import json
import re

import meshio
import numpy as np
import pytest

from conftest import PEER_CASES, needs_peer_files, run
import homesh
from homesh import HighOrderMesh, _core, read

PEERS = PEER_CASES / "optimiser"
NACA = PEERS / "varopti_naca.msh"
CUBE_SPHERE = PEERS / "varopti_cube_sphere.msh"
NEKTAR_XML = PEER_CASES / "nektar-xml" / "sphere_box_o6_varopti.xml"


@pytest.fixture(scope="module")
def made(tmp_path_factory, homesh_bin, data):
    """tests/data/sphere.brep meshed by `homesh mesh` at order 4 (tetrahedra, proven valid):
    the MSH file and the mesh command's report."""
    folder = tmp_path_factory.mktemp("made")
    path, report = folder / "sphere.msh", folder / "mesh.json"
    r = run([homesh_bin, "mesh", data / "sphere.brep", "--order", "4", "--size", "0.5", "-o", path,
             "--report", report, "-q"])
    assert r.returncode == 0, r.stderr
    return path, json.loads(report.read_text())


@pytest.fixture(scope="module")
def tangled(tmp_path_factory, data):
    """Gmsh's order-4 sphere in a box (MSH 4.1, tests/data), with negative Jacobians inside."""
    path = tmp_path_factory.mktemp("tangled") / "t.msh"
    path.write_bytes(gzip.decompress((data / "sphere_in_box_p4.msh.gz").read_bytes()))
    return path


def two_tetrahedra(order, fold=False):
    """Two disjoint straight tetrahedra of order `order` (our reference element and a shifted
    copy); with `fold`, the second one's node on edge 0-1 is pulled far beyond vertex 1, which
    reverses the edge at that vertex: a negative Jacobian there."""
    xi = _core.reference_nodes("tet", order)
    n = len(xi)
    second = xi + np.array([3.0, 0.0, 0.0])
    if fold:
        second[4] = second[0] + 5.0 * (second[1] - second[0])  # Gmsh order: node 4 is on edge 0-1
    nodes = np.vstack([xi, second])
    m = len(nodes)
    core = _core.mesh_from_arrays(
        3, order, nodes, np.full(m, 3, dtype=np.uint8), np.ones(m, dtype=np.int32),
        np.full((m, 2), np.nan),
        [("tet", order, np.arange(m, dtype=np.int64).reshape(2, n), np.ones(2, dtype=np.int32))],
        (0.0, 0.0, 1.0))
    return HighOrderMesh(core)


def test_quality_report_of_a_peer_mesh(homesh_bin, tmp_path):
    needs_peer_files()
    report = tmp_path / "q.json"
    r = run([homesh_bin, "quality", NACA, "--report", report])
    assert r.returncode == 0, r.stderr
    assert "certified valid" in r.stdout
    q = json.loads(report.read_text())
    assert q["elements"]["tri"] == 524 and q["order"] == 3
    quality = q["quality"]
    for key in ("scaled_jacobian", "distortion"):
        m = quality[key]
        assert 0.0 < m["min"] <= m["mean"] <= 1.0
        assert len(m["histogram"]["edges"]) == 21 and len(m["histogram"]["counts"]) == 20
        assert sum(m["histogram"]["counts"]) + m["histogram"]["below_zero"] == 524
    # Gmsh's AnalyseMeshQuality on this file gives 0.345951 (tests/cpp/io/test_readers.cpp): a
    # peer's figure; both are lower bounds within 1e-3 of the same minimum.
    assert abs(quality["scaled_jacobian"]["min"] - 0.345951) < 1e-3
    assert quality["invalid_elements"] == 0 and quality["certified"] is True
    assert quality["by_type"]["tri"]["count"] == 524
    assert quality["flagged_elements"] == []
    # The report on standard output is the same document.
    r = run([homesh_bin, "quality", NACA, "--report", "-", "-q", "-j", "2"])
    assert r.returncode == 0 and json.loads(r.stdout)["quality"] == quality


def test_quality_report_of_a_made_mesh(homesh_bin, tmp_path, made):
    """The sibling of the test above on a mesh made here: the same report, its counts those of
    the file as meshio reads it, and its worst value the one `homesh mesh` reported of the mesh
    it wrote (the file keeps every double)."""
    path, mesh_report = made
    report = tmp_path / "q.json"
    r = run([homesh_bin, "quality", path, "--report", report])
    assert r.returncode == 0, r.stderr
    assert "certified valid" in r.stdout
    q = json.loads(report.read_text())
    tets = sum(len(c.data) for c in meshio.read(path).cells if c.type == "tetra35")
    assert tets > 0 and q["elements"]["tet"] == tets and q["order"] == 4
    quality = q["quality"]
    for key in ("scaled_jacobian", "distortion"):
        m = quality[key]
        assert 0.0 < m["min"] <= m["mean"] <= 1.0
        assert len(m["histogram"]["edges"]) == 21 and len(m["histogram"]["counts"]) == 20
        assert sum(m["histogram"]["counts"]) + m["histogram"]["below_zero"] == tets
    assert quality["scaled_jacobian"]["min"] == mesh_report["quality"]["scaled_jacobian"]["min"]
    assert quality["invalid_elements"] == 0 and quality["certified"] is True
    assert quality["by_type"]["tet"]["count"] == tets
    assert quality["flagged_elements"] == []
    r = run([homesh_bin, "quality", path, "--report", "-", "-q", "-j", "2"])
    assert r.returncode == 0 and json.loads(r.stdout)["quality"] == quality


def test_quality_against_the_cad_measures_as_the_mesh_command(homesh_bin, tmp_path, made, data):
    """`homesh quality --cad` on the mesh `homesh mesh` wrote: its boundary, put back on the CAD
    by the corners of its cells, is measured as the mesh command measured it: the same samples,
    distances to the projections' precision (1e-9 of the diagonal) and angles to that over the
    radius (1)."""
    path, mesh_report = made
    report = tmp_path / "q.json"
    r = run([homesh_bin, "quality", path, "--cad", data / "sphere.brep", "--report", report])
    assert r.returncode == 0, r.stderr
    assert "normal angle to the CAD: max" in r.stdout
    q = json.loads(report.read_text())
    got, expected = q["geometry"], mesh_report["geometry"]
    assert q["cad"].endswith("sphere.brep")
    for key in ("samples", "angle_samples", "undefined_normals", "worst_angle_entity"):
        assert got[key] == expected[key], key
    precision = 1e-9 * expected["diagonal"]
    assert got["max_distance"] == pytest.approx(expected["max_distance"], abs=precision)
    assert got["max_normal_angle_deg"] == pytest.approx(expected["max_normal_angle_deg"],
                                                        abs=np.degrees(precision))
    assert q["quality"] == json.loads(run([homesh_bin, "quality", path, "--report", "-", "-q"])
                                      .stdout)["quality"]


def test_quality_against_the_cad_of_a_gmsh_mesh(homesh_bin, tmp_path, data):
    """Gmsh's linear mesh of the unit sphere, its boundary triangles tagged by Gmsh's own numbers:
    each flat triangle's normal n is off the sphere's x / |x| by an angle that is largest at a
    vertex (the directions within an angle of n form a convex cone), and the measure samples the
    vertices, so its largest angle is the largest over the triangles' vertices (the poles, where
    the CAD has no normal, left out). The distance lies between the flat triangle and the sphere:
    at most 1 - (the distance from the centre to the triangle)."""
    path = tmp_path / "gmsh.msh"
    r = run(["gmsh", data / "sphere.brep", "-3", "-setnumber", "Mesh.MeshSizeMax", "0.4",
             "-setnumber", "Mesh.SaveAll", "1", "-format", "msh41", "-o", path, "-v", "1"])
    assert r.returncode == 0 and path.exists(), r.stderr
    report = tmp_path / "q.json"
    r = run([homesh_bin, "quality", path, "--cad", data / "sphere.brep", "--report", report, "-q"])
    assert r.returncode == 0, r.stderr
    g = json.loads(report.read_text())["geometry"]
    mesh = meshio.read(path)
    x = mesh.points
    triangles = np.concatenate([c.data for c in mesh.cells if c.type == "triangle"])
    assert np.allclose(np.linalg.norm(x[np.unique(triangles)], axis=1), 1.0, atol=1e-9)
    angle, nearest = 0.0, 1.0
    for t in triangles:
        a, b, c = x[t]
        n = np.cross(b - a, c - a)
        n /= np.linalg.norm(n)
        for v in (a, b, c):
            if np.hypot(v[0], v[1]) > 1e-6:  # not a pole
                angle = max(angle, np.degrees(np.arccos(min(1.0, abs(n @ v) / np.linalg.norm(v)))))
        nearest = min(nearest, abs(n @ a))  # the triangle's plane: no nearer than it
    assert g["max_normal_angle_deg"] == pytest.approx(angle, abs=1e-6)
    assert 0.0 < g["max_distance"] <= 1.0 - nearest + 1e-9
    assert g["worst_angle_entity"] == "Face1"


def test_quality_against_the_cad_errors_name_the_problem(homesh_bin, tmp_path, made, data):
    path, _ = made
    r = run([homesh_bin, "quality", path, "--classify-tolerance", "1e-4"])
    assert r.returncode == 2 and "--classify-tolerance needs --cad" in r.stderr
    r = run([homesh_bin, "quality", path, "--cad", data / "box_hole.step", "--report",
             tmp_path / "q.json"])
    assert r.returncode != 0 and "is the mesh of this shape?" in r.stderr
    assert "boundary node" in r.stderr and not (tmp_path / "q.json").exists()
    tets = tmp_path / "tets.msh"
    two_tetrahedra(2).write(tets)
    r = run([homesh_bin, "quality", tets, "--cad", data / "sphere.brep"])
    assert r.returncode != 0 and "no boundary cells" in r.stderr


def test_python_read_with_the_cad_measures_its_geometry(made, data):
    """homesh.read(path, cad=...) gives geometry() as `homesh quality --cad` reports it, and
    names the problem as the command does."""
    path, mesh_report = made
    assert read(path).geometry() is None
    g = read(path, cad=data / "sphere.brep", threads=1).geometry()
    expected = mesh_report["geometry"]
    assert g["samples"] == expected["samples"]
    assert g["max_distance"] == pytest.approx(expected["max_distance"],
                                              abs=1e-9 * expected["diagonal"])
    with pytest.raises(homesh.ParameterError, match="classify_tolerance needs cad"):
        read(path, classify_tolerance=1e-4)
    with pytest.raises(homesh.MeshingError, match="is the mesh of this shape"):
        read(path, cad=data / "box_hole.step")


def test_strict_fails_on_a_certified_invalid_mesh(homesh_bin, tmp_path):
    good, bad = two_tetrahedra(2), two_tetrahedra(2, fold=True)
    assert good.quality()["invalid_elements"] == 0
    for name, mesh, invalid in (("good.msh", good, 0), ("bad.msh", bad, 1)):
        mesh.write(tmp_path / name)
        report = tmp_path / (name + ".json")
        r = run([homesh_bin, "quality", tmp_path / name, "--strict", "--report", report])
        assert r.returncode == (3 if invalid else 0), (name, r.stdout, r.stderr)
        q = json.loads(report.read_text())["quality"]
        assert q["invalid_elements"] == invalid
        assert q["certified"] is True  # invalid for certain, not undecided
        if invalid:
            assert q["scaled_jacobian"]["min"] < 0.0
            assert q["scaled_jacobian"]["histogram"]["below_zero"] == 1
            # The report says which element, and the interval holding its min J / max J.
            [flagged] = q["flagged_elements"]
            assert flagged["element"] == 1 and flagged["type"] == "tet"
            assert flagged["verdict"] == "invalid"
            lower, upper = flagged["scaled_jacobian"]
            assert lower == q["scaled_jacobian"]["min"] and lower <= upper < 0.0
            assert "element 1 (tet, entity 1): invalid" in r.stdout
    # Without --strict the verdict is printed but the command succeeds.
    r = run([homesh_bin, "quality", tmp_path / "bad.msh"])
    assert r.returncode == 0 and "invalid elements 1" in r.stdout


def barycentric(kind, order):
    """Barycentric coordinates of the reference nodes of a simplex (rows), to 1e-12."""
    xi = _core.reference_nodes(kind, order)
    nv = xi.shape[1] + 1
    corners = np.hstack([xi[:nv], np.ones((nv, 1))])
    return np.linalg.solve(corners.T, np.hstack([xi, np.ones((len(xi), 1))]).T).T


def test_per_element_verdicts_and_intervals():
    q = two_tetrahedra(2, fold=True).quality()
    assert list(q["validity"]) == [1, -1]
    # A straight element: 1 less the proven rounding margin (~1e-11 at order 2).
    assert q["scaled_jacobian"][0] == pytest.approx(1.0, abs=1e-9) and q["scaled_jacobian"][1] < 0


def check_intervals(path):
    q = read(path).quality()
    assert (q["validity"] == 1).all()
    # min J / max J lies in [lower, upper]; the bounds of min J and of max J are each refined to
    # 1e-3 of max J, so the ratio's interval is at most about 2e-3 wide.
    gap = q["scaled_jacobian_upper"] - q["scaled_jacobian"]
    assert gap.min() >= 0.0 and gap.max() < 2e-3, path


def test_per_element_intervals_of_peer_meshes():
    needs_peer_files()
    for name in ("varopti_naca.msh", "varopti_cube_sphere.msh"):
        check_intervals(PEERS / name)


def test_per_element_intervals_of_a_made_mesh(made):
    check_intervals(made[0])


def test_validity_field_in_files(tmp_path):
    mesh = two_tetrahedra(2, fold=True)
    mesh.write(tmp_path / "bad.vtu")
    vtu = meshio.read(tmp_path / "bad.vtu")
    assert list(vtu.cell_data["validity"][0]) == [1.0, -1.0]


def same_mesh(a, b, tol, interior=0):
    """Same elements, in the same order, with the same node coordinates. Formats may renumber
    an element's vertices (Nektar++ does, for positive volumes): each node is matched through
    that renumbering by its barycentric coordinates, so a node in the wrong slot still fails.
    `interior`: that many nodes at the end of each element (inside it) are not compared."""
    assert a.order == b.order and a.dim == b.dim
    assert [x.element_type for x in a.element_blocks] == [x.element_type for x in b.element_blocks]
    for x, y in zip(a.element_blocks, b.element_blocks):
        assert x.elements.shape == y.elements.shape and x.element_type in ("tet", "tri")
        assert np.array_equal(x.cad_entity, y.cad_entity)
        lam = barycentric(x.element_type, a.order)
        nv = lam.shape[1]
        keys = {tuple(np.round(row * a.order).astype(int)): n for n, row in enumerate(lam)}
        for ea, eb in zip(x.elements, y.elements):
            va, vb = a.nodes[ea[:nv]], b.nodes[eb[:nv]]
            # b's vertex k is a's vertex sigma[k].
            sigma = [int(np.argmin(np.abs(va - v).max(axis=1))) for v in vb]
            assert sorted(sigma) == list(range(nv)) and np.abs(va[sigma] - vb).max() <= tol
            for n in range(len(eb) - interior):
                mu = np.zeros(nv)
                mu[sigma] = lam[n]
                m = keys[tuple(np.round(mu * a.order).astype(int))]
                assert np.abs(a.nodes[ea[m]] - b.nodes[eb[n]]).max() <= tol, (n, m)


def convert_round_trip(homesh_bin, tmp_path, binary, path):
    """`path`: an order-4 tetrahedral mesh written by Gmsh."""
    source = read(path)
    flag = ["--binary"] if binary else []
    # Gmsh's MSH in -> MSH 4.1 (ASCII or binary) and compressed Nektar++ XML in one run.
    r = run([homesh_bin, "convert", path, "-o", tmp_path / "a.msh", "-o",
             tmp_path / "a.xml", "--compressed", "-q"] + flag)
    assert r.returncode == 0 and r.stdout == "", r.stderr
    assert "B64Z-LittleEndian" in (tmp_path / "a.xml").read_text()
    # Binary and ASCII with 17 significant digits both keep every double exactly; the source
    # (from Gmsh) is read once and written by us.
    tol = 0.0
    same_mesh(source, read(tmp_path / "a.msh"), tol)
    # From XML back to MSH: the same mesh again. Nektar++ files store vertices, edges and faces
    # but not the one interior node of these order-4 tetrahedra (last in Gmsh order), which the
    # reader rebuilds.
    r = run([homesh_bin, "convert", tmp_path / "a.xml", "-o", tmp_path / "b.msh", "-q"] + flag)
    assert r.returncode == 0, r.stderr
    assert source.order == 4
    same_mesh(source, read(tmp_path / "b.msh"), tol, interior=1)
    r = run([homesh_bin, "convert", tmp_path / "a.msh", "-o", tmp_path / "c.vtu", "-q"] + flag)
    assert r.returncode == 0, r.stderr
    vtu = meshio.read(tmp_path / "c.vtu")
    assert sum(len(c.data) for c in vtu.cells if c.type.startswith("VTK_LAGRANGE_TETRA")) == \
        source.num_elements
    assert len(vtu.cell_data["scaled_jacobian"][0]) == source.num_elements
    # Float64 in the VTU, computed from the same coordinates as source's: the same doubles.
    assert min(vtu.cell_data["scaled_jacobian"][0]) == source.quality()["min"]


@pytest.mark.parametrize("binary", [False, True])
def test_convert_round_trips(homesh_bin, tmp_path, binary):
    needs_peer_files()
    convert_round_trip(homesh_bin, tmp_path, binary, CUBE_SPHERE)  # MSH 2.2


@pytest.mark.parametrize("binary", [False, True])
def test_convert_round_trips_gmsh_sphere_in_box(homesh_bin, tmp_path, binary, tangled):
    convert_round_trip(homesh_bin, tmp_path, binary, tangled)  # MSH 4.1


def meshio_reads_binary_msh_and_appended_vtu(tmp_path, path, cell_type, count):
    """`cell_type`: meshio's name of the mesh's elements, `count` of them."""
    mesh = read(path)
    mesh.write(tmp_path / "n.msh", binary=True)
    mesh.write(tmp_path / "n.vtu", binary=True)
    msh = meshio.read(tmp_path / "n.msh")
    assert sum(len(c.data) for c in msh.cells if c.type == cell_type) == count
    # meshio keeps Gmsh's node order within cells (MSH 4.1 lists nodes by entity, so compare
    # through the connectivity).
    cells = np.vstack([c.data for c in msh.cells if c.type == cell_type])
    assert np.array_equal(msh.points[cells], mesh.nodes[mesh.elements])
    vtu = meshio.read(tmp_path / "n.vtu")
    assert np.array_equal(vtu.points, mesh.nodes)
    assert sum(len(c.data) for c in vtu.cells) == count
    assert np.array_equal(vtu.cell_data["scaled_jacobian"][0], mesh.quality()["scaled_jacobian"])


def test_meshio_reads_binary_msh_and_appended_vtu(tmp_path):
    needs_peer_files()
    meshio_reads_binary_msh_and_appended_vtu(tmp_path, NACA, "triangle10", 524)


def test_meshio_reads_binary_msh_and_appended_vtu_of_a_made_mesh(tmp_path, made):
    # The count as the mesh command reported it.
    meshio_reads_binary_msh_and_appended_vtu(tmp_path, made[0], "tetra35",
                                             made[1]["elements"]["tet"])


def test_convert_errors_name_the_problem(homesh_bin, tmp_path):
    mesh_file = tmp_path / "good.msh"  # any mesh file
    two_tetrahedra(2).write(mesh_file)
    r = run([homesh_bin, "convert", mesh_file, "-o", tmp_path / "x.foo"])
    assert r.returncode != 0 and "unknown mesh format '.foo'" in r.stderr
    assert not (tmp_path / "x.foo").exists()
    r = run([homesh_bin, "convert", mesh_file])
    assert r.returncode != 0 and "-o" in r.stderr
    garbage = tmp_path / "garbage.msh"
    garbage.write_text("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 2\n")
    r = run([homesh_bin, "quality", garbage])
    assert r.returncode != 0 and "garbage.msh" in r.stderr
    assert r.stderr.count("\n") == 1, r.stderr  # one line, no trace


def test_nektar_output_is_checked_as_nektar_builds_it(homesh_bin, tmp_path):
    """Nektar++ rebuilds element interiors from the faces, so a written .xml is read back and
    checked as Nektar++ will build it: NekMesh's tangled sphere_box_o6 file, passed through, is
    reported with its invalid elements; a valid mesh is reported with none."""
    needs_peer_files()
    nektar = NEKTAR_XML
    r = run([homesh_bin, "convert", nektar, "-o", tmp_path / "t.xml"])
    assert r.returncode == 0, r.stderr
    line = [s for s in r.stderr.splitlines() if "as Nektar++ builds it" in s]
    assert len(line) == 1, r.stderr
    invalid = int(line[0].split("; ")[1].split()[0])
    assert invalid > 0, line[0]
    # Quiet, a bad geometry is still said; a good one is not.
    r = run([homesh_bin, "convert", nektar, "-o", tmp_path / "t.xml", "-q"])
    assert "as Nektar++ builds it" in r.stderr
    r = run([homesh_bin, "convert", CUBE_SPHERE, "-o", tmp_path / "c.xml"])
    assert r.returncode == 0, r.stderr
    assert "as Nektar++ builds it (element interiors from the faces): scaled Jacobian min" in \
        r.stderr and "; 0 invalid, 0 undecided" in r.stderr, r.stderr
    r = run([homesh_bin, "convert", CUBE_SPHERE, "-o", tmp_path / "c.xml", "-q"])
    assert r.returncode == 0 and r.stderr == "", r.stderr


def nektar_line(stderr):
    """(scaled Jacobian min, invalid) from convert's line on the written .xml."""
    [line] = [s for s in stderr.splitlines() if "as Nektar++ builds it" in s]
    found = re.search(r"scaled Jacobian min (\S+); (\d+) invalid, (\d+) undecided", line)
    assert found, line
    return float(found.group(1)), int(found.group(2))


def test_nektar_output_of_repo_meshes_is_checked_as_nektar_builds_it(homesh_bin, tmp_path, made,
                                                                      tangled):
    """The sibling of the test above: Gmsh's tangled sphere in a box written as Nektar++ XML is
    reported with its invalid elements, quiet or not; a valid mesh made here is reported with
    none. Read back, each written file has the verdicts the line gave, and the valid mesh's
    elements (interiors rebuilt from the faces) those of its MSH file."""
    r = run([homesh_bin, "convert", tangled, "-o", tmp_path / "t.xml"])
    assert r.returncode == 0, r.stderr
    worst, invalid = nektar_line(r.stderr)
    assert invalid > 0 and worst < 0
    back = read(tmp_path / "t.xml").quality()
    assert back["invalid_elements"] == invalid
    assert back["min"] == pytest.approx(worst, abs=5e-5)  # printed with 4 decimals
    r = run([homesh_bin, "convert", tangled, "-o", tmp_path / "t.xml", "-q"])
    assert "as Nektar++ builds it" in r.stderr
    path = made[0]
    r = run([homesh_bin, "convert", path, "-o", tmp_path / "c.xml"])
    assert r.returncode == 0, r.stderr
    worst, invalid = nektar_line(r.stderr)
    assert invalid == 0 and "; 0 invalid, 0 undecided" in r.stderr, r.stderr
    back, msh = read(tmp_path / "c.xml").quality(), read(path).quality()
    assert back["min"] == pytest.approx(worst, abs=5e-5)
    assert np.array_equal(back["validity"], msh["validity"]) and (msh["validity"] == 1).all()
    r = run([homesh_bin, "convert", path, "-o", tmp_path / "c.xml", "-q"])
    assert r.returncode == 0 and r.stderr == "", r.stderr


def test_python_write_warns_when_nektar_geometry_is_not_valid(tmp_path):
    """HighOrderMesh.write to .xml says, as a warning, when the geometry Nektar++ builds from the
    file (element interiors from the faces) is not proven valid, and is silent when it is."""
    import warnings
    needs_peer_files()
    nektar = read(NEKTAR_XML)
    with pytest.warns(UserWarning, match="as Nektar..? builds it.*[1-9][0-9]* invalid"):
        nektar.write(tmp_path / "t.xml")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        read(CUBE_SPHERE).write(tmp_path / "c.xml")


def test_python_write_warns_when_nektar_geometry_of_a_repo_mesh_is_not_valid(tmp_path, made,
                                                                             tangled):
    """The sibling of the test above: Gmsh's tangled sphere in a box warns, a valid mesh made
    here does not."""
    import warnings
    with pytest.warns(UserWarning, match="as Nektar..? builds it.*[1-9][0-9]* invalid"):
        read(tangled).write(tmp_path / "t.xml")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        read(made[0]).write(tmp_path / "c.xml")

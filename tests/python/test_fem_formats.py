"""Reading the FEM workbench's mesh files (FemMesh.write: .unv, .vtk, .vtu), linear and quadratic,
from Python (homesh.read) and the command line (homesh quality): files written by FreeCAD itself
(tests/data/fem, made by make_fem_files.py there, and a cylinder written live through
freecadcmd), files written by meshio from our own meshes, and broken files.

The analytic figures of tests/data/fem/tet10_cases.*: the unit tetrahedron A B C D of volume
1/6, its edge AB's mid-edge node moved by d from the midpoint. Only that node's basis function
phi = 4 lambda_A lambda_B changes the map, so J = J0 (1 + grad(phi) . d) with grad(phi) =
4 (lambda_A - lambda_B, -lambda_B, -lambda_B): J / J0 ranges over [min, max] of that linear
function of the barycentric coordinates, reached at the vertices; the volume changes by
d . (the two faces' area vectors on AB) / 3 = -(d_y + d_z) / 6.
"""

import math
import os
import re
import shutil
import subprocess

import meshio
import meshio.vtk
import meshio.vtu
import numpy as np
import pytest

import homesh
from homesh import tessellation
from conftest import DATA, ROOT, run

FEM = DATA / "fem"
FORMATS = ("unv", "vtk", "vtu")


def tet10_expected():
    """(volume, exact scaled Jacobian, valid) of each tet10 case, from d (see the module doc)."""
    cases = [(0, 0, 0), (0, -0.1, -0.1), (0, 0.1, 0.1), (0, 0.15, 0.15), (-0.3, 0, 0),
             (-0.2, 0, 0)]
    out = []
    for d in cases:
        # 1 + grad(phi) . d at the vertices A (lambda_A = 1), B, C, D (gradient 0 there).
        at = [1 + 4 * d[0], 1 - 4 * d[0] - 4 * d[1] - 4 * d[2], 1.0, 1.0]
        out.append((1 / 6 - (d[1] + d[2]) / 6, min(at) / max(at), min(at) > 0))
    return out


@pytest.mark.parametrize("ext", FORMATS)
def test_freecad_tet10_cases_give_the_analytic_volume_and_verdict(ext):
    mesh = homesh.read(FEM / ("tet10_cases." + ext))
    assert mesh.order == 2 and mesh.element_type == "tet" and mesh.num_elements == 6
    q = mesh.quality()
    # UNV: 17 digits; VTK and VTU from FreeCAD: float32 coordinates, whose spacing at the
    # cases' |x| <= 16 is 9.5e-7 (volumes and J ratios move by a few times that).
    tol = 1e-12 if ext == "unv" else 5e-6
    for k, (volume, scaled, valid) in enumerate(tet10_expected()):
        assert mesh.element_volumes()[k] == pytest.approx(volume, abs=tol), k
        assert q["validity"][k] == (1 if valid else -1), k
        # Certified bounds around the exact value, within the subdivision's 1e-3 (relative).
        assert q["scaled_jacobian"][k] <= scaled + tol <= q["scaled_jacobian_upper"][k] + 2 * tol
        assert q["scaled_jacobian"][k] == pytest.approx(scaled, abs=2e-3), k
    notes = mesh.report()["notes"]
    # FreeCAD writes SMESH's (left-handed) order to VTK; its UNV writer turns it right-handed.
    assert (notes == []) == (ext == "unv"), notes


def test_cli_strict_on_the_tet10_cases(homesh_bin, tmp_path):
    for ext in FORMATS:
        report = tmp_path / ("r_%s.json" % ext)
        r = run([homesh_bin, "quality", FEM / ("tet10_cases." + ext), "--strict", "--report",
                 report])
        assert r.returncode == 3, r.stderr  # two invalid elements
        assert "invalid elements 2, undecided 0: INVALID" in r.stdout
        assert "element 3 (tet" in r.stdout and "element 4 (tet" in r.stdout
        data = __import__("json").loads(report.read_text())
        assert data["quality"]["invalid_elements"] == 2 and data["elements"]["tet"] == 6
        assert len(data["notes"]) == (0 if ext == "unv" else 1)
        assert ("negative volume" in r.stderr) == (ext != "unv"), r.stderr


@pytest.mark.parametrize("ext", ("unv", "vtk"))
def test_freecad_disc_is_planar_curved_and_valid(ext):
    mesh = homesh.read(FEM / ("disc_p2." + ext))
    assert mesh.dim == 2 and mesh.order == 2 and mesh.element_type == "tri"
    q = mesh.quality()
    assert q["invalid_elements"] == 0 and q["undecided_elements"] == 0
    area = abs(mesh.element_volumes().sum())
    corners = mesh.nodes[mesh.elements[:, :3]]
    straight = 0.5 * np.abs(np.cross(corners[:, 1] - corners[:, 0],
                                     corners[:, 2] - corners[:, 0])[:, 2]).sum()
    # The parabolic edges follow the circle: the area error falls from the polygon's O(h^2) to
    # O(h^4), here by more than 100 times.
    assert abs(area - math.pi) < 1e-3 * math.pi
    assert abs(area - math.pi) * 100 < abs(straight - math.pi)
    # Mid-edge nodes of edges on the circle lie on it (float32 in the VTK file).
    r = np.linalg.norm(mesh.nodes[:, :2], axis=1)
    on_circle = r > 0.999
    assert on_circle.sum() >= 2 * 0.9 * 2 * math.pi / 0.5  # corners and mid-edge nodes
    assert np.abs(r[on_circle] - 1).max() < (1e-12 if ext == "unv" else 1e-6)


def test_unv_and_vtk_of_the_disc_agree():
    a, b = homesh.read(FEM / "disc_p2.unv"), homesh.read(FEM / "disc_p2.vtk")
    assert np.abs(a.nodes - b.nodes).max() < 1e-6  # float32
    np.testing.assert_array_equal(a.elements, b.elements)
    assert len(a.boundary) == 1 and a.boundary[0].element_type == "line"  # UNV: its edges too
    assert b.boundary == []  # FreeCAD's VTK: the highest dimension only


# --- A cylinder meshed by FEM's Gmsh mesher and written by FreeCAD, live -----------------------

@pytest.fixture(scope="module")
def freecad_cylinder(tmp_path_factory):
    if shutil.which("freecadcmd") is None or shutil.which("gmsh") is None:
        pytest.skip("needs freecadcmd and gmsh (FEM's Gmsh mesher)")
    out = tmp_path_factory.mktemp("fem")
    home = tmp_path_factory.mktemp("home")
    script = FEM / "make_fem_files.py"
    env = dict(os.environ, HOME=str(home), FREECAD_USER_HOME=str(home), HOMESH_FEM_OUT=str(out),
               HOMESH_FEM_FILES="cylinder")
    r = subprocess.run(["freecadcmd", "-c", "import runpy; runpy.run_path(%r, run_name="
                        "'__main__')" % str(script)], env=env, capture_output=True, text=True,
                       timeout=300)
    assert r.returncode == 0, r.stdout[-2000:] + r.stderr[-2000:]
    return out


def test_freecad_cylinder_volumes_show_the_curved_geometry(freecad_cylinder):
    exact = 2 * math.pi  # radius 1, height 2
    p1 = homesh.read(freecad_cylinder / "cylinder_p1.unv")
    p1_error = abs(p1.element_volumes().sum() - exact)
    meshes = {ext: homesh.read(freecad_cylinder / ("cylinder_p2." + ext)) for ext in FORMATS}
    for ext, mesh in meshes.items():
        assert mesh.order == 2 and mesh.element_type == "tet"
        q = mesh.quality()
        assert q["invalid_elements"] == 0 and q["undecided_elements"] == 0, ext
        volumes = mesh.element_volumes()
        assert (volumes > 0).all()
        # Quadratic tetrahedra with their boundary mid-edge nodes on the cylinder: the volume
        # error is a thousandth of the straight mesh's (measured: 1.2e-5 against 1.2e-2).
        error = abs(volumes.sum() - exact)
        assert error < 1e-4 * exact and error * 100 < p1_error, (ext, error, p1_error)
    # The three files describe the same elements in the same order: equal verdicts, scaled
    # Jacobians equal up to the VTK files' float32 coordinates.
    ref = meshes["unv"].quality()
    for ext in ("vtk", "vtu"):
        q = meshes[ext].quality()
        np.testing.assert_array_equal(q["validity"], ref["validity"])
        assert np.abs(q["scaled_jacobian"] - ref["scaled_jacobian"]).max() < 1e-3
        assert np.abs(meshes[ext].element_volumes() - meshes["unv"].element_volumes()).max() \
            < 1e-6
    # Boundary nodes of the UNV file (its triangles) lie on the cylinder.
    unv = meshes["unv"]
    tri = next(b for b in unv.boundary if b.element_type == "tri")
    x = unv.nodes[np.unique(tri.elements)]
    r = np.hypot(x[:, 0], x[:, 1])
    on_caps = (np.abs(x[:, 2]) < 1e-12) | (np.abs(x[:, 2] - 2) < 1e-12)
    assert np.abs(r[~on_caps] - 1).max() < 1e-9
    assert (r[on_caps] <= 1 + 1e-9).all()


def unv_nodes(text):
    """{label: index of its coordinate line} of dataset 2411 in UNV text lines."""
    lines = text.split("\n")
    start = lines.index("  2411") + 1
    out = {}
    i = start
    while lines[i].strip() != "-1":
        out[int(lines[i].split()[0])] = i + 1
        i += 2
    return lines, out


def first_unv_tet(lines):
    """Node labels, in the file's order, of the first parabolic tetrahedron (FE id 118)."""
    i = lines.index("  2412") + 1
    while True:
        fields = lines[i].split()
        if fields[1] == "118":
            return [int(v) for v in lines[i + 1].split() + lines[i + 2].split()]
        i += 2 + (1 if fields[1] in ("11", "21", "22", "23", "24") else 0) + \
            (int(fields[5]) > 8)


def test_pushing_a_mid_edge_node_flips_the_verdict(freecad_cylinder, homesh_bin, tmp_path):
    source = freecad_cylinder / "cylinder_p2.unv"
    r = run([homesh_bin, "quality", source, "--strict", "-q"])
    assert r.returncode == 0, r.stderr
    lines, where = unv_nodes(source.read_text())
    tet = first_unv_tet(lines)  # c0 m01 c1 m12 c2 m20 m03 m13 m23 c3
    c0, m01, c1 = (np.array([float(v) for v in lines[where[n]].split()]) for n in tet[:3])
    # Along the edge to a tenth of it: J at c0 is proportional to 4 t - 1 < 0.
    moved = c0 + 0.1 * (c1 - c0)
    lines[where[tet[1]]] = "  %.17e  %.17e  %.17e" % tuple(moved)
    broken = tmp_path / "pushed.unv"
    broken.write_text("\n".join(lines))
    r = run([homesh_bin, "quality", broken, "--strict"])
    assert r.returncode == 3, r.stderr
    assert "element 0 (tet" in r.stdout  # the first tetrahedron of the file
    mesh = homesh.read(broken)
    assert mesh.quality()["validity"][0] == -1


# --- meshio-written VTK and VTU of our meshes ------------------------------------------------

MESHIO_WRITES = [
    ("vtu", dict(binary=True, compression="zlib")),
    ("vtu", dict(binary=True, compression=None)),
    ("vtu", dict(binary=False)),
    ("vtu", dict(binary=True, compression="zlib", header_type="UInt64")),
    ("vtk", dict(binary=True)),
    ("vtk", dict(binary=False)),
    ("vtk", dict(binary=True, fmt_version="4.2")),
    ("vtk", dict(binary=False, fmt_version="4.2")),
]


@pytest.fixture(scope="module")
def our_meshes(tmp_path_factory, data):
    """Order 1 and 2 meshes of the box with a hole (tetra, triangle, line; tetra10, triangle6,
    line3) and FreeCAD's disc (triangle6, line3) as .msh, which meshio maps to VTK's node order
    with its own tables (independent of ours)."""
    folder = tmp_path_factory.mktemp("ours")
    out = {}
    for order in (1, 2):
        m = homesh.mesh(str(data / "box_hole.step"), order=order, size=1.5)
        out["box%d" % order] = m
    out["disc"] = homesh.read(FEM / "disc_p2.unv")
    paths = {}
    for name, m in out.items():
        paths[name] = folder / (name + ".msh")
        m.write(paths[name])
    return out, paths


@pytest.mark.parametrize("ext, options", MESHIO_WRITES,
                         ids=["%s-%s" % (e, "-".join("%s=%s" % kv for kv in o.items()))
                              for e, o in MESHIO_WRITES])
def test_meshio_round_trip(our_meshes, tmp_path, ext, options):
    meshes, paths = our_meshes
    # meshio writes ASCII with 16 significant digits (its legacy VTK: 11 in version 4.2).
    tol = 0.0 if options.get("binary") else 1e-9
    for name, ours in meshes.items():
        m = meshio.read(paths[name])  # its own node numbering (our file's node blocks)
        path = tmp_path / ("%s.%s" % (name, ext))
        writer = meshio.vtk.write if ext == "vtk" else meshio.vtu.write
        writer(path, meshio.Mesh(m.points, m.cells), **options)
        back = homesh.read(path)
        assert back.report()["notes"] == []
        assert back.order == ours.order and back.element_type == ours.element_type
        # Each element's nodes, in Gmsh's order, at the same places.
        np.testing.assert_allclose(back.nodes[back.elements], ours.nodes[ours.elements],
                                   rtol=0, atol=tol)
        assert sorted(b.element_type for b in back.boundary) == \
            sorted(b.element_type for b in ours.boundary)
        q, ref = back.quality(), ours.quality()
        np.testing.assert_array_equal(q["validity"], ref["validity"])
        np.testing.assert_allclose(q["scaled_jacobian"], ref["scaled_jacobian"], rtol=0,
                                   atol=1e3 * tol)


def test_cli_converts_a_freecad_unv_to_msh(homesh_bin, tmp_path):
    # homesh convert x.unv -o x.msh: the FEM mesh for Gmsh or our optimiser, with its quality.
    out = tmp_path / "disc.msh"
    r = run([homesh_bin, "convert", FEM / "disc_p2.unv", "-o", out, "-q"])
    assert r.returncode == 0, r.stderr
    back = homesh.read(out)
    src = homesh.read(FEM / "disc_p2.unv")
    np.testing.assert_array_equal(back.nodes, src.nodes)
    np.testing.assert_array_equal(back.elements, src.elements)


# --- Files HOMesh does not read, and broken files: one line, exit status 1 ----------------------

def assert_one_line_error(r, *phrases):
    assert r.returncode == 1, (r.returncode, r.stdout, r.stderr)
    assert r.stderr.startswith("homesh: error: ") and r.stderr.count("\n") == 1, r.stderr
    for phrase in phrases:
        assert phrase in r.stderr, r.stderr


def test_cells_homesh_does_not_read(homesh_bin, tmp_path):
    points = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                       [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], dtype=float)
    mids = np.array([(points[a] + points[b]) / 2 for a, b in
                     [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4),
                      (1, 5), (2, 6), (3, 7)]])
    hex20 = meshio.Mesh(np.vstack([points, mids]), [("hexahedron20", [list(range(20))])])
    # A 13-node pyramid, in legacy VTK written here (this meshio has no name for it).
    pyramid13 = np.vstack([points[:5], [(points[a] + points[b]) / 2 for a, b in
                                        [(0, 1), (1, 2), (2, 3), (3, 0), (0, 4), (1, 4), (2, 4),
                                         (3, 4)]]])
    (tmp_path / "pyramid13.vtk").write_text(
        "# vtk DataFile Version 4.2\npyramid13\nASCII\nDATASET UNSTRUCTURED_GRID\n"
        "POINTS 13 double\n" + "".join(f"{x} {y} {z}\n" for x, y, z in pyramid13)
        + "CELLS 1 14\n13 " + " ".join(str(i) for i in range(13)) + "\nCELL_TYPES 1\n27\n")
    for name, mesh, phrase in [
            ("hex20.vtu", hex20, "cell 0 is a VTK_QUADRATIC_HEXAHEDRON (type 25), a serendipity"),
            ("hex20.vtk", hex20, "cell 0 is a VTK_QUADRATIC_HEXAHEDRON (type 25)"),
            ("pyramid13.vtk", None,
             "cell 0 is a VTK_QUADRATIC_PYRAMID (type 27), a serendipity")]:
        if mesh is not None:
            meshio.write(tmp_path / name, mesh)
        assert_one_line_error(run([homesh_bin, "quality", tmp_path / name]), name, phrase)
        with pytest.raises(homesh.FileError, match=re.escape(phrase)):
            homesh.read(tmp_path / name)


def test_linear_pyramids_are_read_and_judged(homesh_bin, tmp_path):
    # The reference pyramid (apex above its base's first corner), a VTK_PYRAMID: read, and
    # certified valid with min J / max J = 1 (its J is constant), from the CLI and from Python.
    points = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    path = tmp_path / "pyramid.vtu"
    meshio.write(path, meshio.Mesh(points, [("pyramid", [[0, 1, 2, 3, 4]])]))
    r = run([homesh_bin, "quality", path])
    assert r.returncode == 0, r.stderr
    assert "pyramid" in r.stdout and "invalid elements 0" in r.stdout, r.stdout
    mesh = homesh.read(path)
    assert mesh.num_elements == 1
    # Certified to within the Bezier bounds' rounding margin (1e-9 here) of 1.
    assert mesh.quality()["scaled_jacobian"][0] == pytest.approx(1.0, abs=1e-9)
    # Drawn as FreeCAD draws chosen elements: its 5 faces, every point on one of them, and one
    # polyline per side of each face (4 + 4 x 3).
    drawn = tessellation.element_surfaces(mesh, [0], level=4)
    x, y, z = drawn["points"].T
    on_face = np.min(np.abs(np.stack([z, y, x, x + z - 1.0, y + z - 1.0])), axis=0)
    assert on_face.max() < 1e-12
    assert len(drawn["edge_polylines"]) == 16


UNV_QUAD8 = """    -1
  2411
         1         1         1        11
   0.0  0.0  0.0
         2         1         1        11
   1.0  0.0  0.0
    -1
    -1
  2412
         7        45         2         1         7         8
         1         2         1         2         1         2         1         2
    -1
"""

UNV_SHELL = """    -1
  2411
         1         1         1        11
   0.0  0.0  0.0
         2         1         1        11
   1.0  0.0  0.0
         3         1         1        11
   0.0  1.0  0.0
         4         1         1        11
   1.0  1.0  0.5
    -1
    -1
  2412
         1        91         2         1         7         3
         1         2         3
         2        91         2         1         7         3
         2         4         3
    -1
"""


def test_a_shell_is_read_as_a_surface_mesh(homesh_bin, tmp_path):
    # Two triangles folded along their shared edge (node 4 lifted by 0.5): no plane holds them,
    # so each is judged along its own normal, both straight and valid.
    path = tmp_path / "shell.unv"
    path.write_text(UNV_SHELL)
    m = homesh.read(path)
    assert m.dim == 2 and m.num_elements == 2
    assert tuple(m.plane_normal) == (0.0, 0.0, 0.0)
    q = m.quality()
    assert q["invalid_elements"] == 0 and q["min"] == pytest.approx(1.0)
    r = run([homesh_bin, "quality", path])
    assert r.returncode == 0, r.stderr


@pytest.mark.parametrize("text, phrases", [
    (UNV_QUAD8, ["line 10: element 7 (FE descriptor 45, a quadrilateral) has 8 nodes",
                 "serendipity"]),
    (UNV_SHELL.replace("  2412", "  2413"), ["it has no elements (dataset 2412)"]),
    (UNV_SHELL.replace("   1.0  1.0  0.5\n", ""), ["line 9: node 4 has no coordinate line"]),
    (UNV_SHELL.replace("         2         4         3\n    -1\n", ""),
     ["is not closed by '-1' (the file is truncated)"]),
    ("garbage\x01\x02\n", ["line 1: '-1' expected", "'garbage??'"]),
    ("", ["it has no nodes (dataset 2411)"]),
])
def test_broken_unv_files(homesh_bin, tmp_path, text, phrases):
    path = tmp_path / "bad.unv"
    path.write_text(text)
    assert_one_line_error(run([homesh_bin, "quality", path]), "bad.unv", *phrases)
    with pytest.raises(homesh.FileError):
        homesh.read(path)


def test_truncated_and_garbled_freecad_files(homesh_bin, tmp_path):
    """Every FreeCAD file cut short at many places, or with bytes overwritten, reads or fails
    with one error line: never a crash (a signal), a hang or a multi-line message."""
    rng = np.random.default_rng(7)
    for name in ("tet10_cases.unv", "tet10_cases.vtk", "tet10_cases.vtu", "disc_p2.vtk"):
        data = (FEM / name).read_bytes()
        cuts = sorted(set(rng.integers(0, len(data), 12).tolist()))
        variants = [data[:n] for n in cuts]
        for _ in range(6):
            garbled = bytearray(data)
            at = int(rng.integers(0, len(data) - 8))
            garbled[at:at + 8] = rng.integers(0, 256, 8, dtype=np.uint8).tobytes()
            variants.append(bytes(garbled))
        for k, bytes_ in enumerate(variants):
            path = tmp_path / ("v%d_%s" % (k, name))
            path.write_bytes(bytes_)
            r = run([homesh_bin, "quality", path, "-q"], timeout=60)
            assert r.returncode in (0, 1, 3), (name, k, r.returncode, r.stderr)
            if r.returncode == 1:
                assert r.stderr.startswith("homesh: error: ") and r.stderr.count("\n") == 1, \
                    (name, k, r.stderr)
                assert path.name in r.stderr


def test_broken_vtu_data(homesh_bin, tmp_path):
    m = homesh.read(FEM / "disc_p2.unv")
    mesh = meshio.Mesh(m.nodes, [("triangle6", m.elements[:, [0, 1, 2, 3, 4, 5]])])
    good = tmp_path / "good.vtu"
    meshio.write(good, mesh, binary=True, compression="zlib")
    text = good.read_text()
    assert run([homesh_bin, "quality", good, "-q"]).returncode == 0
    cases = [
        (text.replace('compressor="vtkZLibDataCompressor"', 'compressor="vtkLZ4DataCompressor"'),
         "compressor 'vtkLZ4DataCompressor' is not supported"),
        (re.sub(r'(Name="connectivity"[^>]*>)\s*(\S)', r"\1!\2", text, count=1),
         "DataArray connectivity: invalid character in base64 data"),
        (text.replace('NumberOfPoints="%d"' % len(m.nodes),
                      'NumberOfPoints="%d"' % (len(m.nodes) + 1)), "point coordinates for"),
        (text.replace('type="UnstructuredGrid"', 'type="PolyData"'),
         'its root is not <VTKFile type="UnstructuredGrid">'),
        (text[:len(text) // 2], "is not valid XML"),
    ]
    for k, (broken, phrase) in enumerate(cases):
        path = tmp_path / ("bad%d.vtu" % k)
        path.write_text(broken)
        assert_one_line_error(run([homesh_bin, "quality", path]), path.name, phrase)


def test_broken_legacy_vtk(homesh_bin, tmp_path):
    text = (FEM / "tet10_cases.vtk").read_text()
    cases = [
        (text.replace("DATASET UNSTRUCTURED_GRID", "DATASET POLYDATA"),
         "DATASET 'POLYDATA': HOMesh reads UNSTRUCTURED_GRID only"),
        (text.replace("CELLS 7 60", "CELLS 7 6000000000"),
         "the CELLS connectivity size 6000000000 is more than the rest of the file holds"),
        (text.replace("\n24\n", "\n99\n", 1), "cell 0 is of VTK type 99"),
        (text[:text.index("CELL_TYPES")], "the file ends without CELL_TYPES"),
        (text.replace("0 10 20", "0 10 200"), "cell 1 has offset 200 outside [10, 60]"),
        ("# vtk DataFile Version 5.1\nx\nBINARY\nDATASET UNSTRUCTURED_GRID\nPOINTS 1000 double\n"
         "\x00\x01", "POINTS 1000 is more than the rest of the file holds"),
        ("not vtk at all", "it does not start with '# vtk DataFile Version"),
    ]
    for k, (broken, phrase) in enumerate(cases):
        path = tmp_path / ("bad%d.vtk" % k)
        path.write_text(broken)
        assert_one_line_error(run([homesh_bin, "quality", path]), path.name, phrase)

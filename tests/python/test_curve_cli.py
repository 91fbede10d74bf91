"""`homesh curve`: another tool's linear mesh (Gmsh's, made here from the STEP: tetrahedra, a
cylinder of prisms also through Python's homesh.curve, a cylinder of hexahedra; Netgen's
tetrahedra; CGNS files the CGNS library's converter wrote) curved on its CAD from the command line,
every boundary node on the CAD, certified valid; a mesh whose boundary node lies off the CAD is
refused naming it, and nothing is written."""

import json
import shutil

import meshio
import numpy as np
import pytest

import homesh

from conftest import run

# tests/data/box_hole.step: the box [0, 4] x [0, 4] x [0, 2] with a hole of radius 1 through it
# around the axis x = y = 2 (test_support.hpp's boxWithHole). Its bounding diagonal is 6.
DIAGONAL = 6.0


def distance_to_cad(points):
    """Each point's distance to the nearest of the CAD's surfaces (planes and the cylinder)."""
    x, y, z = points.T
    planes = np.abs(np.stack([x, x - 4.0, y, y - 4.0, z, z - 2.0]))
    cylinder = np.abs(np.hypot(x - 2.0, y - 2.0) - 1.0)
    return np.minimum(planes.min(axis=0), cylinder)


def curved_valid(homesh_bin, tmp_path, linear, step, *args):
    """Runs `homesh curve LINEAR --cad STEP ARGS -o curved.msh --report report.json`, asserts it
    succeeded certified valid, and returns the report and the curved mesh (meshio)."""
    curved, report = tmp_path / "curved.msh", tmp_path / "report.json"
    r = run([homesh_bin, "curve", linear, "--cad", step] + list(args) +
            ["-o", curved, "--report", report])
    assert r.returncode == 0, r.stderr
    rep = json.loads(report.read_text())
    assert rep["quality"]["invalid_elements"] == 0 and rep["quality"]["undecided_elements"] == 0
    return rep, meshio.read(curved)


@pytest.fixture(scope="module")
def gmsh_linear(tmp_path_factory, data):
    gmsh = shutil.which("gmsh")
    assert gmsh, "Debian's gmsh package is needed"
    out = tmp_path_factory.mktemp("curve")
    linear = out / "linear.msh"
    r = run([gmsh, data / "box_hole.step", "-3", "-clmax", "0.6", "-format", "msh41", "-o",
             linear])
    assert r.returncode == 0 and linear.is_file(), r.stdout + r.stderr
    return out, linear


def test_gmsh_mesh_is_curved_on_its_cad_and_certified_valid(homesh_bin, data, gmsh_linear):
    out, linear = gmsh_linear
    curved, report = out / "curved.msh", out / "report.json"
    r = run([homesh_bin, "curve", linear, "--cad", data / "box_hole.step", "--order", "3",
             "--optimise", "-o", curved, "--report", report])
    assert r.returncode == 0, r.stderr
    rep = json.loads(report.read_text())
    assert rep["quality"]["invalid_elements"] == 0
    assert rep["quality"]["undecided_elements"] == 0
    assert rep["quality"]["scaled_jacobian"]["min"] > 0.0
    mesh = meshio.read(curved)
    before = meshio.read(linear)
    assert len(mesh.cells_dict["tetra20"]) == len(before.cells_dict["tetra"])
    boundary = np.unique(mesh.cells_dict["triangle10"].ravel())
    assert len(boundary) > len(np.unique(before.cells_dict["triangle"].ravel()))
    # Every boundary node, the new ones included, is a point of the CAD: its distance is the
    # CAD's own projection and evaluation rounding (about 1e-15 of these coordinates), far
    # below 1e-9 of the diagonal; a node left on a straight chord of the hole is up to 5e-3 off.
    assert distance_to_cad(mesh.points[boundary]).max() < 1e-9 * DIAGONAL


def test_a_node_off_the_cad_is_refused_by_name_and_nothing_is_written(homesh_bin, data,
                                                                       gmsh_linear, tmp_path):
    _, linear = gmsh_linear
    mesh = meshio.read(linear)
    boundary = np.unique(mesh.cells_dict["triangle"].ravel())
    # A node on the hole, moved outwards by 1 % of the 0.6 size: 6e-3, far beyond the 6e-5
    # (1e-5 of the diagonal) within which a node counts as on the CAD.
    # (inside the hole's wall, away from its rims on the box's faces)
    on_hole = boundary[(np.abs(np.hypot(mesh.points[boundary, 0] - 2.0,
                                        mesh.points[boundary, 1] - 2.0) - 1.0) < 1e-9)
                       & (mesh.points[boundary, 2] > 0.1) & (mesh.points[boundary, 2] < 1.9)]
    node = on_hole[len(on_hole) // 2]
    radial = mesh.points[node, :2] - 2.0
    mesh.points[node, :2] += 0.006 * radial / np.linalg.norm(radial)
    moved = tmp_path / "moved.msh"
    meshio.write(moved, meshio.Mesh(mesh.points, [("tetra", mesh.cells_dict["tetra"])]),
                 file_format="gmsh22", binary=False)
    out = tmp_path / "out.msh"
    r = run([homesh_bin, "curve", moved, "--cad", data / "box_hole.step", "-o", out])
    assert r.returncode == 1, (r.returncode, r.stderr)
    error = r.stderr.splitlines()[-1]
    assert error.startswith("homesh: error: "), r.stderr
    # The node by its number in the file (1-based, as Gmsh numbers it), where it is, the face
    # nearest to it and how far.
    assert "node %d at (%g, %g, %g)" % ((node + 1,) + tuple(mesh.points[node])) in error, error
    assert "Face" in error and "distance 0.006" in error, error
    assert not out.exists()
    # Within a tolerance of 2e-3 of the diagonal (0.012) the node counts as on the hole: it is
    # put back onto it and the mesh is curved and certified valid.
    r = run([homesh_bin, "curve", moved, "--cad", data / "box_hole.step", "-o", out,
             "--classify-tolerance", "2e-3", "--order", "2"])
    assert r.returncode == 0, r.stderr
    curved = meshio.read(out)
    boundary = np.unique(curved.cells_dict["triangle6"].ravel())
    assert distance_to_cad(curved.points[boundary]).max() < 1e-9 * DIAGONAL
    r = run([homesh_bin, "curve", moved, "--cad", data / "box_hole.step",
             "--classify-tolerance", "0.5"])
    assert r.returncode == 2 and "--classify-tolerance must be a number in (0, 0.01]" in r.stderr, \
        r.stderr


def test_curve_needs_its_cad_and_refuses_a_mesh_of_another_shape(homesh_bin, data, tmp_path):
    r = run([homesh_bin, "curve", data / "box_hole.step"])
    assert r.returncode == 2 and "--cad" in r.stderr, r.stderr
    # A lone pyramid in the box's corner: its base and two faces lie on the box's faces, its
    # two slanted faces on none.
    points = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1]], dtype=float)
    pyramid = tmp_path / "pyramid.vtu"
    meshio.write(pyramid, meshio.Mesh(points, [("pyramid", [[0, 1, 2, 3, 4]])]))
    r = run([homesh_bin, "curve", pyramid, "--cad", data / "box_hole.step", "-o",
             tmp_path / "out.msh"])
    assert r.returncode != 0 and "spans more than one face" in r.stderr, r.stderr
    assert not (tmp_path / "out.msh").exists()


CYLINDER_GEO = """SetFactory("OpenCASCADE");
Disk(1) = {0, 0, 0, 1};
Extrude {0, 0, 1} { Surface{1}; Layers{4}; Recombine; }
Mesh.MeshSizeMax = 0.4;
"""


def test_prisms_are_curved_from_the_command_line_and_python(homesh_bin, tmp_path):
    """Gmsh's cylinder of 4 layers of prisms (a disk's triangles extruded): every prism's
    column runs from the bottom to the top, so it is no boundary layer (the report says why)
    and the prisms are curved as given, certified valid, with every boundary node on the CAD."""
    gmsh = shutil.which("gmsh")
    assert gmsh, "Debian's gmsh package is needed"
    geo, linear, step = tmp_path / "cyl.geo", tmp_path / "cyl.msh", tmp_path / "cyl.step"
    geo.write_text(CYLINDER_GEO)
    for args in (["-3", "-format", "msh41", "-o", linear], ["-0", "-o", step]):
        r = run([gmsh, geo] + args)
        assert r.returncode == 0, r.stdout + r.stderr
    curved, report = tmp_path / "curved.msh", tmp_path / "report.json"
    r = run([homesh_bin, "curve", linear, "--cad", step, "--order", "4", "-o", curved,
             "--report", report])
    assert r.returncode == 0, r.stderr
    rep = json.loads(report.read_text())
    assert rep["quality"]["invalid_elements"] == 0 and rep["quality"]["undecided_elements"] == 0
    assert any("spans the domain" in note for note in rep["notes"]), rep["notes"]
    assert "given_layers" not in rep
    before = meshio.read(linear)
    mesh = meshio.read(curved)
    wedges = before.cells_dict["wedge"]
    assert len(mesh.cells_dict["wedge75"]) == len(wedges)
    # Every boundary node (on the quadrilaterals of the side, the triangles of the ends) lies on
    # the cylinder or its end planes to the CAD's projection rounding.
    boundary = np.unique(np.concatenate([mesh.cells_dict["quad25"].ravel(),
                                         mesh.cells_dict["triangle15"].ravel()]))
    x, y, z = mesh.points[boundary].T
    off = np.minimum(np.abs(np.hypot(x, y) - 1.0), np.minimum(np.abs(z), np.abs(z - 1.0)))
    assert off.max() < 1e-9 * np.sqrt(4 + 4 + 1)

    python = homesh.curve(str(step), before.points, {"prism": wedges}, order=4)
    assert python.quality()["invalid_elements"] == 0
    assert python.num_elements == len(wedges)
    with pytest.raises(homesh.ParameterError, match="unknown cell type 'wedge'"):
        homesh.curve(str(step), before.points, {"wedge": wedges}, order=4)
    with pytest.raises(homesh.ParameterError, match=r"prism cells must be an \(E, 6\) array"):
        homesh.curve(str(step), before.points, {"prism": wedges[:, :4]}, order=4)


def test_a_mesh_netgen_made_and_wrote_is_curved(homesh_bin, data, tmp_path):
    """Netgen itself (Debian's python3-netgen) meshes box_hole.step and writes Gmsh's legacy
    format (MSH 2.0, coordinates to 6 decimals, so its boundary nodes are up to 5e-7 off the
    CAD); `homesh curve` reads the file and curves it at order 4, certified valid, every
    boundary node put on the CAD."""
    import netgen.NgOCC as ngocc  # Debian's python3-netgen (scripts/install-deps.sh)
    linear = tmp_path / "netgen.msh"
    ngocc.LoadOCCGeometry(str(data / "box_hole.step")).GenerateMesh(maxh=0.6).Export(
        str(linear), "Gmsh2 Format")
    assert linear.read_text().startswith("$MeshFormat\n2.0")
    curved, report = tmp_path / "curved.msh", tmp_path / "report.json"
    r = run([homesh_bin, "curve", linear, "--cad", data / "box_hole.step", "--order", "4",
             "--optimise", "-o", curved, "--report", report])
    assert r.returncode == 0, r.stderr
    rep = json.loads(report.read_text())
    assert rep["quality"]["invalid_elements"] == 0 and rep["quality"]["undecided_elements"] == 0
    mesh = meshio.read(curved)
    assert len(mesh.cells_dict["tetra35"]) == len(meshio.read(linear).cells_dict["tetra"])
    boundary = np.unique(mesh.cells_dict["triangle15"].ravel())
    assert distance_to_cad(mesh.points[boundary]).max() < 1e-9 * DIAGONAL


HEX_CYLINDER_GEO = """Point(1) = {0, 0, 0, 0.4}; Point(2) = {1, 0, 0, 0.4}; Point(3) = {0, 1, 0, 0.4};
Point(4) = {-1, 0, 0, 0.4}; Point(5) = {0, -1, 0, 0.4};
Circle(1) = {2, 1, 3}; Circle(2) = {3, 1, 4}; Circle(3) = {4, 1, 5}; Circle(4) = {5, 1, 2};
Curve Loop(1) = {1, 2, 3, 4};
Plane Surface(1) = {1};
Recombine Surface{1};
Extrude {0, 0, 1} { Surface{1}; Layers{3}; Recombine; }
"""
CYLINDER_STEP_GEO = """SetFactory("OpenCASCADE");
Cylinder(1) = {0, 0, 0, 0, 0, 1, 1};
"""


def test_hexahedra_on_a_cylinder_are_curved(homesh_bin, tmp_path):
    """Gmsh's cylinder of hexahedra (its recombined disk extruded in 3 layers, in Gmsh's own
    kernel; the CAD an OpenCASCADE cylinder of the same size): `homesh curve` makes it order 4,
    certified valid, with every node of its boundary quadrilaterals on the cylinder or its end
    planes (112 quadrilaterals: 32 on each end, 48 on the side)."""
    gmsh = shutil.which("gmsh")
    assert gmsh, "Debian's gmsh package is needed"
    geo, step_geo = tmp_path / "hex.geo", tmp_path / "cyl.geo"
    linear, step = tmp_path / "hex.msh", tmp_path / "cyl.step"
    geo.write_text(HEX_CYLINDER_GEO)
    step_geo.write_text(CYLINDER_STEP_GEO)
    for args in ([geo, "-3", "-format", "msh41", "-o", linear], [step_geo, "-0", "-o", step]):
        r = run([gmsh] + args)
        assert r.returncode == 0, r.stdout + r.stderr
    rep, mesh = curved_valid(homesh_bin, tmp_path, linear, step, "--order", "4", "--optimise")
    assert rep["elements"]["hex"] == len(meshio.read(linear).cells_dict["hexahedron"])
    assert rep["boundary"]["quad"] == 112
    quads = np.concatenate([c.data for c in mesh.cells if c.type == "quad25"])
    boundary = np.unique(quads.ravel())
    x, y, z = mesh.points[boundary].T
    off = np.minimum(np.abs(np.hypot(x, y) - 1.0), np.minimum(np.abs(z), np.abs(z - 1.0)))
    assert off.max() < 1e-9 * np.sqrt(4 + 4 + 1)


def write_ugrid(path, mesh):
    """A meshio mesh (Gmsh's linear cells) as an ASCII AFLR3 UGRID file: boundary triangles and
    quadrilaterals with Gmsh's surface tags as surface IDs, then the volume cells. (UGRID lists a
    pyramid's nodes as base 1, base 4, apex, base 2, base 3; the CGNS library's aflr3_to_cgns
    turns them back.)"""
    cells = {c.type: [] for c in mesh.cells}
    tags = {c.type: [] for c in mesh.cells}
    for block, tag in zip(mesh.cells, mesh.cell_data["gmsh:geometrical"]):
        cells[block.type].append(block.data)
        tags[block.type].append(tag)
    get = {t: np.concatenate(cells[t]) for t in cells}
    tri, quad = get.get("triangle", np.zeros((0, 3), int)), get.get("quad", np.zeros((0, 4), int))
    tet, pyr = get.get("tetra", np.zeros((0, 4), int)), get.get("pyramid", np.zeros((0, 5), int))
    prism = get.get("wedge", np.zeros((0, 6), int))
    hexa = get.get("hexahedron", np.zeros((0, 8), int))
    surface = np.concatenate([np.concatenate(tags[t]) for t in ("triangle", "quad") if t in tags])
    lines = ["%d %d %d %d %d %d %d" % (len(mesh.points), len(tri), len(quad), len(tet), len(pyr),
                                       len(prism), len(hexa))]
    lines += ["%.17g %.17g %.17g" % tuple(p) for p in mesh.points]
    for block in (tri, quad):
        lines += [" ".join(str(i + 1) for i in c) for c in block]
    lines += [str(s) for s in surface]
    for block in (tet, pyr[:, [0, 3, 4, 1, 2]], prism, hexa):
        lines += [" ".join(str(i + 1) for i in c) for c in block]
    path.write_text("\n".join(lines) + "\n")


@pytest.mark.parametrize("geo, kind", [(CYLINDER_GEO, "wedge"), (HEX_CYLINDER_GEO, "hexahedron")],
                         ids=["prisms", "hexahedra"])
def test_a_cgns_file_another_tool_wrote_is_curved(homesh_bin, tmp_path, geo, kind):
    """Gmsh's cylinders of prisms and of hexahedra, turned into CGNS by the CGNS library's own
    converter (aflr3_to_cgns, Debian's cgns-convert: a section and a boundary condition per
    surface, named as it names them), read and curved by `homesh curve` at order 3: certified
    valid, every boundary node on the cylinder or its end planes, the converter's conditions
    carried over as named groups."""
    gmsh = shutil.which("gmsh")
    assert gmsh, "Debian's gmsh package is needed"
    (tmp_path / "m.geo").write_text(geo)
    (tmp_path / "step.geo").write_text(CYLINDER_STEP_GEO)
    linear, step = tmp_path / "m.msh", tmp_path / "cyl.step"
    for args in ([tmp_path / "m.geo", "-3", "-format", "msh41", "-o", linear],
                 [tmp_path / "step.geo", "-0", "-o", step]):
        r = run([gmsh] + args)
        assert r.returncode == 0, r.stdout + r.stderr
    before = meshio.read(linear)
    ugrid, cgns = tmp_path / "m.ugrid", tmp_path / "m.cgns"
    write_ugrid(ugrid, before)
    r = run(["aflr3_to_cgns", "-f", ugrid, cgns])
    assert r.returncode == 0 and cgns.is_file(), r.stdout + r.stderr
    _, mesh = curved_valid(homesh_bin, tmp_path, cgns, step, "--order", "3")
    order3 = {"wedge": "wedge40", "hexahedron": "hexahedron64"}[kind]
    assert len(mesh.cells_dict[order3]) == len(before.cells_dict[kind])
    boundary = np.unique(np.concatenate([c.data.ravel() for c in mesh.cells
                                         if c.type in ("triangle10", "quad16")]))
    x, y, z = mesh.points[boundary].T
    off = np.minimum(np.abs(np.hypot(x, y) - 1.0), np.minimum(np.abs(z), np.abs(z - 1.0)))
    assert off.max() < 1e-9 * np.sqrt(4 + 4 + 1)

    # `convert` keeps the converter's conditions ("UserDefined 1", ...) as the groups of the MSH.
    msh = tmp_path / "converted.msh"
    r = run([homesh_bin, "convert", cgns, "-o", msh])
    assert r.returncode == 0, r.stderr
    names = set(meshio.read(msh).field_data)
    surfaces = np.unique(np.concatenate([t for c, t in zip(
        before.cells, before.cell_data["gmsh:geometrical"]) if c.type in ("triangle", "quad")]))
    # (The converter numbers its conditions 1, 2, ... in the order of the surface IDs.)
    assert {n for n in names if n.startswith("UserDefined ")} == \
        {"UserDefined %d" % (k + 1) for k in range(len(surfaces))}, names


DISK_GEO = """SetFactory("OpenCASCADE");
Disk(1) = {0, 0, 0, 1};
Mesh.MeshSizeMax = 0.3;
"""


@pytest.mark.parametrize("recombine", [False, True], ids=["triangles", "quadrilaterals"])
def test_a_planar_2d_mesh_is_curved_on_its_faces(homesh_bin, tmp_path, recombine):
    """Gmsh's 2D mesh of a disk (triangles, or recombined into quadrilaterals) curved on the disk
    at order 4 with --optimise, from the command line and from Python: certified valid, every
    boundary node on the circle to 1e-9 of the diagonal, the plane kept; a node moved off the
    circle by 1% of the size is refused by name, and nothing is written."""
    gmsh = shutil.which("gmsh")
    assert gmsh, "Debian's gmsh package is needed"
    geo = tmp_path / "disk.geo"
    geo.write_text(DISK_GEO + ("Recombine Surface{1};\n" if recombine else ""))
    linear, step = tmp_path / "disk.msh", tmp_path / "disk.step"
    for args in (["-2", "-format", "msh41", "-o", linear], ["-0", "-o", step]):
        r = run([gmsh, geo] + args)
        assert r.returncode == 0, r.stdout + r.stderr
    _, mesh = curved_valid(homesh_bin, tmp_path, linear, step, "--order", "4", "--optimise")
    before = meshio.read(linear)
    kind = "quad" if recombine else "triangle"
    assert len(mesh.cells_dict[kind + "25" if recombine else "triangle15"]) == \
        len(before.cells_dict[kind])
    boundary = np.unique(mesh.cells_dict["line5"].ravel())
    assert np.abs(np.hypot(*mesh.points[boundary, :2].T) - 1.0).max() < 1e-9 * 2 * np.sqrt(2)
    assert np.abs(mesh.points[:, 2]).max() == 0.0

    cells = {"quad" if recombine else "tri": before.cells_dict[kind]}
    python = homesh.curve(str(step), before.points, cells, order=4)
    assert python.dim == 2 and python.quality()["invalid_elements"] == 0

    # A boundary node moved outwards by 1% of the size (0.3): refused, naming it.
    moved = before.points.copy()
    node = int(before.cells_dict["line"][0][0])
    moved[node, :2] *= 1.003
    off = tmp_path / "off.vtu"
    meshio.write(off, meshio.Mesh(moved, [(kind, before.cells_dict[kind])]))
    out = tmp_path / "off_curved.msh"
    r = run([homesh_bin, "curve", off, "--cad", step, "-o", out])
    assert r.returncode != 0
    assert "node %d at (" % (node + 1) in r.stderr and "lies on no face" in r.stderr, r.stderr
    assert "at distance 0.003" in r.stderr, r.stderr
    assert not out.exists()


def test_a_curve_between_two_faces_of_a_2d_mesh_is_followed(homesh_bin, tmp_path):
    """A disk cut by a circle of radius 0.5 into two faces (Gmsh's conforming 2D mesh of both):
    the sides on the inner circle, shared by a cell of each face, become lines on it, so that
    curving puts their new nodes on the circle (to 1e-9), as on the outer one."""
    gmsh = shutil.which("gmsh")
    assert gmsh, "Debian's gmsh package is needed"
    geo = tmp_path / "two.geo"
    geo.write_text('SetFactory("OpenCASCADE");\nDisk(1) = {0, 0, 0, 1};\n'
                   'Disk(2) = {0, 0, 0, 0.5};\nBooleanFragments{ Surface{1}; Delete; }'
                   '{ Surface{2}; Delete; }\nMesh.MeshSizeMax = 0.25;\n')
    linear, step = tmp_path / "two.msh", tmp_path / "two.step"
    for args in (["-2", "-format", "msh41", "-o", linear], ["-0", "-o", step]):
        r = run([gmsh, geo] + args)
        assert r.returncode == 0, r.stdout + r.stderr
    _, mesh = curved_valid(homesh_bin, tmp_path, linear, step, "--order", "4")
    lines = mesh.cells_dict["line5"]
    radius = np.hypot(*mesh.points[np.unique(lines.ravel()), :2].T)
    inner = radius < 0.75
    assert inner.sum() > 20 and (~inner).sum() > 20
    assert np.abs(radius[inner] - 0.5).max() < 1e-9 * 2 * np.sqrt(2)
    assert np.abs(radius[~inner] - 1.0).max() < 1e-9 * 2 * np.sqrt(2)

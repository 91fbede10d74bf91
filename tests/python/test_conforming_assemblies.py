"""Solids that touch, exported as separate solids (a STEP file of FreeCAD's General Fuse or
Boolean Fragments reads back so: each solid with its own faces), are imprinted on each other
before meshing (cad/solid_imprint.hpp): one conforming mesh, with no duplicate node on the
interface and every interface triangle between exactly two tetrahedra of different solids,
certified valid, each solid its own volume group and each interface face its own boundary
group (MSH physical groups, Nektar++ composites); numbers given in the file's own numbering
are mapped; solids that overlap, or imprinting turned off, are meshed apart with a warning."""

import collections
import json
import os
import re
import subprocess
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

from conftest import gmsh_worst, run

MAKE = """
import FreeCAD, Part
V = FreeCAD.Vector
def save(solids, path):
    Part.makeCompound(solids).exportStep(path)
a = Part.makeBox(1, 1, 1)
save([a, Part.makeBox(1, 1, 1, V(1, 0, 0))], %r)
ball = Part.makeSphere(0.3, V(0.5, 0.5, 0.5))
save([Part.makeBox(1, 1, 1).cut(ball), ball], %r)
save([a, Part.makeBox(1, 1, 1, V(1, 0.5, 0))], %r)
save([a, Part.makeBox(1, 1, 1, V(0.5, 0, 0))], %r)
"""
NAMES = ["two_boxes", "sphere_in_box", "offset_boxes", "overlapping_boxes"]


@pytest.fixture(scope="module")
def shapes(tmp_path_factory):
    folder = tmp_path_factory.mktemp("assemblies")
    paths = {name: folder / (name + ".step") for name in NAMES}
    subprocess.run(["freecadcmd", "-c", MAKE % tuple(str(paths[n]) for n in NAMES)], check=True,
                   capture_output=True, timeout=300)
    assert all(p.exists() for p in paths.values())
    return paths


def tet_faces(m):
    """{sorted vertex triple: [solid of each tetrahedron with that face]} (MSH entity tags are
    the solids' numbers)."""
    faces = collections.defaultdict(list)
    for cells, solids in zip(m.cells, m.cell_data["gmsh:geometrical"]):
        if cells.type.startswith("tetra"):
            for v, solid in zip(cells.data[:, :4], solids):
                for f in ((0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)):
                    faces[tuple(sorted(v[list(f)]))].append(int(solid))
    return faces


def triangles(m):
    """[(vertex triple, face tag)] of the boundary cells."""
    out = []
    for cells, tags in zip(m.cells, m.cell_data["gmsh:geometrical"]):
        if cells.type.startswith("triangle"):
            out += [(tuple(sorted(v[:3])), int(t)) for v, t in zip(cells.data, tags)]
    return out


def mesh(homesh_bin, step, folder, *extra):
    msh, xml, report = folder / "m.msh", folder / "m.xml", folder / "r.json"
    r = run([homesh_bin, "mesh", step, "-o", msh, "-o", xml, "--report", report, *extra])
    return r, msh, xml, json.loads(report.read_text()) if report.exists() else None


@pytest.mark.parametrize("name,order", [("two_boxes", 2), ("sphere_in_box", 4)])
def test_touching_solids_get_one_conforming_certified_mesh(homesh_bin, shapes, tmp_path, name,
                                                          order):
    extra = ["--optimise"] if order == 4 else []
    r, msh, xml, report = mesh(homesh_bin, shapes[name], tmp_path, "--order", str(order), *extra)
    assert r.returncode == 0, r.stderr  # certified valid (4 otherwise)
    imprint = report["healing"]["imprint"]
    assert imprint["imprinted"] and imprint["warning"] == "", imprint
    [interface] = imprint["interfaces"]
    assert interface["solids"] == [1, 2], imprint
    shared = interface["face"]
    assert "imprinted 2 touching solids: 1 face shared (Face%d: Solid1 | Solid2)" % shared \
        in r.stderr, r.stderr
    assert report["healing"]["warnings"] == []

    m = meshio.read(msh)
    # No two nodes at one place: the interface's nodes are the two solids' own.
    diagonal = np.linalg.norm(m.points.max(axis=0) - m.points.min(axis=0))
    rounded = np.round(m.points / (1e-9 * diagonal))
    assert len(np.unique(rounded, axis=0)) == len(m.points)
    faces = tet_faces(m)
    assert max(len(s) for s in faces.values()) <= 2
    tris = triangles(m)
    on_interface = [t for t, tag in tris if tag == shared]
    assert on_interface
    for t in on_interface:  # between one tetrahedron of each solid
        assert sorted(faces[t]) == [1, 2], (t, faces[t])
    for t, tag in tris:  # every other boundary triangle bounds one tetrahedron
        if tag != shared:
            assert len(faces[t]) == 1, (t, tag, faces[t])
    # Every tetrahedron face shared by two solids is an interface triangle.
    between = {t for t, s in faces.items() if len(s) == 2 and s[0] != s[1]}
    assert between == set(on_interface)
    # Groups: each solid, and the interface face as a group of its own.
    assert {"Solid1", "Solid2", "Face%d" % shared} <= set(m.field_data)
    composites = {c.get("NAME"): c.text for c in ET.parse(xml).iter("C")}
    assert {"Solid1", "Solid2", "Face%d" % shared} <= set(composites)
    assert composites["Face%d" % shared].strip().startswith("F[")
    # Gmsh's own Bezier-bounded verdict agrees that the mesh is valid.
    assert gmsh_worst(msh) > 0.0


def test_faces_that_partly_touch_are_imprinted_where_they_overlap(homesh_bin, shapes, tmp_path):
    """The right box moved up by half: the interface is the half of each face at x = 1 that the
    other covers; the triangles there have its area, 0.5, to rounding."""
    r, msh, _, report = mesh(homesh_bin, shapes["offset_boxes"], tmp_path, "--order", "2")
    assert r.returncode == 0, r.stderr
    [interface] = report["healing"]["imprint"]["interfaces"]
    m = meshio.read(msh)
    faces = tet_faces(m)
    area = 0.0
    for t, tag in triangles(m):
        if tag == interface["face"]:
            assert sorted(faces[t]) == [1, 2]
            a, b, c = m.points[list(t)]
            area += 0.5 * np.linalg.norm(np.cross(b - a, c - a))
            assert abs(a[0] - 1.0) < 1e-12 and min(a[1], b[1], c[1]) >= 0.5 - 1e-12
    assert abs(area - 0.5) < 1e-12, area
    # The faces at x = 1 were each split in two: Face2 (left) and Face7 (right) map to two.
    faces_map = {e["from"]: e["to"] for e in report["healing"]["imprint"]["renumbered"]["faces"]}
    assert len(faces_map[2]) == 2 and len(faces_map[7]) == 2, faces_map
    assert interface["face"] in faces_map[2] and interface["face"] in faces_map[7]


def test_numbers_in_the_files_own_numbering_are_mapped(homesh_bin, shapes, tmp_path):
    """A group named by the right box's face at x = 2, Face8 in the file, holds the triangles at
    x = 2 in the imprinted model (where that face is Face7); one the model has not is refused."""
    r, msh, _, report = mesh(homesh_bin, shapes["two_boxes"], tmp_path, "--order", "2",
                             "--group", "outlet=8")
    assert r.returncode == 0, r.stderr
    m = meshio.read(msh)
    tag = m.field_data["outlet"][0]
    at = np.concatenate([m.points[c.data[p == tag][:, :3]][..., 0].ravel()
                         for c, p in zip(m.cells, m.cell_data["gmsh:physical"])
                         if c.type.startswith("triangle")])
    assert len(at) > 0 and np.all(np.abs(at - 2.0) < 1e-12)
    r = run([homesh_bin, "mesh", shapes["two_boxes"], "--order", "1", "--group", "outlet=13",
             "-o", tmp_path / "bad.msh"])
    assert r.returncode != 0
    assert ("boundary group 'outlet': entity 13: the model has 12 (Face1 to Face12)"
            in r.stderr), r.stderr


def test_overlapping_solids_are_cut_and_imprinting_off_meshes_apart_with_a_warning(
        homesh_bin, shapes, tmp_path):
    # Two unit boxes overlapping by half: cut where they overlap, the overlap a solid of its own,
    # so that the tetrahedra fill the union once (volume 1.5, not 2) and conform.
    r, msh, _, report = mesh(homesh_bin, shapes["overlapping_boxes"], tmp_path, "--order", "1")
    assert r.returncode == 0, r.stderr
    assert ("Solid1 and Solid2 share volume (they overlap, not only touch): cut where they "
            "overlap") in r.stderr, r.stderr
    imprint = report["healing"]["imprint"]
    assert imprint["imprinted"] and "Solid1 -> " in imprint["overlap"], imprint
    m = meshio.read(msh)
    volume, solids = 0.0, set()
    for cells, tags in zip(m.cells, m.cell_data["gmsh:geometrical"]):
        if cells.type == "tetra":
            p = m.points[cells.data]
            volume += np.abs(np.einsum("ij,ij->i", p[:, 1] - p[:, 0],
                                       np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 0]))).sum() / 6
            solids |= set(int(t) for t in np.unique(tags))
    assert solids == {1, 2, 3}, solids
    assert abs(volume - 1.5) < 1e-9, volume
    # The solids share their interfaces' triangles: tetrahedra of different solids meet face
    # to face there, and no face has more than two tetrahedra.
    faces = tet_faces(m).values()
    assert any(len(s) == 2 and s[0] != s[1] for s in faces)
    assert all(len(s) <= 2 for s in faces)
    r, msh, _, report = mesh(homesh_bin, shapes["two_boxes"], tmp_path, "--order", "1",
                             "--no-imprint")
    assert r.returncode == 0, r.stderr
    assert re.search(r"solids lie against each other on faces they do not share: Solid1 and "
                     r"Solid2 \(Face2 on Face7\).*imprinting is off", r.stderr), r.stderr
    m = meshio.read(msh)
    at_one = m.points[np.abs(m.points[:, 0] - 1.0) < 1e-12]
    assert len(np.unique(np.round(at_one, 9), axis=0)) < len(at_one)  # each side its own nodes


# OpenCASCADE's sample data (Debian package occt-misc, installed by scripts/install-deps.sh): a
# bearing axis whose balls touch their races at points. Imprinted with the fuzzy value of ten
# times the healing tolerance, the fuse stretched a vertex's tolerance to 0.11 and joined a
# race's edges out of order, and the fuzzy contacts left 332 internal edges 0.006 to 0.05 long:
# Gmsh 4.8 aborted on both, and the model was meshed with its solids apart.
BEARING = "/usr/share/opencascade/data/occ/Axis_of_bearing.brep"


def test_balls_touching_their_races_are_imprinted_and_the_mesh_conforms(homesh_bin, tmp_path):
    assert os.path.isfile(BEARING), "occt-misc is not installed (scripts/install-deps.sh)"
    r, msh, _, report = mesh(homesh_bin, BEARING, tmp_path, "--order", "2")
    assert r.returncode == 0, r.stderr  # certified valid
    assert "does not conform" not in r.stderr, r.stderr
    healing = report["healing"]
    imprint = healing["imprint"]
    assert imprint["imprinted"] and len(imprint["interfaces"]) > 0, imprint
    # The point contacts' edges were taken out, and the fuse was done again with a tenth of
    # its fuzzy value (the first one stretched a tolerance past ten times the value).
    assert imprint["contact_edges"] > 0, imprint
    assert imprint["fuzzy"] == pytest.approx(healing["tolerance"]), (imprint, healing)
    # Conforming: every interface face's triangles are faces of two tetrahedra, of the two
    # solids it separates; no face of the mesh has more than two tetrahedra.
    m = meshio.read(msh)
    faces = tet_faces(m)
    assert all(len(s) <= 2 for s in faces.values())
    tris = triangles(m)
    for interface in imprint["interfaces"]:
        on_it = [t for t, tag in tris if tag == interface["face"]]
        assert on_it, interface
        for t in on_it:
            assert sorted(faces[t]) == interface["solids"], (interface, t, faces[t])

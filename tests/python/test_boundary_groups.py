"""Named boundary groups: "wall" and "farfield" on the sphere in a box become Gmsh physical
groups (read back by meshio and by Gmsh itself) and Nektar++ composites with those names, each
holding exactly the boundary cells of its faces; bad groups are refused by name."""

import re
import xml.etree.ElementTree as ET

import meshio
import numpy as np
import pytest

import homesh

from conftest import ROOT, run

SPHERE_BOX = ROOT / "examples" / "sphere_box.step"


@pytest.fixture(scope="module")
def mesh():
    return homesh.mesh(SPHERE_BOX, order=2, size=1.2)


def boundary_faces(mesh):
    """{face: triangle count} of the mesh's boundary."""
    (block,) = [b for b in mesh.boundary if b.element_type == "tri"]
    faces, counts = np.unique(block.cad_entity, return_counts=True)
    return dict(zip(faces.tolist(), counts.tolist()))


def groups_of(mesh):
    """wall: the sphere's faces (the nodes at radius 1), farfield: the box's."""
    (block,) = [b for b in mesh.boundary if b.element_type == "tri"]
    radius = np.linalg.norm(mesh.nodes[block.elements[:, 0]], axis=1)  # sphere at the origin
    wall = sorted({int(f) for f, r in zip(block.cad_entity, radius) if abs(r - 1.0) < 1e-9})
    farfield = sorted(set(boundary_faces(mesh)) - set(wall))
    assert wall and farfield
    return {"wall": wall, "farfield": farfield}


def test_msh_physical_groups_carry_the_names_and_exactly_their_cells(mesh, tmp_path):
    groups = groups_of(mesh)
    counts = boundary_faces(mesh)
    path = tmp_path / "g.msh"
    mesh.write(path, groups=groups)
    m = meshio.read(path)
    names = {name: tags for name, tags in m.field_data.items()}
    assert "wall" in names and "farfield" in names
    for name, faces in groups.items():
        tag = names[name][0]
        physical = np.concatenate([m.cell_data["gmsh:physical"][i]
                                   for i, c in enumerate(m.cells) if c.type.startswith("triangle")])
        assert int((physical == tag).sum()) == sum(counts[f] for f in faces), name
    # The faces in groups lose their own "FaceN" physical names; the volume keeps "Solid1".
    assert not any(re.fullmatch(r"Face\d+", n) for n in names)
    assert "Solid1" in names


def test_gmsh_reads_the_named_groups(mesh, tmp_path):
    """Gmsh's command line reads the file and writes it again (MSH 2.2) with the names."""
    path = tmp_path / "g.msh"
    mesh.write(path, groups=groups_of(mesh))
    again = tmp_path / "again.msh"
    result = run(["gmsh", path, "-0", "-format", "msh22", "-o", again])
    assert result.returncode == 0, result.stdout + result.stderr
    names = re.search(r"\$PhysicalNames\n(.*)\$EndPhysicalNames", again.read_text(),
                      re.S).group(1)
    assert '"wall"' in names and '"farfield"' in names


def test_nektar_composites_carry_the_names(mesh, tmp_path):
    groups = groups_of(mesh)
    counts = boundary_faces(mesh)
    path = tmp_path / "g.xml"
    mesh.write(path, groups=groups)
    composites = {c.get("NAME"): c.text for c in ET.parse(path).iter("C")}
    for name, faces in groups.items():
        ids = re.search(r"F\[([^\]]*)\]", composites[name]).group(1)
        n = sum(int(b) - int(a) + 1 if "-" in part else 1
                for part in ids.split(",") for a, b in [(part.split("-") + [part])[:2]])
        assert n == sum(counts[f] for f in faces), name
    assert homesh.read(path).num_elements == mesh.num_elements


@pytest.mark.parametrize("groups, message", [
    ({"": [1]}, "has no name"),
    ({'a"b': [1]}, "must not contain a quote"),
    ({"wall": [1], "inlet": [1]}, "Face1 is in two boundary groups, 'wall' and 'inlet'"),
    # (sphere_box.step's touching solids are imprinted: numbers are the file's, of 8 faces)
    ({"wall": [999]}, "boundary group 'wall': entity 999: the model has 8 (Face1 to Face8)"),
    ({"wall": []}, "'wall' is empty"),
])
def test_bad_groups_are_refused_by_name(mesh, tmp_path, groups, message):
    with pytest.raises(homesh.ParameterError, match=re.escape(message)):
        mesh.write(tmp_path / "bad.msh", groups=groups)
    assert not (tmp_path / "bad.msh").exists()


def test_the_command_line_takes_groups(homesh_bin, tmp_path):
    out = tmp_path / "cli.msh"
    result = run([homesh_bin, "mesh", SPHERE_BOX, "--order", "2", "--size", "1.2",
                  "--group", "farfield=1,2,3,4,5,6", "-o", out, "-q"])
    assert result.returncode in (0, 4), result.stderr
    assert "farfield" in meshio.read(out).field_data
    bad = run([homesh_bin, "mesh", SPHERE_BOX, "--group", "wall", "-o", out])
    assert bad.returncode == 2 and "NAME=ENTITY" in bad.stderr

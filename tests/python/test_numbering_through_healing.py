"""Numbers a user gives in the file's own numbering (the FaceN FreeCAD shows for the file) are
kept through healing: a STEP of loose faces is sewn into a solid, which numbers its faces and
edges afresh, and the boundary layer, the named groups and the report follow the file's faces
through each step's history (cad/numbering_map.hpp); a face that healing removed is refused,
naming it and the step that removed it."""

import json
import subprocess

import meshio
import numpy as np
import pytest

from conftest import run

# A 4 x 2 x 2 block with a round hole (radius 0.4, axis x = 1.5, y = 1), written as its faces
# alone, last first (so sewing numbers them otherwise than the file), and again with a stray
# square beside it; FreeCAD reads each back and says which of its faces is the hole.
MAKE = """
import FreeCAD, Part, json
V = FreeCAD.Vector
body = Part.makeBox(4, 2, 2).cut(Part.makeCylinder(0.4, 2, V(1.5, 1, 0)))
faces = body.Faces[::-1]
Part.makeCompound(faces).exportStep(%(plain)r)
Part.makeCompound(faces + [Part.makePlane(0.5, 0.5, V(6, 0, 0))]).exportStep(%(stray)r)
seen = {}
for name, path in (("plain", %(plain)r), ("stray", %(stray)r)):
    shape = Part.read(path)
    seen[name] = {"solids": len(shape.Solids),
                  "hole": [i + 1 for i, f in enumerate(shape.Faces)
                           if f.Surface.__class__.__name__ == "Cylinder"],
                  "stray": [i + 1 for i, f in enumerate(shape.Faces)
                            if f.BoundBox.XMin > 5.0]}
# A 2D plate (6 x 4, a round hole of radius 0.5 at the origin) whose right side has a kink
# 1e-7 long: healing merges that edge away and numbers the curves afresh.
w = Part.makePolygon([V(-2, -2, 0), V(4, -2, 0), V(4, 2 - 1e-7, 0), V(4, 2, 0), V(-2, 2, 0),
                      V(-2, -2, 0)])
Part.Face(w).cut(Part.Face(Part.Wire(Part.makeCircle(0.5)))).exportStep(%(plate)r)
shape = Part.read(%(plate)r)
seen["plate"] = {"hole": [i + 1 for i, e in enumerate(shape.Edges)
                          if e.Curve.__class__.__name__ == "Circle"],
                 "kink": [i + 1 for i, e in enumerate(shape.Edges) if e.Length < 1e-6]}
json.dump(seen, open(%(seen)r, "w"))
"""

RADIUS, AXIS, THICKNESS = 0.4, (1.5, 1.0), 0.05
# The CAD's tolerance: healing sews within 1e-6 of the bounding-box diagonal (about 4.9).
CAD_TOLERANCE = 1e-6 * np.sqrt(4**2 + 2**2 + 2**2)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("loose_faces")
    paths = {"plain": str(folder / "holed.step"), "stray": str(folder / "holed_stray.step"),
             "plate": str(folder / "plate.step"), "seen": str(folder / "seen.json")}
    subprocess.run(["freecadcmd", "-c", MAKE % paths], check=True, capture_output=True,
                   timeout=300)
    seen = json.load(open(paths["seen"]))
    # Loose faces: no solid in the file, and one cylindrical face (and one stray square).
    assert seen["plain"]["solids"] == 0 and len(seen["plain"]["hole"]) == 1, seen
    assert len(seen["stray"]["stray"]) == 1, seen
    return paths, seen


def radius(points):
    return np.hypot(points[:, 0] - AXIS[0], points[:, 1] - AXIS[1])


def test_layer_and_groups_follow_the_files_face_numbers_through_sewing(homesh_bin, files,
                                                                       tmp_path):
    paths, seen = files
    hole = seen["plain"]["hole"][0]
    out, report = tmp_path / "m.msh", tmp_path / "r.json"
    r = run([homesh_bin, "mesh", paths["plain"], "--order", "2", "--bl-faces", str(hole),
             "--bl-thickness", str(THICKNESS), "--bl-layers", "3", "--group",
             "hole=%d" % hole, "-o", out, "--report", report])
    assert r.returncode == 0, r.stderr  # certified valid
    assert "healing numbered the faces and edges afresh" in r.stderr, r.stderr
    healing = json.loads(report.read_text())["healing"]
    assert any("sewed the faces" in a for a in healing["actions"]), healing
    # Sewing gave the hole another number: without the map the layer would land elsewhere.
    moved = {e["from"]: e["to"] for e in healing["numbering"]["faces"]}
    assert healing["renumbered"] and hole in moved and moved[hole] != [hole], healing
    m = meshio.read(out)
    # The layer is on the hole: every prism node lies between the hole's wall and the layer's
    # top, to the CAD's tolerance.
    wedges = [c.data for c in m.cells if c.type.startswith("wedge")]
    assert wedges and sum(len(w) for w in wedges) > 0
    r_wedge = radius(m.points[np.unique(np.concatenate(wedges))])
    assert r_wedge.min() > RADIUS - CAD_TOLERANCE, r_wedge.min()
    assert r_wedge.max() < RADIUS + THICKNESS + CAD_TOLERANCE, r_wedge.max()
    # The group named by the file's number holds the hole's triangles: all on the wall.
    group_tag = m.field_data["hole"][0]
    hole_triangles = [c.data for c, tags in zip(m.cells, m.cell_data["gmsh:physical"])
                      if c.type.startswith("triangle") and np.all(tags == group_tag)]
    assert hole_triangles, m.field_data
    r_wall = radius(m.points[np.unique(np.concatenate(hole_triangles))])
    assert np.abs(r_wall - RADIUS).max() < CAD_TOLERANCE, np.abs(r_wall - RADIUS).max()


def test_a_face_healing_removed_is_refused_naming_it_and_why(homesh_bin, files, tmp_path):
    paths, seen = files
    stray = seen["stray"]["stray"][0]
    out = tmp_path / "m.msh"
    r = run([homesh_bin, "mesh", paths["stray"], "--solids-only", "--bl-faces", str(stray),
             "--bl-thickness", str(THICKNESS), "-o", out])
    assert r.returncode == 2, r.stderr
    expected = ("boundary-layer face {0}: Face{0} was removed by leaving out the faces in no "
                "solid (1 face (Face{0}) in no solid, within x [6, 6.5]").format(stray)
    assert expected in r.stderr, r.stderr
    assert not out.exists()
    # The hole's own number still maps: the same file meshes with the layer there.
    hole = seen["stray"]["hole"][0]
    r = run([homesh_bin, "mesh", paths["stray"], "--solids-only", "--order", "2",
             "--bl-faces", str(hole), "--bl-thickness", str(THICKNESS), "-o", out])
    assert r.returncode == 0, r.stderr
    m = meshio.read(out)
    wedges = np.concatenate([c.data for c in m.cells if c.type.startswith("wedge")])
    assert radius(m.points[np.unique(wedges)]).min() > RADIUS - CAD_TOLERANCE


def hole_group_on_wall(msh):
    """The triangles of group 'hole' in the MSH file: how far their nodes are from the hole's
    wall at most, and how many there are."""
    m = meshio.read(msh)
    tag = m.field_data["hole"][0]
    tris = [c.data for c, tags in zip(m.cells, m.cell_data["gmsh:physical"])
            if c.type.startswith("triangle") and np.all(tags == tag)]
    nodes = m.points[np.unique(np.concatenate(tris))]
    return np.abs(radius(nodes) - RADIUS).max(), sum(len(t) for t in tris)


def test_a_saved_mesh_keeps_the_files_numbering_for_its_groups(files, tmp_path):
    """The Python API's mesh, saved (.npz, as FreeCAD stores a HighOrderMesh object's mesh in
    its document) and loaded again, maps groups given in the file's numbering as the mesh just
    made does."""
    import homesh
    paths, seen = files
    hole = seen["plain"]["hole"][0]
    made = homesh.mesh(paths["plain"], order=2)
    assert made.report()["healing"]["renumbered"]
    saved = tmp_path / "m.npz"
    made.write(saved)
    for name, mesh in (("made", made), ("loaded", homesh.load(saved))):
        out = tmp_path / (name + ".msh")
        mesh.write(out, groups={"hole": [hole]})
        off, count = hole_group_on_wall(out)
        assert count > 0 and off < CAD_TOLERANCE, (name, off, count)
    # A number the file does not have is refused by the loaded mesh too.
    with pytest.raises(homesh.ParameterError, match="the model has 7 \\(Face1 to Face7\\)"):
        homesh.load(saved).write(tmp_path / "bad.msh", groups={"hole": [8]})


def test_a_2d_layer_follows_the_files_curve_numbers_through_healing(homesh_bin, files,
                                                                     tmp_path):
    """In a 2D model the layer is given on curves (EdgeN): mapped as curves."""
    paths, seen = files
    hole, kink = seen["plate"]["hole"], seen["plate"]["kink"]
    assert len(hole) == 1 and len(kink) == 1 and kink[0] < hole[0], seen["plate"]
    out = tmp_path / "p.msh"
    r = run([homesh_bin, "mesh", paths["plate"], "--order", "2", "--bl-faces", str(hole[0]),
             "--bl-thickness", "0.05", "--bl-layers", "3", "-o", out])
    assert r.returncode == 0, r.stderr
    assert "healing numbered the faces and edges afresh" in r.stderr, r.stderr
    m = meshio.read(out)
    quads = np.concatenate([c.data for c in m.cells if c.type.startswith("quad")])
    # Every layer node between the hole's wall and the layer's top, to the CAD's tolerance
    # (1e-6 of the plate's diagonal).
    tolerance = 1e-6 * np.hypot(6, 4)
    r_layer = np.hypot(*m.points[np.unique(quads)][:, :2].T)
    assert r_layer.min() > 0.5 - tolerance, r_layer.min()
    assert r_layer.max() < 0.55 + tolerance, r_layer.max()
    r = run([homesh_bin, "mesh", paths["plate"], "--bl-faces", str(kink[0]), "--bl-thickness",
             "0.05", "-o", tmp_path / "k.msh"])
    assert r.returncode == 2, r.stderr
    assert ("boundary-layer curve {0}: Edge{0} was removed by healing (merged edges shorter "
            "than").format(kink[0]) in r.stderr, r.stderr

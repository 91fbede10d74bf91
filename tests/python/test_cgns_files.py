"""CGNS files HOMesh writes, read by two other readers: the CGNS library's own checker
(cgnscheck, Debian's cgns-convert) finds no error or warning in one curved element of every shape
at orders 1 to 4, and VTK's CGNS reader (Debian's python3-vtk9) puts every node where HOMesh
put it, for the types and orders VTK 9.1 reads (its three departures from the SIDS are checked
as such below). HOMesh reads each file back with the same nodes and cells."""

import subprocess

import numpy as np
import pytest
import vtk

import homesh
from homesh import HighOrderMesh, _core

DIM = {"tri": 2, "quad": 2, "tet": 3, "prism": 3, "pyramid": 3, "hex": 3}
LINEAR = {"tri": vtk.vtkTriangle, "quad": vtk.vtkQuad, "tet": vtk.vtkTetra, "prism": vtk.vtkWedge,
          "pyramid": vtk.vtkPyramid, "hex": vtk.vtkHexahedron}


def curved(xi):
    x = np.zeros((len(xi), 3))
    x[:, : xi.shape[1]] = xi
    x[:, 0] += 0.1 * np.sin(2.0 * x[:, 1])
    x[:, 2] += 0.05 * np.cos(x[:, 0])
    return x


def element_mesh(kind, order):
    xi = _core.reference_nodes(kind, order)
    n = len(xi)
    core = _core.mesh_from_arrays(
        DIM[kind], order, curved(xi), np.full(n, DIM[kind], dtype=np.uint8),
        np.ones(n, dtype=np.int32), np.full((n, 2), np.nan),
        [(kind, order, np.arange(n, dtype=np.int64).reshape(1, n), np.ones(1, dtype=np.int32))],
        (0.0, 0.0, 1.0))
    return HighOrderMesh(core), xi


def vtk_cell(path):
    reader = vtk.vtkCGNSReader()
    reader.SetFileName(str(path))
    reader.Update()
    grid = reader.GetOutput().GetBlock(0).GetBlock(0)
    assert grid.GetNumberOfCells() == 1
    cell = grid.GetCell(0)
    return None if cell is None or grid.GetCellType(0) == 0 else cell


def vtk_disagreements(cell, kind, xi):
    """The VTK points whose parametric position, mapped through the corners' reference positions
    (VTK's linear cell), is not the reference position of HOMesh's node found there: each as
    (VTK point, HOMesh's node)."""
    ours = curved(xi)
    ref = np.zeros((len(xi), 3))
    ref[:, : xi.shape[1]] = xi
    points = np.array([cell.GetPoints().GetPoint(k) for k in range(cell.GetNumberOfPoints())])
    # Every VTK point is one of our nodes, exactly (the file holds doubles).
    node = [int(np.argmin(np.linalg.norm(ours - q, axis=1))) for q in points]
    assert np.array_equal(ours[node], points)
    assert sorted(node) == list(range(len(xi)))
    linear = LINEAR[kind]()
    for k in range(linear.GetNumberOfPoints()):
        linear.GetPoints().SetPoint(k, ref[node[k]])
        linear.GetPointIds().SetId(k, k)
    pcoords = np.array(cell.GetParametricCoords()).reshape(-1, 3)[: len(points)]
    wrong = []
    for k, pc in enumerate(pcoords):
        x = [0.0, 0.0, 0.0]
        linear.EvaluateLocation(vtk.reference(0), pc, x, [0.0] * linear.GetNumberOfPoints())
        # Affine images of lattice points: exact but for rounding of a few operations.
        if np.linalg.norm(np.array(x) - ref[node[k]]) > 1e-12:
            wrong.append((k, node[k]))
    return wrong


@pytest.mark.parametrize("kind", list(DIM))
def test_cgnscheck_vtk_and_homesh_read_our_elements(tmp_path, kind):
    vtk_checked = []
    for order in range(1, 5):
        mesh, xi = element_mesh(kind, order)
        path = tmp_path / ("%s%d.cgns" % (kind, order))
        mesh.write(path)
        check = subprocess.run(["cgnscheck", str(path)], capture_output=True, text=True,
                               timeout=900)
        assert check.returncode == 0, check.stdout + check.stderr
        assert "checking complete" in check.stdout
        assert "ERROR" not in check.stdout.upper().replace("ERRORS", ""), check.stdout
        assert "WARNING" not in check.stdout.upper(), check.stdout

        back = homesh.read(path)
        assert back.order == order
        assert np.array_equal(back.nodes, mesh.nodes)
        assert np.array_equal(back.elements, mesh.elements)

        cell = vtk_cell(path)
        if cell is None:
            continue
        vtk_checked.append(order)
        wrong = vtk_disagreements(cell, kind, xi)
        if kind == "hex" and order == 3:
            # VTK 9.1's CGNS reader builds Lagrange hexahedra in VTK 8's numbering, whose edges
            # 10 and 11 (through corners 2-6 and 3-7) are listed the other way round: exactly
            # those four points.
            assert [k for k, _ in wrong] == [28, 29, 30, 31], wrong
        elif kind == "prism" and order == 3:
            # ... and reverses the nodes of PENTA_40's face F3 (N3 N1 N4 N6, N34 next to N3 in
            # the SIDS's figure and table): exactly that face's four points.
            assert [k for k, _ in wrong] == [34, 35, 36, 37], wrong
        elif kind == "pyramid" and order == 2:
            # ... and reads PYRA_14 as VTK's 13-node (serendipity) pyramid: the base's centre, the
            # 14th node, is outside its cell.
            assert [k for k, _ in wrong] == [13], wrong
        else:
            assert wrong == [], (kind, order, wrong)
    # What VTK 9.1 reads of CGNS's high-order types: up to order 3, pyramids up to order 2.
    assert vtk_checked == ([1, 2] if kind == "pyramid" else [1, 2, 3])


def test_order_five_is_refused_and_nothing_is_written(tmp_path):
    mesh, _ = element_mesh("tet", 5)
    path = tmp_path / "tet5.cgns"
    with pytest.raises(Exception, match="up to order 4"):
        mesh.write(path)
    assert not path.exists()


def test_damaged_files_are_errors_never_crashes(tmp_path, data):
    """A curved mesh's CGNS file (box_hole.step at order 2: some 40 sections, which HDF5 keeps
    in its dense link storage) with bytes changed at random (300 damaged copies, a fixed seed):
    each is read or refused with homesh.FileError, and this process lives on. HDF5 itself
    crashes on some such files (a pointer freed twice in its link table: 19 of these 300 here):
    the reader runs the library in a child process, so those are errors too."""
    import random
    mesh = homesh.mesh(str(data / "box_hole.step"), order=2, size=0.9)
    path = tmp_path / "good.cgns"
    mesh.write(path)
    data = path.read_bytes()
    rng = random.Random(11)
    outcomes = {"read": 0, "refused": 0, "crash": 0}
    for i in range(300):
        damaged = bytearray(data)
        for _ in range(rng.choice([1, 4, 16, 64])):
            damaged[rng.randrange(len(damaged) // 4, len(damaged))] = rng.randrange(256)
        bad = tmp_path / ("bad%d.cgns" % i)
        bad.write_bytes(bytes(damaged))
        try:
            homesh.read(bad)
            outcomes["read"] += 1
        except homesh.FileError as e:
            outcomes["crash" if "crashed" in str(e) else "refused"] += 1
            assert str(bad) in str(e) or bad.name in str(e), str(e)
        bad.unlink()
    assert outcomes["refused"] > 0, outcomes

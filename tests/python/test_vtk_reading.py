"""VTK (python3-vtk9) reads our VTU and interprets every Lagrange cell exactly as we do: the
points VTK interpolates inside each cell equal those of our own basis on the Gmsh-ordered
nodes, which proves the node permutation, and the volume VTK integrates equals ours."""

import numpy as np
import pytest

import homesh
from homesh import _core

import vtk  # Debian's python3-vtk9, installed by scripts/install-deps.sh


def read_vtu(path):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    return reader.GetOutput()


def random_simplex_points(dim, count, rng):
    pts = rng.dirichlet(np.ones(dim + 1), size=count)[:, 1:]
    return np.ascontiguousarray(pts)


@pytest.mark.parametrize("order", [1, 2, 3, 4, 5, 6, 8, 10])
def test_vtk_interpolates_our_cells_like_we_do(tmp_path, data, order):
    # Coarser at high order: the test is about node ordering, not about mesh size.
    mesh = homesh.mesh(str(data / "box_hole.step"), order=order, size=1.2 if order <= 6 else 2.5)
    path = tmp_path / "mesh.vtu"
    mesh.write(path)
    grid = read_vtu(path)
    assert grid.GetNumberOfCells() == mesh.num_elements
    assert grid.GetNumberOfPoints() == mesh.num_nodes

    rng = np.random.default_rng(order)
    xi = random_simplex_points(3, 7, rng)
    basis = _core.lagrange_basis("tet", order, xi)  # (7, nodes)
    worst = 0.0
    for cell_id in range(0, mesh.num_elements, max(1, mesh.num_elements // 40)):
        cell = grid.GetCell(cell_id)
        ours = basis @ mesh.nodes[mesh.elements[cell_id]]
        weights = [0.0] * cell.GetNumberOfPoints()
        for k in range(len(xi)):
            x = [0.0, 0.0, 0.0]
            cell.EvaluateLocation(vtk.mutable(0), list(xi[k]), x, weights)
            worst = max(worst, np.linalg.norm(np.array(x) - ours[k]))
    assert worst < 1e-10


@pytest.mark.parametrize("order", [1, 3, 5, 8, 10])
def test_vtk_interpolates_our_triangles_like_we_do(tmp_path, order):
    """A planar (2D) mesh: VTK's Lagrange triangles against our basis."""
    import subprocess
    square = tmp_path / "plate.brep"
    subprocess.run(["freecadcmd", "-c",
                    "import Part; Part.makePlane(3, 2).exportBrep(%r)" % str(square)],
                   check=True, capture_output=True, timeout=120)
    mesh = homesh.mesh(str(square), order=order, size=0.8)
    path = tmp_path / "plate.vtu"
    mesh.write(path)
    grid = read_vtu(path)
    assert grid.GetNumberOfCells() == mesh.num_elements
    rng = np.random.default_rng(order)
    xi = random_simplex_points(2, 5, rng)
    basis = _core.lagrange_basis("tri", order, xi)
    worst = 0.0
    for cell_id in range(mesh.num_elements):
        cell = grid.GetCell(cell_id)
        ours = basis @ mesh.nodes[mesh.elements[cell_id]]
        weights = [0.0] * cell.GetNumberOfPoints()
        for k in range(len(xi)):
            x = [0.0, 0.0, 0.0]
            cell.EvaluateLocation(vtk.mutable(0), [xi[k][0], xi[k][1], 0.0], x, weights)
            worst = max(worst, np.linalg.norm(np.array(x) - ours[k]))
    assert worst < 1e-10


def test_vtk_volume_equals_ours(tmp_path, data):
    """Integrates det J over every cell with VTK's own derivatives and compares with the volume
    from our basis; the sphere mesh also gets close to 4/3 pi."""
    order = 3
    mesh = homesh.mesh(str(data / "sphere.brep"), order=order, size=0.5)
    path = tmp_path / "sphere.vtu"
    mesh.write(path)
    grid = read_vtu(path)
    # A degree-6 collapsed Gauss rule on the unit tetrahedron, built from numpy's Gauss-Jacobi.
    from numpy.polynomial.legendre import leggauss
    g, w = leggauss(5)
    g, w = 0.5 * (g + 1.0), 0.5 * w
    pts, wts = [], []
    for i, a in enumerate(g):
        for j, b in enumerate(g):
            for k, c in enumerate(g):
                x = a * (1 - b) * (1 - c)
                y = b * (1 - c)
                z = c
                pts.append((x, y, z))
                wts.append(w[i] * w[j] * w[k] * (1 - b) * (1 - c) ** 2)
    pts = np.array(pts)
    wts = np.array(wts)
    vtk_volume = 0.0
    derivs = [0.0] * (3 * mesh.elements.shape[1])
    for cell_id in range(grid.GetNumberOfCells()):
        cell = grid.GetCell(cell_id)
        xyz = np.array([cell.GetPoints().GetPoint(n) for n in range(cell.GetNumberOfPoints())])
        for q, p in enumerate(pts):
            cell.InterpolateDerivs(list(p), derivs)
            d = np.array(derivs).reshape(3, -1)
            vtk_volume += wts[q] * np.linalg.det(d @ xyz)
    # Our volume: the same rule with finite differences of our own basis.
    h = 1e-6
    ours = 0.0
    nodes = mesh.nodes[mesh.elements]  # (E, n, 3)
    base = _core.lagrange_basis("tet", order, pts)
    cols = [(_core.lagrange_basis("tet", order, pts + h * np.eye(3)[c]) - base) / h
            for c in range(3)]
    jac = np.stack([np.einsum("qn,enc->eqc", col, nodes) for col in cols], axis=-1)
    ours = float(np.sum(np.linalg.det(jac) * wts[None, :]))
    assert abs(vtk_volume - ours) < 1e-4 * ours
    assert abs(vtk_volume - 4.0 / 3.0 * np.pi) < 0.01

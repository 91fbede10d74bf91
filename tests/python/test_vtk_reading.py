"""VTK (python3-vtk9) reads our VTU and interprets every Lagrange cell exactly as we do: the
points VTK interpolates inside each cell equal those of our own basis on the Gmsh-ordered
nodes, which proves the node permutation, and the volume VTK integrates equals ours."""

import numpy as np
import pytest

import homesh
from homesh import _core, tessellation

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
    # Coarser at high order, and no repair rounds: the test is about node ordering, not about
    # mesh size or validity (order 10 spent 190 s in repair rounds).
    mesh = homesh.mesh(str(data / "box_hole.step"), order=order, size=1.2 if order <= 6 else 2.5,
                       repair_rounds=0)
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
    assert worst < rounding_bound(basis, mesh.nodes)


def rounding_bound(basis, nodes):
    """What two evaluations of sum_n phi_n(xi) x_n may differ by: each sums N terms of size
    <= |phi_n| max|x| (N eps of their sum, sum |phi_n| the Lebesgue function), and the basis
    values carry as much again; twice for the two sides, and 4x margin."""
    n = basis.shape[1]
    lebesgue = np.abs(basis).sum(axis=1).max()
    return 16 * n * np.finfo(float).eps * lebesgue * np.abs(nodes).max()


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
    assert worst < rounding_bound(basis, mesh.nodes)


def test_vtk_volume_equals_ours(tmp_path, data):
    """Integrates det J over every cell with VTK's own derivatives and compares with our exact
    volume; the sphere mesh also gets close to 4/3 pi."""
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
    # Our volume: the exact integral of each element's Jacobian (element_volumes). The rule
    # above integrates det J (degree 6 at order 3, 8 with the collapse factor) exactly too, so
    # the two differ by rounding only: per element ~N eps sum|dphi| <= 20 * 50 eps relative
    # (order-3 basis derivatives), plus n eps for summing n cells; allowed: 1e3 n eps.
    ours = float(np.sum(mesh.element_volumes()))
    assert abs(vtk_volume - ours) < 1e3 * grid.GetNumberOfCells() * np.finfo(float).eps * ours
    # The curved mesh approximates the ball: the volumes differ by at most the sphere's area
    # times the boundary's largest distance from it, sampled on a level-6 tessellation of the
    # boundary triangles (x1.5 for the largest falling between samples). Measured: 1.6e-3
    # against a bound of 0.07 (the distance depends on Gmsh's mesh, so it is measured here).
    points = tessellation.surface_and_edges(mesh, level=6)["points"]
    deviation = np.max(np.abs(np.linalg.norm(points, axis=1) - 1.0))
    assert abs(vtk_volume - 4.0 / 3.0 * np.pi) < 1.5 * 4.0 * np.pi * deviation

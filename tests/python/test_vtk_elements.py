"""One curved element of every type and order, written to VTU (base64 and appended binary) and
read back by VTK (Debian's python3-vtk9): VTK's volume of each equals ours to 1e-10, which
proves the VTK Lagrange node ordering of every type."""

import numpy as np
import pytest
import vtk  # Debian's python3-vtk9, installed by scripts/install-deps.sh

from homesh import HighOrderMesh, _core

DIM = {"tri": 2, "quad": 2, "tet": 3, "prism": 3, "hex": 3}
CASES = [(t, p) for t in ("tri", "quad", "tet") for p in range(1, 11)] + \
        [(t, p) for t in ("prism", "hex") for p in range(1, 7)]


def curved(xi):
    """A smooth, orientation-preserving map of the reference shape."""
    x = np.zeros((len(xi), 3))
    x[:, : xi.shape[1]] = xi @ np.diag([2.0, 1.5, 1.2][: xi.shape[1]])
    x[:, 0] += 0.1 * np.sin(2.0 * x[:, 1]) + 0.05 * x[:, 1]
    x[:, 1] += 0.1 * np.sin(1.5 * x[:, 0])
    if xi.shape[1] == 3:
        x[:, 2] += 0.08 * np.cos(x[:, 0] + x[:, 1])
    return x


def element_mesh(kind, order):
    xi = _core.reference_nodes(kind, order)
    nodes = curved(xi)
    n = len(nodes)
    core = _core.mesh_from_arrays(
        DIM[kind], order, nodes, np.full(n, DIM[kind], dtype=np.uint8),
        np.ones(n, dtype=np.int32), np.full((n, 2), np.nan),
        [(kind, order, np.arange(n, dtype=np.int64).reshape(1, n), np.ones(1, dtype=np.int32))],
        (0.0, 0.0, 1.0))
    return HighOrderMesh(core)


def vtk_volume(path, kind, order):
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(str(path))
    reader.Update()
    grid = reader.GetOutput()
    assert grid.GetNumberOfCells() == 1
    cell = grid.GetCell(0)
    points, weights = _core.quadrature_rule(kind, 3 * order + 2)
    xyz = np.array([cell.GetPoints().GetPoint(k) for k in range(cell.GetNumberOfPoints())])
    dim = DIM[kind]
    assert cell.GetCellDimension() == dim
    derivs = [0.0] * (dim * cell.GetNumberOfPoints())
    volume = 0.0
    for p, w in zip(points, weights):
        pc = [0.0, 0.0, 0.0]
        pc[:dim] = p
        cell.InterpolateDerivs(pc, derivs)
        # VTK's Lagrange quadrilaterals and hexahedra interleave the derivatives node by node;
        # its triangles, tetrahedra and wedges list them direction by direction.
        node_major = kind in ("quad", "hex")
        grads = np.array(derivs).reshape(-1, dim).T if node_major else \
            np.array(derivs).reshape(dim, -1)
        d = grads @ xyz  # dim x 3
        volume += w * (np.cross(d[0], d[1])[2] if dim == 2 else np.linalg.det(d))
    return volume


@pytest.mark.parametrize("kind, order", CASES)
def test_vtk_measures_our_element_like_we_do(tmp_path, kind, order):
    mesh = element_mesh(kind, order)
    ours = float(mesh.element_volumes()[0])
    assert ours > 0.0
    for binary in (False, True):
        path = tmp_path / ("e%d.vtu" % binary)
        mesh.write(path, binary=binary)
        # Two exact quadratures of the same polynomial det J, rounded differently: VTK's
        # Lagrange derivatives at order 10 sum ~10^3 terms of size up to ~10^3 (equispaced
        # nodes), so ~1e-12 relative; 1e-10 leaves a factor 100 (measured below 1e-12).
        assert abs(vtk_volume(path, kind, order) - ours) < 1e-10 * abs(ours), (kind, order)


def test_straight_elements_have_their_exact_volume():
    for kind, exact in (("tri", 0.5 * 2 * 1.5), ("quad", 2 * 1.5), ("tet", 2 * 1.5 * 1.2 / 6),
                        ("prism", 0.5 * 2 * 1.5 * 1.2), ("hex", 2 * 1.5 * 1.2)):
        xi = _core.reference_nodes(kind, 3)
        nodes = np.zeros((len(xi), 3))
        nodes[:, : xi.shape[1]] = xi @ np.diag([2.0, 1.5, 1.2][: xi.shape[1]])
        n = len(nodes)
        core = _core.mesh_from_arrays(
            DIM[kind], 3, nodes, np.zeros(n, dtype=np.uint8), np.zeros(n, dtype=np.int32),
            np.full((n, 2), np.nan),
            [(kind, 3, np.arange(n, dtype=np.int64).reshape(1, n), np.ones(1, dtype=np.int32))],
            (0.0, 0.0, 1.0))
        # An exact quadrature of a constant det J: a few ulps of the volume (<= 3.6).
        assert abs(HighOrderMesh(core).element_volumes()[0] - exact) < 1e-12

#!/usr/bin/python3
"""Draws docs/images/bracket.png from a mesh that `homesh` made of examples/bracket.step.

    homesh mesh examples/bracket.step --order 4 --optimise -o /tmp/bracket.msh
    /usr/bin/python3 docs/images/make_bracket_picture.py /tmp/bracket.msh docs/images/bracket.png

Reads the MSH 4.1 file (ASCII, as `homesh mesh` writes it by default) with a small reader of its
own, takes the curved boundary triangles (15-node, order 4) and the curves on the CAD edges
(5-node lines), and renders them with a z-buffer: each triangle's surface through its own
polynomial map (shaded by the normal), its three curved edges as polylines, the CAD edges
thicker. Hidden lines are removed by the depth test, so what the picture shows is the mesh as
written, nothing smoothed. Needs numpy and Pillow (Debian's python3-numpy, python3-pil).
"""
import sys

import numpy as np
from PIL import Image

SUPERSAMPLE = 3        # rendered at 3x and averaged down: anti-aliased lines
WIDTH, HEIGHT = 760, 600
AZIMUTH, ELEVATION = -55.0, 28.0   # degrees
SUBDIV = 8             # each curved triangle drawn as SUBDIV^2 flat ones
EDGE_SAMPLES = 24      # points along each curved edge


def read_msh(path):
    """Nodes {tag: xyz} and element blocks [(dim, entity, type, [[node tags]])] of MSH 4.1."""
    with open(path) as f:
        lines = iter(f.read().splitlines())
    nodes, blocks = {}, []
    for line in lines:
        if line == "$MeshFormat":
            version = next(lines).split()
            if version[0] != "4.1" or version[1] != "0":
                sys.exit("expected an ASCII MSH 4.1 file")
        elif line == "$Nodes":
            n_blocks = int(next(lines).split()[0])
            for _ in range(n_blocks):
                _, _, _, count = map(int, next(lines).split())
                tags = [int(next(lines)) for _ in range(count)]
                for tag in tags:
                    nodes[tag] = [float(v) for v in next(lines).split()]
        elif line == "$Elements":
            n_blocks = int(next(lines).split()[0])
            for _ in range(n_blocks):
                dim, entity, etype, count = map(int, next(lines).split())
                cells = [[int(v) for v in next(lines).split()[1:]] for _ in range(count)]
                blocks.append((dim, entity, etype, cells))
    return nodes, blocks


def triangle_basis(order, points):
    """Lagrange basis of the equispaced order-P triangle at (u, v) points, Gmsh's node order."""
    lattice = gmsh_triangle_lattice(order)
    # Solve for the basis through the monomials u^a v^b, a + b <= P.
    exps = [(a, b) for a in range(order + 1) for b in range(order + 1 - a)]
    def vander(uv):
        return np.stack([uv[:, 0] ** a * uv[:, 1] ** b for a, b in exps], axis=1)
    coeff = np.linalg.inv(vander(lattice / order))
    return vander(points) @ coeff


def gmsh_triangle_lattice(order):
    """(i, j) lattice coordinates of Gmsh's nodes of the order-P triangle (recursive order)."""
    if order == 0:
        return np.array([[0.0, 0.0]])
    nodes = [(0, 0), (order, 0), (0, order)]
    nodes += [(i, 0) for i in range(1, order)]
    nodes += [(order - i, i) for i in range(1, order)]
    nodes += [(0, order - i) for i in range(1, order)]
    if order >= 3:
        inner = gmsh_triangle_lattice(order - 3)
        nodes += [(1 + i, 1 + j) for i, j in inner]
    return np.array(nodes, dtype=float)


def line_basis(order, t):
    """Lagrange basis of the equispaced order-P line at t in [0, 1], Gmsh's node order."""
    params = np.array([0.0, 1.0] + [i / order for i in range(1, order)])
    basis = np.ones((len(t), order + 1))
    for k in range(order + 1):
        for m in range(order + 1):
            if m != k:
                basis[:, k] *= (t - params[m]) / (params[k] - params[m])
    return basis


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    nodes, blocks = read_msh(sys.argv[1])
    tags = np.array(sorted(nodes))
    xyz = np.array([nodes[t] for t in tags])
    index = {t: i for i, t in enumerate(tags)}
    def cells_of(gmsh_type):
        return np.array([[index[t] for t in cell] for _, _, ty, cells in blocks
                         if ty == gmsh_type for cell in cells])
    tris = cells_of(23)     # 15-node triangles (order 4) on the CAD faces
    lines = cells_of(27)    # 5-node lines (order 4) on the CAD edges
    order = 4
    if tris.shape[1] != 15 or lines.shape[1] != 5:
        sys.exit("expected a mesh of order 4 (15-node triangles, 5-node lines)")

    # View: rotate so that the camera looks down -z.
    az, el = np.radians(AZIMUTH), np.radians(ELEVATION)
    rz = np.array([[np.cos(az), -np.sin(az), 0], [np.sin(az), np.cos(az), 0], [0, 0, 1]])
    rx = np.array([[1, 0, 0], [0, np.cos(el - np.pi / 2), -np.sin(el - np.pi / 2)],
                   [0, np.sin(el - np.pi / 2), np.cos(el - np.pi / 2)]])
    view = rx @ rz
    centre = 0.5 * (xyz.min(0) + xyz.max(0))
    p = (xyz - centre) @ view.T
    w, h = WIDTH * SUPERSAMPLE, HEIGHT * SUPERSAMPLE
    scale = 0.92 * min(w / np.ptp(p[:, 0]), h / np.ptp(p[:, 1]))
    def to_screen(q):
        return np.stack([w / 2 + scale * q[..., 0], h / 2 - scale * q[..., 1], q[..., 2]], -1)

    # Sub-triangles of every curved triangle, through its own map.
    sub = [(i, j) for i in range(SUBDIV + 1) for j in range(SUBDIV + 1 - i)]
    sub_index = {ij: k for k, ij in enumerate(sub)}
    sub_tris = []
    for i in range(SUBDIV):
        for j in range(SUBDIV - i):
            sub_tris.append((sub_index[i, j], sub_index[i + 1, j], sub_index[i, j + 1]))
            if i + j < SUBDIV - 1:
                sub_tris.append((sub_index[i + 1, j], sub_index[i + 1, j + 1], sub_index[i, j + 1]))
    sub_tris = np.array(sub_tris)
    basis = triangle_basis(order, np.array(sub, dtype=float) / SUBDIV)
    surface = np.einsum("sn,tnc->tsc", basis, p[tris])          # (T, S, 3) in view space
    screen = to_screen(surface)

    zbuf = np.full((h, w), -np.inf)
    image = np.ones((h, w, 3), dtype=np.float32)
    light = np.array([-0.35, 0.45, 0.82])
    light /= np.linalg.norm(light)
    base = np.array([0.70, 0.80, 0.93])
    for t in range(len(tris)):
        corners = screen[t][sub_tris]                           # (k, 3, 3)
        normals = np.cross(surface[t][sub_tris[:, 1]] - surface[t][sub_tris[:, 0]],
                           surface[t][sub_tris[:, 2]] - surface[t][sub_tris[:, 0]])
        normals /= np.linalg.norm(normals, axis=1, keepdims=True) + 1e-300
        shade = 0.55 + 0.45 * np.abs(normals @ light)
        for c, s in zip(corners, shade):
            x0, x1 = int(max(c[:, 0].min(), 0)), int(min(c[:, 0].max() + 1, w))
            y0, y1 = int(max(c[:, 1].min(), 0)), int(min(c[:, 1].max() + 1, h))
            if x0 >= x1 or y0 >= y1:
                continue
            xs, ys = np.meshgrid(np.arange(x0, x1) + 0.5, np.arange(y0, y1) + 0.5)
            (ax, ay, az0), (bx, by, bz), (cx, cy, cz) = c
            det = (by - cy) * (ax - cx) + (cx - bx) * (ay - cy)
            if abs(det) < 1e-12:
                continue
            l0 = ((by - cy) * (xs - cx) + (cx - bx) * (ys - cy)) / det
            l1 = ((cy - ay) * (xs - cx) + (ax - cx) * (ys - cy)) / det
            l2 = 1 - l0 - l1
            inside = (l0 >= -1e-9) & (l1 >= -1e-9) & (l2 >= -1e-9)
            z = l0 * az0 + l1 * bz + l2 * cz
            region = zbuf[y0:y1, x0:x1]
            nearer = inside & (z > region)
            region[nearer] = z[nearer]
            image[y0:y1, x0:x1][nearer] = base * s

    # Curved edges: the element edges (thin) and the CAD curves (thick), depth-tested.
    t = np.linspace(0.0, 1.0, EDGE_SAMPLES)
    edge_nodes = [[0, 3, 4, 5, 1], [1, 6, 7, 8, 2], [2, 9, 10, 11, 0]]   # Gmsh's triangle edges
    lb = line_basis(order, t)
    gmsh_line = [0, 4, 1, 2, 3]        # equispaced positions -> Gmsh's line node order
    seen, thin = set(), []
    for tri in tris:
        for ids in edge_nodes:
            key = tuple(sorted((tri[ids[0]], tri[ids[-1]], tri[ids[2]])))
            if key in seen:
                continue
            seen.add(key)
            ordered = np.array([tri[k] for k in ids])[gmsh_line]
            thin.append(lb @ p[ordered])
    thick = [lb @ p[line] for line in lines]
    depth_tol = 0.004 * np.ptp(p[:, 2])
    for polylines, width, grey in ((thin, 1.0, 0.22), (thick, 2.4, 0.0)):
        samples = []
        for points in polylines:
            q = to_screen(points)
            for a, b in zip(q[:-1], q[1:]):
                n = int(np.hypot(*(b[:2] - a[:2])) * 2) + 2
                samples.append(a + np.linspace(0, 1, n)[:, None] * (b - a))
        seg = np.concatenate(samples)
        r = width * SUPERSAMPLE / 2
        for dx in np.arange(-r, r + 0.01, 1.0):
            for dy in np.arange(-r, r + 0.01, 1.0):
                if dx * dx + dy * dy > r * r + 0.25:
                    continue
                xs = (seg[:, 0] + dx).astype(int)
                ys = (seg[:, 1] + dy).astype(int)
                ok = (xs >= 0) & (xs < w) & (ys >= 0) & (ys < h)
                xs, ys, zs = xs[ok], ys[ok], seg[ok, 2]
                visible = zs >= zbuf[ys, xs] - depth_tol
                image[ys[visible], xs[visible]] = grey

    small = image.reshape(HEIGHT, SUPERSAMPLE, WIDTH, SUPERSAMPLE, 3).mean(axis=(1, 3))
    picture = Image.fromarray((np.clip(small, 0, 1) * 255).astype(np.uint8))
    picture.quantize(colors=64, dither=Image.Dither.NONE).save(sys.argv[2], optimize=True)
    print(f"{sys.argv[2]}: {len(tris)} curved triangles, {len(lines)} CAD edge curves")


if __name__ == "__main__":
    main()

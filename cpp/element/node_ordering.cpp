#include "element/node_ordering.hpp"

#include <map>
#include <string>
#include <utility>

#include "core/error.hpp"

namespace homesh {
namespace {

using P3 = LatticePoint;
using Nodes = std::vector<P3>;

P3 operator+(P3 a, const P3& b) {
  for (int k = 0; k < 3; ++k) a[k] += b[k];
  return a;
}
P3 operator-(P3 a, const P3& b) {
  for (int k = 0; k < 3; ++k) a[k] -= b[k];
  return a;
}
// a + (b - a) * t / n, exact: corner differences are multiples of n by construction.
P3 along(const P3& a, const P3& b, int t, int n) {
  P3 r = a;
  for (int k = 0; k < 3; ++k) r[k] += (b[k] - a[k]) / n * t;
  return r;
}

void edge(Nodes& out, const P3& a, const P3& b, int n) {
  for (int t = 1; t < n; ++t) out.push_back(along(a, b, t, n));
}

// Corners moved one lattice step towards the given neighbours: the corners of the interior
// sub-element (order n - 3 for simplices' faces, n - 4 tetrahedron, n - 2 tensor shapes).
P3 inward(const P3& corner, const std::vector<P3>& neighbours, int n) {
  P3 r = corner;
  for (const P3& b : neighbours) r = r + along(P3{0, 0, 0}, b - corner, 1, n);
  return r;
}

// Recursive triangle (Gmsh and VTK): vertices, edges ab, bc, ca, interior of order n - 3.
void triangle(Nodes& out, const P3& a, const P3& b, const P3& c, int n) {
  if (n == 0) {
    out.push_back(a);
    return;
  }
  out.insert(out.end(), {a, b, c});
  edge(out, a, b, n);
  edge(out, b, c, n);
  edge(out, c, a, n);
  if (n >= 3)
    triangle(out, inward(a, {b, c}, n), inward(b, {a, c}, n), inward(c, {a, b}, n), n - 3);
}

// Interior of a triangle face, ordered as a recursive triangle of order n - 3.
void triangleInterior(Nodes& out, const P3& a, const P3& b, const P3& c, int n) {
  if (n >= 3)
    triangle(out, inward(a, {b, c}, n), inward(b, {a, c}, n), inward(c, {a, b}, n), n - 3);
}

// Recursive quadrilateral (Gmsh): vertices, edges ab, bc, cd, da, interior of order n - 2.
void quadrilateral(Nodes& out, const P3& a, const P3& b, const P3& c, const P3& d, int n) {
  if (n == 0) {
    out.push_back(a);
    return;
  }
  out.insert(out.end(), {a, b, c, d});
  edge(out, a, b, n);
  edge(out, b, c, n);
  edge(out, c, d, n);
  edge(out, d, a, n);
  if (n >= 2)
    quadrilateral(out, inward(a, {b, d}, n), inward(b, {a, c}, n), inward(c, {b, d}, n),
                  inward(d, {a, c}, n), n - 2);
}

void quadrilateralInterior(Nodes& out, const P3& a, const P3& b, const P3& c, const P3& d, int n) {
  if (n >= 2)
    quadrilateral(out, inward(a, {b, d}, n), inward(b, {a, c}, n), inward(c, {b, d}, n),
                  inward(d, {a, c}, n), n - 2);
}

using Edges = std::vector<std::pair<int, int>>;
using Faces = std::vector<std::vector<int>>;

void corners(Nodes& out, const std::vector<P3>& v) {
  out.insert(out.end(), v.begin(), v.end());
}
void edges(Nodes& out, const std::vector<P3>& v, const Edges& list, int n) {
  for (const auto& [a, b] : list) edge(out, v[a], v[b], n);
}

void tetrahedron(Nodes& out, const std::vector<P3>& v, int n, NodeConvention convention) {
  if (n == 0) {
    out.push_back(v[0]);
    return;
  }
  const bool gmsh = convention == NodeConvention::Gmsh;
  const Edges edgeList = gmsh ? Edges{{0, 1}, {1, 2}, {2, 0}, {3, 0}, {3, 2}, {3, 1}}
                              : Edges{{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
  const Faces faceList = gmsh ? Faces{{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {3, 1, 2}}
                              : Faces{{0, 1, 3}, {2, 3, 1}, {0, 3, 2}, {0, 2, 1}};
  corners(out, v);
  edges(out, v, edgeList, n);
  for (const auto& f : faceList) triangleInterior(out, v[f[0]], v[f[1]], v[f[2]], n);
  if (n >= 4) {
    std::vector<P3> inner;
    for (int i = 0; i < 4; ++i) {
      std::vector<P3> others;
      for (int j = 0; j < 4; ++j)
        if (j != i) others.push_back(v[j]);
      inner.push_back(inward(v[i], others, n));
    }
    tetrahedron(out, inner, n - 4, convention);
  }
}

void gmshHexahedron(Nodes& out, const std::vector<P3>& v, int n) {
  if (n == 0) {
    out.push_back(v[0]);
    return;
  }
  corners(out, v);
  edges(out, v,
        {{0, 1},
         {0, 3},
         {0, 4},
         {1, 2},
         {1, 5},
         {2, 3},
         {2, 6},
         {3, 7},
         {4, 5},
         {4, 7},
         {5, 6},
         {6, 7}},
        n);
  for (const auto& f :
       Faces{{0, 3, 2, 1}, {0, 1, 5, 4}, {0, 4, 7, 3}, {1, 2, 6, 5}, {2, 3, 7, 6}, {4, 5, 6, 7}})
    quadrilateralInterior(out, v[f[0]], v[f[1]], v[f[2]], v[f[3]], n);
  if (n >= 2) {
    // Each corner's three neighbours along hexahedron edges.
    static const int adjacent[8][3] = {{1, 3, 4}, {0, 2, 5}, {1, 3, 6}, {0, 2, 7},
                                       {0, 5, 7}, {1, 4, 6}, {2, 5, 7}, {3, 4, 6}};
    std::vector<P3> inner;
    inner.reserve(8);
    for (int i = 0; i < 8; ++i)
      inner.push_back(inward(v[i], {v[adjacent[i][0]], v[adjacent[i][1]], v[adjacent[i][2]]}, n));
    gmshHexahedron(out, inner, n - 2);
  }
}

// Gmsh's line of order n between lattice coordinates lo and hi (vertices first).
std::vector<int> gmshLine(int lo, int hi, int n) {
  std::vector<int> k{lo};
  if (n == 0) return k;
  k.push_back(hi);
  for (int t = 1; t < n; ++t) k.push_back(lo + (hi - lo) / n * t);
  return k;
}

void gmshPrism(Nodes& out, const std::vector<P3>& v, int n) {
  corners(out, v);
  edges(out, v, {{0, 1}, {0, 2}, {0, 3}, {1, 2}, {1, 4}, {2, 5}, {3, 4}, {3, 5}, {4, 5}}, n);
  triangleInterior(out, v[0], v[2], v[1], n);
  triangleInterior(out, v[3], v[4], v[5], n);
  for (const auto& f : Faces{{0, 1, 4, 3}, {0, 3, 5, 2}, {1, 2, 5, 4}})
    quadrilateralInterior(out, v[f[0]], v[f[1]], v[f[2]], v[f[3]], n);
  if (n >= 3) {
    Nodes tri;
    triangleInterior(tri, v[0], v[1], v[2], n);
    const std::vector<int> ks = gmshLine(1, n - 1, n - 2);
    for (const P3& p : tri)
      for (const int k : ks) out.push_back({p[0], p[1], k});
  }
}

// Gmsh's pyramid: base corners 0-3, apex 4; the eight edges, the four triangles' interiors, the
// base's interior (as the quadrilateral 0, 3, 2, 1), then the interior: a pyramid of order n - 3
// one lattice step inside every face.
void gmshPyramid(Nodes& out, const std::vector<P3>& v, int n) {
  if (n == 0) {
    out.push_back(v[0]);
    return;
  }
  corners(out, v);
  edges(out, v, {{0, 1}, {0, 3}, {0, 4}, {1, 2}, {1, 4}, {2, 3}, {2, 4}, {3, 4}}, n);
  for (const auto& f : Faces{{0, 1, 4}, {3, 0, 4}, {1, 2, 4}, {2, 3, 4}})
    triangleInterior(out, v[f[0]], v[f[1]], v[f[2]], n);
  quadrilateralInterior(out, v[0], v[3], v[2], v[1], n);
  if (n >= 3)
    gmshPyramid(out,
                {inward(v[0], {v[1], v[3], v[4]}, n), inward(v[1], {v[0], v[2], v[4]}, n),
                 inward(v[2], {v[1], v[3], v[4]}, n), inward(v[3], {v[0], v[2], v[4]}, n),
                 // the apex steps down the axis: one step towards the base's diagonal ends
                 inward(v[4], {v[0], v[2]}, n)},
                n - 3);
}

void vtkQuadrilateral(Nodes& out, int n) {
  // (push_back rather than insert of a list: GCC 12 warns falsely about the latter here)
  for (const P3& corner : {P3{0, 0, 0}, P3{n, 0, 0}, P3{n, n, 0}, P3{0, n, 0}})
    out.push_back(corner);
  edge(out, {0, 0, 0}, {n, 0, 0}, n);
  edge(out, {n, 0, 0}, {n, n, 0}, n);
  edge(out, {0, n, 0}, {n, n, 0}, n);
  edge(out, {0, 0, 0}, {0, n, 0}, n);
  for (int j = 1; j < n; ++j)
    for (int i = 1; i < n; ++i) out.push_back({i, j, 0});
}

void vtkHexahedron(Nodes& out, const std::vector<P3>& v, int n) {
  corners(out, v);
  edges(out, v,
        {{0, 1},
         {1, 2},
         {3, 2},
         {0, 3},
         {4, 5},
         {5, 6},
         {7, 6},
         {4, 7},
         {0, 4},
         {1, 5},
         {2, 6},
         {3, 7}},
        n);
  // Faces x = 0, x = n, y = 0, y = n, z = 0, z = n; each row-major in its two free axes.
  for (int axis = 0; axis < 3; ++axis) {
    const int a = axis == 0 ? 1 : 0, b = axis == 2 ? 1 : 2;
    for (const int side : {0, n})
      for (int q = 1; q < n; ++q)
        for (int p = 1; p < n; ++p) {
          P3 c{0, 0, 0};
          c[axis] = side;
          c[a] = p;
          c[b] = q;
          out.push_back(c);
        }
  }
  for (int k = 1; k < n; ++k)
    for (int j = 1; j < n; ++j)
      for (int i = 1; i < n; ++i) out.push_back({i, j, k});
}

void vtkWedge(Nodes& out, const std::vector<P3>& v, int n) {
  corners(out, v);
  edges(out, v, {{0, 1}, {1, 2}, {2, 0}, {3, 4}, {4, 5}, {5, 3}, {0, 3}, {1, 4}, {2, 5}}, n);
  for (const int k : {0, n})
    for (int j = 1; j < n; ++j)
      for (int i = 1; i + j < n; ++i) out.push_back({i, j, k});
  for (int k = 1; k < n; ++k)
    for (int i = 1; i < n; ++i) out.push_back({i, 0, k});
  for (int k = 1; k < n; ++k)
    for (int j = 1; j < n; ++j) out.push_back({n - j, j, k});
  for (int k = 1; k < n; ++k)
    for (int j = n - 1; j >= 1; --j) out.push_back({0, j, k});
  for (int k = 1; k < n; ++k)
    for (int j = 1; j < n; ++j)
      for (int i = 1; i + j < n; ++i) out.push_back({i, j, k});
}

// CGNS's interior of a quadrilateral face (SIDS, "Unstructured Grid Element Numbering
// Conventions", QUAD_16 / QUAD_25 and the faces of HEXA_64 / HEXA_125, PENTA_75, PYRA_55): the
// (n-1) x (n-1) interior nodes walked ring by ring from the one next to corner a, towards b,
// then c and d, each ring's corners and side nodes in turn, then the ring inside it.
void cgnsRing(Nodes& out, const P3& a, const P3& b, const P3& c, const P3& d, int m) {
  if (m == 0) {
    out.push_back(a);
    return;
  }
  const P3* ring[4] = {&a, &b, &c, &d};
  for (int s = 0; s < 4; ++s) {
    out.push_back(*ring[s]);
    edge(out, *ring[s], *ring[(s + 1) % 4], m);
  }
  if (m >= 2)
    cgnsRing(out, inward(a, {b, d}, m), inward(b, {a, c}, m), inward(c, {b, d}, m),
             inward(d, {a, c}, m), m - 2);
}

void cgnsQuadrilateralInterior(Nodes& out, const P3& a, const P3& b, const P3& c, const P3& d,
                               int n) {
  if (n >= 2)
    cgnsRing(out, inward(a, {b, d}, n), inward(b, {a, c}, n), inward(c, {b, d}, n),
             inward(d, {a, c}, n), n - 2);
}

P3 lifted(P3 p, int k) {
  p[2] += k;
  return p;
}

// CGNS (orders 1 to 4; SIDS figures TRI_15, QUAD_25, TETRA_35, PYRA_55, PENTA_75, HEXA_125 and
// their tables): vertices, edges, faces' interiors (triangles as Gmsh's recursion, which for the
// one or three nodes of orders 3 and 4 is the SIDS's order from the face's first corner;
// quadrilaterals by cgnsRing), then the cell's interior level by level from the base (prisms,
// pyramids, hexahedra) or the tetrahedron's centroid.
void cgnsCell(Nodes& out, CellType type, const std::vector<P3>& v, int n) {
  corners(out, v);
  switch (type) {
    case CellType::Tetrahedron:
      edges(out, v, {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}}, n);
      for (const auto& f : Faces{{0, 1, 2}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}})
        triangleInterior(out, v[f[0]], v[f[1]], v[f[2]], n);
      if (n == 4) out.push_back({1, 1, 1});
      break;
    case CellType::Prism:
      edges(out, v, {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 4}, {2, 5}, {3, 4}, {4, 5}, {5, 3}}, n);
      triangleInterior(out, v[0], v[1], v[2], n);
      for (const auto& f : Faces{{0, 1, 4, 3}, {1, 2, 5, 4}, {2, 0, 3, 5}})
        cgnsQuadrilateralInterior(out, v[f[0]], v[f[1]], v[f[2]], v[f[3]], n);
      triangleInterior(out, v[3], v[4], v[5], n);
      for (int k = 1; k < n; ++k)
        triangleInterior(out, lifted(v[0], k), lifted(v[1], k), lifted(v[2], k), n);
      break;
    case CellType::Pyramid:
      edges(out, v, {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 4}, {1, 4}, {2, 4}, {3, 4}}, n);
      cgnsQuadrilateralInterior(out, v[0], v[1], v[2], v[3], n);
      for (const auto& f : Faces{{0, 1, 4}, {1, 2, 4}, {2, 3, 4}, {3, 0, 4}})
        triangleInterior(out, v[f[0]], v[f[1]], v[f[2]], n);
      for (int k = 1; k + 2 <= n; ++k) {  // level k: the square of side n - k
        const int s = n - k;
        cgnsQuadrilateralInterior(out, {0, 0, k}, {s, 0, k}, {s, s, k}, {0, s, k}, s);
      }
      break;
    case CellType::Hexahedron:
      edges(out, v,
            {{0, 1},
             {1, 2},
             {2, 3},
             {3, 0},
             {0, 4},
             {1, 5},
             {2, 6},
             {3, 7},
             {4, 5},
             {5, 6},
             {6, 7},
             {7, 4}},
            n);
      for (const auto& f : Faces{
               {0, 1, 2, 3}, {0, 1, 5, 4}, {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}, {4, 5, 6, 7}})
        cgnsQuadrilateralInterior(out, v[f[0]], v[f[1]], v[f[2]], v[f[3]], n);
      for (int k = 1; k < n; ++k)
        cgnsQuadrilateralInterior(out, lifted(v[0], k), lifted(v[1], k), lifted(v[2], k),
                                  lifted(v[3], k), n);
      break;
    default:
      throw ParameterError("no CGNS node ordering for " + cellShortName(type));
  }
}

}  // namespace

std::vector<LatticePoint> latticeOrder(CellType type, int order, NodeConvention convention) {
  if (order < 1) throw ParameterError("element order must be >= 1, got " + std::to_string(order));
  const int n = order;
  const bool gmsh = convention == NodeConvention::Gmsh;
  Nodes out;
  if (convention == NodeConvention::Cgns) {
    if (order > 4)
      throw ParameterError("CGNS names elements up to order 4, not order " + std::to_string(order));
    if (type == CellType::Line || type == CellType::Triangle)
      return latticeOrder(type, order, NodeConvention::Gmsh);  // the same numbering
    if (type == CellType::Quadrilateral) {
      const std::vector<P3> v{{0, 0, 0}, {n, 0, 0}, {n, n, 0}, {0, n, 0}};
      corners(out, v);
      edges(out, v, {{0, 1}, {1, 2}, {2, 3}, {3, 0}}, n);
      cgnsQuadrilateralInterior(out, v[0], v[1], v[2], v[3], n);
      return out;
    }
  }
  switch (type) {
    case CellType::Line:
      out = {{0, 0, 0}, {n, 0, 0}};
      edge(out, {0, 0, 0}, {n, 0, 0}, n);
      break;
    case CellType::Triangle:
      triangle(out, {0, 0, 0}, {n, 0, 0}, {0, n, 0}, n);
      break;
    case CellType::Quadrilateral:
      if (gmsh)
        quadrilateral(out, {0, 0, 0}, {n, 0, 0}, {n, n, 0}, {0, n, 0}, n);
      else
        vtkQuadrilateral(out, n);
      break;
    case CellType::Tetrahedron:
      if (convention == NodeConvention::Cgns)
        cgnsCell(out, type, {{0, 0, 0}, {n, 0, 0}, {0, n, 0}, {0, 0, n}}, n);
      else
        tetrahedron(out, {{0, 0, 0}, {n, 0, 0}, {0, n, 0}, {0, 0, n}}, n, convention);
      break;
    case CellType::Prism: {
      const std::vector<P3> v{{0, 0, 0}, {n, 0, 0}, {0, n, 0}, {0, 0, n}, {n, 0, n}, {0, n, n}};
      if (gmsh)
        gmshPrism(out, v, n);
      else if (convention == NodeConvention::Cgns)
        cgnsCell(out, type, v, n);
      else
        vtkWedge(out, v, n);
      break;
    }
    case CellType::Hexahedron: {
      const std::vector<P3> v{{0, 0, 0}, {n, 0, 0}, {n, n, 0}, {0, n, 0},
                              {0, 0, n}, {n, 0, n}, {n, n, n}, {0, n, n}};
      if (gmsh)
        gmshHexahedron(out, v, n);
      else if (convention == NodeConvention::Cgns)
        cgnsCell(out, type, v, n);
      else
        vtkHexahedron(out, v, n);
      break;
    }
    case CellType::Pyramid:
      if (convention == NodeConvention::Vtk)
        throw ParameterError("no VTK node ordering for a pyramid");
      if (gmsh)
        gmshPyramid(out, {{0, 0, 0}, {n, 0, 0}, {n, n, 0}, {0, n, 0}, {0, 0, n}}, n);
      else
        cgnsCell(out, type, {{0, 0, 0}, {n, 0, 0}, {n, n, 0}, {0, n, 0}, {0, 0, n}}, n);
      break;
    default:
      throw ParameterError("no node ordering for " + cellShortName(type));
  }
  if (static_cast<int>(out.size()) != cellNumNodes(type, order))
    throw Error("node ordering of " + cellShortName(type) + " order " + std::to_string(order) +
                " produced " + std::to_string(out.size()) + " nodes");
  return out;
}

std::vector<int> nodePermutationFromGmsh(CellType type, int order, NodeConvention convention) {
  const std::vector<LatticePoint> gmsh = latticeOrder(type, order, NodeConvention::Gmsh);
  const std::vector<LatticePoint> other = latticeOrder(type, order, convention);
  std::map<LatticePoint, int> gmshIndex;
  for (int i = 0; i < static_cast<int>(gmsh.size()); ++i) gmshIndex[gmsh[i]] = i;
  if (gmshIndex.size() != gmsh.size())
    throw Error("node ordering of " + cellShortName(type) + " repeats a lattice point");
  std::vector<int> perm;
  perm.reserve(other.size());
  for (const LatticePoint& c : other) perm.push_back(gmshIndex.at(c));
  return perm;
}

std::vector<int> mirrorPermutation(CellType type, int order) {
  const std::vector<LatticePoint> gmsh = latticeOrder(type, order, NodeConvention::Gmsh);
  std::map<LatticePoint, int> index;
  for (int i = 0; i < static_cast<int>(gmsh.size()); ++i) index[gmsh[i]] = i;
  std::vector<int> perm;
  perm.reserve(gmsh.size());
  for (const LatticePoint& c : gmsh) {
    const LatticePoint m =
        type == CellType::Line ? LatticePoint{order - c[0], 0, 0} : LatticePoint{c[1], c[0], c[2]};
    perm.push_back(index.at(m));
  }
  return perm;
}

std::array<int, 4> simplexBarycentric(const LatticePoint& c, int dim, int order) {
  std::array<int, 4> a{0, 0, 0, 0};
  a[0] = order;
  for (int k = 0; k < dim; ++k) {
    a[k + 1] = c[k];
    a[0] -= c[k];
  }
  return a;
}

}  // namespace homesh

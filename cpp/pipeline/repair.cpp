#include "pipeline/repair.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>
#include <limits>
#include <map>
#include <optional>
#include <utility>

#include "core/error.hpp"

namespace homesh {
namespace {

// The linear cells of dimension mesh.dim, in element order.
std::vector<const std::int64_t*> cellsOf(const Mesh& mesh) {
  std::vector<const std::int64_t*> cells;
  for (const ElementBlock& block : mesh.blocks) {
    if (cellDimension(block.type) != mesh.dim) continue;
    if (block.order != 1 || cellNumVertices(block.type) != mesh.dim + 1)
      throw ParameterError("repair needs a linear simplex mesh, got " + cellShortName(block.type) +
                           "s of order " + std::to_string(block.order));
    for (std::size_t e = 0; e < block.count(); ++e) cells.push_back(block.element(e));
  }
  return cells;
}

// The point of CAD face (3D) or curve (2D) `entity` nearest to x, and the unit normal there (the
// face's du x dv; for a curve, the plane normal x tangent).
std::pair<Eigen::Vector3d, Eigen::Vector3d> footAndNormal(const Mesh& mesh, const CadModel& cad,
                                                          int entity, const Eigen::Vector3d& x) {
  if (mesh.dim == 3) {
    const SurfaceProjection proj = cad.projectOnSurface(entity, x);
    const SurfaceDerivatives d = cad.evaluateSurface(entity, proj.u, proj.v);
    const Eigen::Vector3d n = d.du.cross(d.dv);
    const double norm = n.norm();
    return {proj.point, norm > 0.0 ? Eigen::Vector3d(n / norm) : Eigen::Vector3d::Zero()};
  }
  const CurveProjection proj = cad.projectOnCurve(entity, x);
  const CurveDerivatives d = cad.evaluateCurve(entity, proj.t);
  const Eigen::Vector3d plane(mesh.planeNormal[0], mesh.planeNormal[1], mesh.planeNormal[2]);
  const Eigen::Vector3d n = plane.cross(d.d1);
  const double norm = n.norm();
  return {proj.point, norm > 0.0 ? Eigen::Vector3d(n / norm) : Eigen::Vector3d::Zero()};
}

// Signed distance of x to the face along its normal at x's foot point.
double signedDistance(const Mesh& mesh, const CadModel& cad, int entity, const Eigen::Vector3d& x) {
  const auto [foot, normal] = footAndNormal(mesh, cad, entity, x);
  return (x - foot).dot(normal);
}

// Where the new node of a split goes (see applySplits in repair.hpp): the midpoint, or its
// mirror image in the face when the cells around the edge lie on the other side.
Eigen::Vector3d splitPoint(const Mesh& mesh, const CadModel& cad, const CurvedFaceEdge& split) {
  const Eigen::Vector3d a = nodePoint(mesh, split.edge[0]), b = nodePoint(mesh, split.edge[1]);
  Eigen::Vector3d mid = 0.5 * (a + b);  // not const: returned by move
  const auto [foot, normal] = footAndNormal(mesh, cad, split.entity, mid);
  const double depth = (mid - foot).dot(normal);
  if (normal.isZero() || depth == 0.0) return mid;
  // Which side the cells around the edge are on: the vote of their other vertices that are
  // clearly off the face (a fraction of the edge length; vertices on the face say nothing).
  const double clear = 1e-6 * (b - a).norm();
  int side = 0;
  std::vector<std::int64_t> seen;
  for (const ElementBlock& block : mesh.blocks) {
    if (cellDimension(block.type) != mesh.dim) continue;
    const int nv = cellNumVertices(block.type);
    for (std::size_t e = 0; e < block.count(); ++e) {
      const std::int64_t* v = block.element(e);
      if (std::find(v, v + nv, split.edge[0]) == v + nv ||
          std::find(v, v + nv, split.edge[1]) == v + nv)
        continue;
      for (int k = 0; k < nv; ++k) {
        if (v[k] == split.edge[0] || v[k] == split.edge[1]) continue;
        if (std::find(seen.begin(), seen.end(), v[k]) != seen.end()) continue;
        seen.push_back(v[k]);
        const double s = signedDistance(mesh, cad, split.entity, nodePoint(mesh, v[k]));
        if (s > clear) ++side;
        if (s < -clear) --side;
      }
    }
  }
  if (side == 0 || (side > 0) == (depth > 0.0)) return mid;
  return foot - depth * normal;  // the mirror image: as far from the face, on the cells' side
}

// The longest edge of the simplex on `v` (nv vertices) for which `select(edge)` gives a record,
// that record; none if it gives none.
template <class Select>
std::optional<CurvedFaceEdge> longestEdge(const Mesh& mesh, const std::int64_t* v, int nv,
                                          Select select) {
  std::optional<CurvedFaceEdge> found;
  double longest = 0.0;
  for (int i = 0; i < nv; ++i)
    for (int j = i + 1; j < nv; ++j) {
      std::optional<CurvedFaceEdge> candidate = select(meshEdge(v[i], v[j]));
      if (!candidate) continue;
      const double length = (nodePoint(mesh, v[i]) - nodePoint(mesh, v[j])).norm();
      if (length > longest) {
        longest = length;
        found = candidate;
      }
    }
  return found;
}

// A boundary facet's key: its vertices sorted (a line's third -1).
std::array<std::int64_t, 3> facetKey(std::int64_t a, std::int64_t b, std::int64_t c) {
  if (a > b) std::swap(a, b);
  if (c >= 0) {
    if (b > c) std::swap(b, c);
    if (a > b) std::swap(a, b);
  }
  return {a, b, c};
}

}  // namespace

CurvedFaceEdges::CurvedFaceEdges(const Mesh& linear, const CadModel& cad)
    : mesh_(linear),
      nodeFaces_(linear.numNodes()),
      onBoundary_(linear.numNodes(), 0),
      boundary_(boundaryEdges(linear)),
      cells_(cellsOf(linear)) {
  std::map<int, bool> curved;
  std::set<MeshEdge> curveEdges;  // 3D: edges on CAD curves (their nodes would go on the curve)
  for (const ElementBlock& block : linear.blocks)
    if (linear.dim == 3 && block.type == CellType::Line && block.order == 1)
      for (std::size_t e = 0; e < block.count(); ++e)
        curveEdges.insert(meshEdge(block.element(e)[0], block.element(e)[1]));
  for (const ElementBlock& block : linear.blocks) {
    if (cellDimension(block.type) != linear.dim - 1 || block.order != 1) continue;
    const int nv = cellNumVertices(block.type);
    for (std::size_t e = 0; e < block.count(); ++e) {
      for (int k = 0; k < nv; ++k) onBoundary_[static_cast<std::size_t>(block.element(e)[k])] = 1;
      const int entity = block.entity[e];
      if (entity <= 0) continue;
      auto it = curved.find(entity);
      if (it == curved.end())
        it = curved.emplace(entity, linear.dim == 2 || !cad.isPlanar(entity)).first;
      if (!it->second) continue;
      const std::int64_t* v = block.element(e);
      for (int k = 0; k < nv; ++k) {
        std::vector<int>& faces = nodeFaces_[static_cast<std::size_t>(v[k])];
        if (std::find(faces.begin(), faces.end(), entity) == faces.end()) faces.push_back(entity);
        if (nv == 2 && k == 1) break;  // a line has one edge
        const MeshEdge edge = meshEdge(v[k], v[(k + 1) % nv]);
        if (curveEdges.count(edge) == 0) faceEdges_.emplace(edge, entity);
      }
    }
  }
  for (std::vector<int>& faces : nodeFaces_) std::sort(faces.begin(), faces.end());
}

std::vector<CurvedFaceEdge> CurvedFaceEdges::interior(std::size_t cell) const {
  std::vector<CurvedFaceEdge> found;
  const std::int64_t* v = cells_.at(cell);
  const int nv = mesh_.dim + 1;
  for (int i = 0; i < nv; ++i)
    for (int j = i + 1; j < nv; ++j) {
      const MeshEdge edge = meshEdge(v[i], v[j]);
      if (boundary_.count(edge) > 0) continue;
      const std::vector<int>& fa = nodeFaces_[static_cast<std::size_t>(edge[0])];
      const std::vector<int>& fb = nodeFaces_[static_cast<std::size_t>(edge[1])];
      std::vector<int> common;
      std::set_intersection(fa.begin(), fa.end(), fb.begin(), fb.end(), std::back_inserter(common));
      if (!common.empty()) found.push_back({edge, common.front(), false});
    }
  return found;
}

std::optional<CurvedFaceEdge> CurvedFaceEdges::longestOnFace(std::size_t cell) const {
  return longestEdge(mesh_, cells_.at(cell), mesh_.dim + 1,
                     [&](const MeshEdge& edge) -> std::optional<CurvedFaceEdge> {
                       const auto it = faceEdges_.find(edge);
                       if (it == faceEdges_.end()) return std::nullopt;
                       return CurvedFaceEdge{edge, it->second, true};
                     });
}

std::optional<CurvedFaceEdge> CurvedFaceEdges::longestBoundaryChord(std::size_t cell) const {
  const std::int64_t* v = cells_.at(cell);
  const int nv = mesh_.dim + 1;
  for (int i = 0; i < nv; ++i)
    if (onBoundary_[static_cast<std::size_t>(v[i])] == 0) return std::nullopt;
  return longestEdge(mesh_, v, nv, [&](const MeshEdge& edge) -> std::optional<CurvedFaceEdge> {
    if (boundary_.count(edge) > 0) return std::nullopt;
    return CurvedFaceEdge{edge, 0, false};
  });
}

RepairPlan planRepair(const Mesh& linear, const std::vector<Validity>& validity,
                      const CadModel& cad, bool optimised) {
  // Cells of every shape, in element order; splits only in an all-simplex mesh.
  std::vector<const std::int64_t*> cells;
  std::vector<int> vertexCount;
  bool simplex = true;
  for (const ElementBlock& block : linear.blocks) {
    if (cellDimension(block.type) != linear.dim) continue;
    if (block.order != 1)
      throw ParameterError("repair needs a linear mesh, got order " + std::to_string(block.order));
    const int nv = cellNumVertices(block.type);
    simplex = simplex && nv == linear.dim + 1;
    for (std::size_t e = 0; e < block.count(); ++e) {
      cells.push_back(block.element(e));
      vertexCount.push_back(nv);
    }
  }
  if (validity.size() != cells.size())
    throw ParameterError("repair: " + std::to_string(validity.size()) +
                         " verdicts for a linear mesh of " + std::to_string(cells.size()) +
                         " cells");
  // Splits only where their cells' areas can be checked: not in a surface mesh, which has no
  // plane to measure them in (its offenders get refinement spheres).
  std::optional<CurvedFaceEdges> finder;
  if (simplex && !linear.isSurface()) finder.emplace(linear, cad);
  RepairPlan plan;
  std::set<MeshEdge> planned;
  for (std::size_t c = 0; c < cells.size(); ++c) {
    if (validity[c] == Validity::Valid) continue;
    plan.flagged.push_back(c);
    const int nv = vertexCount[c];
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    double longest = 0.0, total = 0.0;
    int edgeCount = 0;
    for (int i = 0; i < nv; ++i) {
      centroid += nodePoint(linear, cells[c][i]) / nv;
      for (int j = i + 1; j < nv; ++j) {
        const double l = (nodePoint(linear, cells[c][i]) - nodePoint(linear, cells[c][j])).norm();
        longest = std::max(longest, l);
        total += l;
        ++edgeCount;
      }
    }
    const RefinementSource sphere =
        RefinementSource::sphere(centroid, longest, 0.5 * total / edgeCount);
    plan.allSources.push_back(sphere);
    std::vector<CurvedFaceEdge> edges;
    if (finder) {
      edges = finder->interior(c);
      // Not in 2D: there a triangle with every vertex on the boundary sits where CAD curves
      // meet, at a cusp or across a narrow gap, and its invalid Jacobian is set by its curved
      // edges at the shared vertex; a chord from that vertex changes nothing there, halving
      // the curved edge halves its sag (gmsh-doc's fragment_numbering.step: valid after 2
      // rounds so, 2 triangles invalid after 8 with the chord).
      if (edges.empty() && optimised && linear.dim == 3)
        if (const auto chord = finder->longestBoundaryChord(c)) edges.push_back(*chord);
      if (edges.empty())
        if (const auto onFace = finder->longestOnFace(c)) edges.push_back(*onFace);
    }
    if (!edges.empty()) {
      ++plan.splitCells;
      for (const CurvedFaceEdge& e : edges)
        if (planned.insert(e.edge).second) plan.splits.push_back(e);
      continue;
    }
    ++plan.refineCells;
    plan.sources.push_back(sphere);
    plan.unsplit.push_back(c);
  }
  return plan;
}

std::vector<CurvedFaceEdge> tangentEarSplits(const Mesh& linear, const CadModel& cad) {
  const int d = linear.dim;
  // (A surface mesh has no plane to check a split's areas in: its rounds refine instead.)
  if (linear.isSurface()) return {};
  for (const ElementBlock& block : linear.blocks)  // simplices only (no layer's prisms)
    if (cellDimension(block.type) == d &&
        (block.order != 1 || cellNumVertices(block.type) != d + 1))
      return {};
  // Boundary facets by their sorted vertices (the third -1 in 2D), with their curved entity.
  std::map<std::array<std::int64_t, 3>, int> facets;
  std::map<int, bool> curved;
  for (const ElementBlock& block : linear.blocks) {
    if (cellDimension(block.type) != d - 1 || block.order != 1 || cellNumVertices(block.type) != d)
      continue;
    for (std::size_t e = 0; e < block.count(); ++e) {
      const int entity = block.entity[e];
      if (entity <= 0) continue;
      auto it = curved.find(entity);
      if (it == curved.end()) it = curved.emplace(entity, d == 2 || !cad.isPlanar(entity)).first;
      if (!it->second) continue;
      const std::int64_t* f = block.element(e);
      facets.emplace(facetKey(f[0], f[1], d == 3 ? f[2] : -1), entity);
    }
  }
  const std::set<MeshEdge> boundary = boundaryEdges(linear);
  std::vector<CurvedFaceEdge> splits;
  std::set<MeshEdge> planned;
  for (const std::int64_t* v : cellsOf(linear)) {
    std::array<int, 4> entity{0, 0, 0, 0};  // of the facet opposite vertex i
    for (int i = 0; i <= d; ++i) {
      std::array<std::int64_t, 3> rest{-1, -1, -1};  // the vertices but i
      for (int k = 0, n = 0; k <= d; ++k)
        if (k != i) rest[static_cast<std::size_t>(n++)] = v[k];
      const auto it = facets.find(facetKey(rest[0], rest[1], rest[2]));
      if (it != facets.end()) entity[static_cast<std::size_t>(i)] = it->second;
    }
    for (int i = 0; i <= d; ++i)
      for (int j = i + 1; j <= d; ++j) {
        const int face = entity[static_cast<std::size_t>(i)];
        if (face == 0 || face != entity[static_cast<std::size_t>(j)]) continue;
        // The facets opposite i and j share every vertex but i and j: the ear's far edge.
        const MeshEdge edge = meshEdge(v[i], v[j]);
        if (boundary.count(edge) == 0 && planned.insert(edge).second)
          splits.push_back({edge, face, false});
      }
  }
  return splits;
}

CuspElements elementsAtCusps(const Mesh& mesh, const QualitySummary& quality,
                             const std::vector<FaceCusp>& cusps) {
  CuspElements out;
  out.perCusp.assign(cusps.size(), 0);
  if (cusps.empty()) return out;
  const auto has = [](const std::vector<int>& list, int x) {
    return std::binary_search(list.begin(), list.end(), x);
  };
  for (const FlaggedElement& f :
       flaggedElements(mesh, quality, quality.invalid + quality.undecided)) {
    bool any = false;
    for (std::size_t c = 0; c < cusps.size(); ++c) {
      const FaceCusp& cusp = cusps[c];
      if (!has(f.cadVertices, cusp.vertex)) continue;
      // Nodes on both edges, or on one of them and on the face: the corner itself (not an
      // element on the edge's other face).
      const bool a = has(f.cadCurves, cusp.edgeA), b = has(f.cadCurves, cusp.edgeB);
      if (!(a && b) && !((a || b) && has(f.cadFaces, cusp.face))) continue;
      ++out.perCusp[c];
      any = true;
    }
    if (any) out.elements.push_back(f.index);
  }
  return out;
}

std::vector<double> curvedVertexPositions(const Mesh& linear, const Mesh& curved) {
  std::vector<double> positions = linear.xyz;
  std::size_t count = 0;
  for (const ElementBlock& block : linear.blocks)
    if (cellDimension(block.type) == linear.dim) count += block.count();
  if (count != curved.numElements())
    throw ParameterError("vertex positions: a linear mesh of " + std::to_string(count) +
                         " elements and a curved mesh of " + std::to_string(curved.numElements()));
  auto from = curved.blocks.begin();
  for (const ElementBlock& block : linear.blocks) {
    if (cellDimension(block.type) != linear.dim) continue;
    while (from != curved.blocks.end() && cellDimension(from->type) != curved.dim) ++from;
    if (from == curved.blocks.end() || from->type != block.type || from->count() != block.count())
      throw ParameterError("vertex positions: the linear and curved meshes' blocks differ");
    const int nv = cellNumVertices(block.type);
    for (std::size_t e = 0; e < block.count(); ++e)
      for (int k = 0; k < nv; ++k)
        for (int c = 0; c < 3; ++c)
          positions[3 * static_cast<std::size_t>(block.element(e)[k]) + c] =
              curved.xyz[3 * static_cast<std::size_t>(from->element(e)[k]) + c];
    ++from;
  }
  return positions;
}

std::size_t applySplits(Mesh& linear, const std::vector<CurvedFaceEdge>& splits,
                        const CadModel& cad) {
  std::size_t done = 0;
  for (const CurvedFaceEdge& split : splits) {
    const Eigen::Vector3d mid =
        0.5 * (nodePoint(linear, split.edge[0]) + nodePoint(linear, split.edge[1]));
    if (split.boundary) {
      SplitNode node;
      if (linear.dim == 3) {
        const SurfaceProjection proj = cad.projectOnSurface(split.entity, mid);
        node.point = proj.point;
        node.cadDim = 2;
        node.param0 = proj.u;
        node.param1 = proj.v;
      } else {
        const CurveProjection proj = cad.projectOnCurve(split.entity, mid);
        node.point = proj.point;
        node.cadDim = 1;
        node.param0 = proj.t;
      }
      node.cadIndex = split.entity;
      if (splitEdge(linear, split.edge, node)) ++done;
      continue;
    }
    const Eigen::Vector3d point = split.entity > 0 ? splitPoint(linear, cad, split) : mid;
    // The midpoint always halves positive cells into positive cells.
    if (!splitInteriorEdge(linear, split.edge, point) &&
        !splitInteriorEdge(linear, split.edge, mid))
      throw MeshingError("repair: splitting an edge at its midpoint made a flat cell");
    ++done;
  }
  return done;
}

SizeField cappedSizeField(SizeField base, std::vector<RefinementSource> sources, double growth) {
  return [base = std::move(base), sources = std::move(sources), growth](const Eigen::Vector3d& x) {
    double size = base(x);
    for (const RefinementSource& s : sources)
      size = std::min(size, s.delta + growth * s.distance(x));
    return size;
  };
}

}  // namespace homesh

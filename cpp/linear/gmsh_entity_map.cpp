#include "linear/gmsh_entity_map.hpp"

#include <gmsh.h>

#include <algorithm>
#include <set>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "linear/gmsh_session.hpp"

namespace homesh {
namespace {

using IndexSet = std::set<int>;

std::vector<int> gmshEntities(int dim) {
  gmsh::vectorpair dimTags;
  gmsh::model::getEntities(dimTags, dim);
  std::vector<int> tags;
  for (const auto& dt : dimTags) tags.push_back(dt.second);
  return tags;
}

std::vector<int> gmshBoundaryTags(int dim, int tag) {
  gmsh::vectorpair out;
  gmsh::model::getBoundary({{dim, tag}}, out, false, false, false);
  std::vector<int> tags;
  for (const auto& dt : out) tags.push_back(std::abs(dt.second));
  return tags;
}

Eigen::Vector3d gmshValue(int dim, int tag, const std::vector<double>& param) {
  std::vector<double> xyz;
  gmsh::model::getValue(dim, tag, param, xyz);
  if (xyz.size() < 3)
    throw MeshingError("Gmsh returned no point for entity (" + std::to_string(dim) + ", " +
                       std::to_string(tag) + ")");
  return {xyz[0], xyz[1], xyz[2]};
}

IndexSet cadBoundary(const CadModel& cad, int dim, int index) {
  const std::vector<int> sub = cad.subShapeIndices(dim, index, dim - 1);
  return {sub.begin(), sub.end()};
}

[[noreturn]] void fail(int dim, int tag, const std::string& why) {
  static const char* kinds[] = {"point", "curve", "surface", "volume"};
  throw MeshingError("cannot match Gmsh " + std::string(kinds[dim]) + " " + std::to_string(tag) +
                     " to a CAD entity: " + why);
}

}  // namespace

int GmshEntityMap::cadIndex(int dim, int tag) const {
  const auto it = toCad_.find({dim, tag});
  if (it == toCad_.end())
    throw MeshingError("Gmsh entity (" + std::to_string(dim) + ", " + std::to_string(tag) +
                       ") has no CAD counterpart");
  return it->second;
}

GmshEntityMap GmshEntityMap::build(const CadModel& cad) {
  GmshEntityMap map;
  const double tol = 1e-7 * cad.boundingDiagonal();
  withGmshErrors("matching Gmsh entities to the CAD", [&] {
    // Vertices: by position.
    std::vector<bool> used(cad.numVertices() + 1, false);
    for (const int tag : gmshEntities(0)) {
      const Eigen::Vector3d p = gmshValue(0, tag, {});
      int best = 0;
      double bestDistance = tol;
      for (int v = 1; v <= cad.numVertices(); ++v) {
        const double d = (cad.vertexPoint(v) - p).norm();
        if (!used[v] && d <= bestDistance) {
          best = v;
          bestDistance = d;
        }
      }
      if (best == 0) fail(0, tag, "no unmatched CAD vertex at its position");
      used[best] = true;
      map.toCad_[{0, tag}] = best;
    }

    // Curves: same end vertices and the same point at the mid parameter.
    used.assign(cad.numEdges() + 1, false);
    for (const int tag : gmshEntities(1)) {
      IndexSet ends;
      for (const int b : gmshBoundaryTags(1, tag)) ends.insert(map.cadIndex(0, b));
      std::vector<double> lo, hi;
      gmsh::model::getParametrizationBounds(1, tag, lo, hi);
      const double tm = 0.5 * (lo.at(0) + hi.at(0));
      const Eigen::Vector3d p = gmshValue(1, tag, {tm});
      int match = 0;
      for (int e = 1; e <= cad.numEdges() && match == 0; ++e) {
        if (used[e] || cadBoundary(cad, 1, e) != ends) continue;
        // A degenerated edge (a sphere's pole) is a point: Gmsh evaluates it at its vertex.
        const Eigen::Vector3d q =
            cad.isDegenerated(e) ? cad.vertexPoint(*ends.begin()) : cad.evaluateCurve(e, tm).point;
        if ((q - p).norm() <= tol) match = e;
      }
      if (match == 0)
        fail(1, tag, "no CAD edge with the same vertices passes through its midpoint");
      used[match] = true;
      map.toCad_[{1, tag}] = match;
    }
    for (int e = 1; e <= cad.numEdges(); ++e)
      if (!used[e]) throw MeshingError(cadEntityName(1, e) + " was not imported by Gmsh");

    // Surfaces: same boundary curves and the same point at the parametric centre.
    used.assign(cad.numFaces() + 1, false);
    for (const int tag : gmshEntities(2)) {
      IndexSet curves;
      for (const int b : gmshBoundaryTags(2, tag)) curves.insert(map.cadIndex(1, b));
      std::vector<double> lo, hi;
      gmsh::model::getParametrizationBounds(2, tag, lo, hi);
      const double um = 0.5 * (lo.at(0) + hi.at(0)), vm = 0.5 * (lo.at(1) + hi.at(1));
      const Eigen::Vector3d p = gmshValue(2, tag, {um, vm});
      int match = 0;
      for (int f = 1; f <= cad.numFaces() && match == 0; ++f) {
        if (used[f]) continue;
        if (cadBoundary(cad, 2, f) != curves) continue;
        if ((cad.evaluateSurface(f, um, vm).point - p).norm() <= tol) match = f;
      }
      if (match == 0) fail(2, tag, "no CAD face with the same edges passes through its centre");
      used[match] = true;
      map.toCad_[{2, tag}] = match;
    }
    for (int f = 1; f <= cad.numFaces(); ++f)
      if (!used[f]) throw MeshingError(cadEntityName(2, f) + " was not imported by Gmsh");

    // Volumes: same boundary surfaces.
    used.assign(cad.numSolids() + 1, false);
    for (const int tag : gmshEntities(3)) {
      IndexSet surfaces;
      for (const int b : gmshBoundaryTags(3, tag)) surfaces.insert(map.cadIndex(2, b));
      int match = 0;
      for (int s = 1; s <= cad.numSolids() && match == 0; ++s)
        if (!used[s] && cadBoundary(cad, 3, s) == surfaces) match = s;
      if (match == 0) fail(3, tag, "no CAD solid has the same faces");
      used[match] = true;
      map.toCad_[{3, tag}] = match;
    }
    for (int s = 1; s <= cad.numSolids(); ++s)
      if (!used[s]) throw MeshingError(cadEntityName(3, s) + " was not imported by Gmsh");
  });
  return map;
}

}  // namespace homesh

#include "linear/gmsh_entity_map.hpp"

#include <gmsh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "linear/gmsh_session.hpp"

namespace homesh {
namespace {

struct GmshEntity {
  int dim = 0, tag = 0;
  std::vector<int> boundary;   // tags of dimension dim - 1, unique
  std::vector<double> lo, hi;  // parametrisation bounds (curves and surfaces)
  Eigen::Vector3d probe;       // the point at the parametric centre (a point's position)
};

std::string gmshName(int dim, int tag) {
  static const char* kinds[] = {"point", "curve", "surface", "volume"};
  return std::string("Gmsh ") + kinds[dim] + " " + std::to_string(tag);
}

GmshEntity readGmshEntity(int dim, int tag) {
  GmshEntity g;
  g.dim = dim;
  g.tag = tag;
  if (dim > 0) {
    gmsh::vectorpair out;
    gmsh::model::getBoundary({{dim, tag}}, out, false, false, false);
    for (const auto& dt : out) g.boundary.push_back(std::abs(dt.second));
    std::sort(g.boundary.begin(), g.boundary.end());
    g.boundary.erase(std::unique(g.boundary.begin(), g.boundary.end()), g.boundary.end());
  }
  std::vector<double> centre;
  if (dim == 1 || dim == 2) {
    gmsh::model::getParametrizationBounds(dim, tag, g.lo, g.hi);
    for (std::size_t k = 0; k < g.lo.size(); ++k) centre.push_back(0.5 * (g.lo[k] + g.hi[k]));
  }
  if (dim <= 2) {
    std::vector<double> xyz;
    gmsh::model::getValue(dim, tag, centre, xyz);
    if (xyz.size() < 3) throw MeshingError(gmshName(dim, tag) + " has no point to evaluate");
    g.probe = {xyz[0], xyz[1], xyz[2]};
  }
  return g;
}

class Matcher {
 public:
  explicit Matcher(const CadModel& cad) : cad_(cad), tol_(1e-7 * cad.boundingDiagonal()) {
    const int counts[4] = {cad.numVertices(), cad.numEdges(), cad.numFaces(), cad.numSolids()};
    for (int dim = 0; dim <= 3; ++dim) {
      gmsh::vectorpair dimTags;
      gmsh::model::getEntities(dimTags, dim);
      for (const auto& dt : dimTags) entities_[dim].push_back(readGmshEntity(dim, dt.second));
      used_[dim].assign(counts[dim] + 1, false);
    }
  }

  std::map<std::pair<int, int>, int> run() {
    for (const GmshEntity& volume : entities_[3]) matchFree(volume);
    for (int dim = 2; dim >= 0; --dim) {
      for (const GmshEntity& parent : entities_[dim + 1]) {
        const int cadParent = map_.at({dim + 1, parent.tag});
        const std::vector<int> cadChildren = cad_.subShapeIndices(dim + 1, cadParent, dim);
        for (const int child : parent.boundary) matchWithin(entity(dim, child), cadChildren);
      }
      for (const GmshEntity& g : entities_[dim])
        if (map_.count({dim, g.tag}) == 0) matchFree(g);
    }
    for (int dim = 0; dim <= 3; ++dim)
      for (std::size_t c = 1; c < used_[dim].size(); ++c)
        if (!used_[dim][c])
          throw MeshingError(cadEntityName(dim, static_cast<int>(c)) +
                             " has no counterpart in the model Gmsh imported");
    return map_;
  }

 private:
  const GmshEntity& entity(int dim, int tag) const {
    for (const GmshEntity& g : entities_[dim])
      if (g.tag == tag) return g;
    throw MeshingError(gmshName(dim, tag) + " is not in the Gmsh model");
  }

  // How well CAD entity c fits Gmsh entity g: nullopt if the geometry differs, else a mismatch
  // of parameter ranges (0 for a perfect fit), to choose between pieces of one curve/surface.
  std::optional<double> score(const GmshEntity& g, int c) const {
    switch (g.dim) {
      case 0: {
        const double d = (cad_.vertexPoint(c) - g.probe).norm();
        return d <= tol_ ? std::optional<double>(d) : std::nullopt;
      }
      case 1: {
        if (cad_.isDegenerated(c)) {
          // Gmsh evaluates the face along the edge's curve on it, which may miss the vertex by
          // up to the tolerance the CAD gives the vertex (OpenCASCADE's shell1.brep: 7e-6 on
          // a model 83 across, where tol_ is 8.3e-6 and the vertex's tolerance 3.2e-5). Only
          // for a Gmsh curve that is itself closed on one point, so that a short edge between
          // two vertices there never takes the degenerated one's place.
          const std::vector<int> v = cad_.subShapeIndices(1, c, 0);
          const double within = g.boundary.size() <= 1 && !v.empty()
                                    ? std::max(tol_, 2.0 * cad_.tolerance(0, v[0]))
                                    : tol_;
          if (v.empty() || (cad_.vertexPoint(v[0]) - g.probe).norm() > within) return std::nullopt;
          return 0.0;
        }
        const double tm = 0.5 * (g.lo.at(0) + g.hi.at(0));
        if ((cad_.evaluateCurve(c, tm).point - g.probe).norm() > tol_) return std::nullopt;
        const ParameterRange r = cad_.edgeRange(c);
        return std::abs(r.first - g.lo[0]) + std::abs(r.last - g.hi[0]);
      }
      case 2: {
        const double um = 0.5 * (g.lo.at(0) + g.hi.at(0)), vm = 0.5 * (g.lo.at(1) + g.hi.at(1));
        if ((cad_.evaluateSurface(c, um, vm).point - g.probe).norm() > tol_) return std::nullopt;
        const SurfaceBounds b = cad_.faceBounds(c);
        return std::abs(b.uMin - g.lo[0]) + std::abs(b.uMax - g.hi[0]) +
               std::abs(b.vMin - g.lo[1]) + std::abs(b.vMax - g.hi[1]);
      }
      default: {  // a solid fits if each Gmsh boundary surface fits one of its faces
        const std::vector<int> faces = cad_.subShapeIndices(3, c, 2);
        if (faces.size() != g.boundary.size()) return std::nullopt;
        double total = 0.0;
        for (const int tag : g.boundary) {
          const GmshEntity& surface = entity(2, tag);
          double bestFace = std::numeric_limits<double>::infinity();
          for (const int f : faces)
            if (const auto s = score(surface, f)) bestFace = std::min(bestFace, *s);
          if (!std::isfinite(bestFace)) return std::nullopt;
          total += bestFace;
        }
        return total;
      }
    }
  }

  int best(const GmshEntity& g, const std::vector<int>& candidates) const {
    int chosen = 0;
    double chosenScore = std::numeric_limits<double>::infinity();
    for (const int c : candidates) {
      if (used_[g.dim][c]) continue;
      if (const auto s = score(g, c); s && *s < chosenScore) {
        chosen = c;
        chosenScore = *s;
      }
    }
    return chosen;
  }

  void assign(const GmshEntity& g, int c) {
    map_[{g.dim, g.tag}] = c;
    used_[g.dim][c] = true;
  }

  void matchFree(const GmshEntity& g) {
    std::vector<int> all(used_[g.dim].size() - 1);
    for (std::size_t c = 0; c < all.size(); ++c) all[c] = static_cast<int>(c) + 1;
    const int c = best(g, all);
    if (c == 0)
      throw MeshingError("cannot match " + gmshName(g.dim, g.tag) +
                         " to a CAD entity: no unmatched one has its geometry");
    assign(g, c);
  }

  // Matches g among the CAD boundary entities of its parent's counterpart, or checks that an
  // earlier match (through another parent sharing it) is one of them.
  void matchWithin(const GmshEntity& g, const std::vector<int>& candidates) {
    if (const auto it = map_.find({g.dim, g.tag}); it != map_.end()) {
      if (std::find(candidates.begin(), candidates.end(), it->second) == candidates.end())
        throw MeshingError(gmshName(g.dim, g.tag) + " was matched to " +
                           cadEntityName(g.dim, it->second) +
                           ", which does not bound the CAD entity of another of its parents");
      return;
    }
    const int c = best(g, candidates);
    if (c == 0)
      throw MeshingError("cannot match " + gmshName(g.dim, g.tag) +
                         " to a CAD entity bounding its parent's counterpart");
    assign(g, c);
  }

  const CadModel& cad_;
  double tol_;
  std::array<std::vector<GmshEntity>, 4> entities_;
  std::array<std::vector<bool>, 4> used_;
  std::map<std::pair<int, int>, int> map_;
};

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
  withGmshErrors("matching Gmsh entities to the CAD", [&] { map.toCad_ = Matcher(cad).run(); });
  return map;
}

}  // namespace homesh

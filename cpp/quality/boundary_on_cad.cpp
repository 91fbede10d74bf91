#include "quality/boundary_on_cad.hpp"

#include <Eigen/Core>
#include <algorithm>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "cad/point_classifier.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "core/parameters.hpp"

namespace homesh {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

Eigen::Vector3d pointOf(const Mesh& mesh, std::int64_t i) {
  return Eigen::Vector3d::Map(&mesh.xyz[3 * static_cast<std::size_t>(i)]);
}

// Whether a block's cells are boundary cells the geometry measure samples (as it selects them):
// faces of a volume or a surface mesh's cells (on CAD faces), lines (on CAD curves).
bool onCad(const Mesh& mesh, const ElementBlock& block) {
  const int d = cellDimension(block.type);
  return d == 1 || (d == 2 && (mesh.dim == 3 || mesh.isSurface()));
}

class Attacher {
 public:
  Attacher(Mesh& mesh, const CadModel& cad, double tolerance)
      : mesh_(mesh),
        cad_(cad),
        classifier_(cad, tolerance),
        places_(mesh.numNodes()),
        placed_(mesh.numNodes(), 0) {}

  // Puts every cell of `block` on its CAD entity.
  void attach(ElementBlock& block, BoundaryOnCadStats& stats) {
    const int entityDim = cellDimension(block.type);
    const int corners = cellNumVertices(block.type), n = block.nodesPerElement();
    std::vector<std::pair<int, int>> places;
    for (std::size_t e = 0; e < block.count(); ++e) {
      const std::int64_t* nodes = block.element(e);
      places.clear();
      for (int k = 0; k < corners; ++k) {
        const CadPlace& p = cornerPlace(nodes[k]);
        places.emplace_back(p.dim, p.index);
        stats.maxCornerDistance = std::max(stats.maxCornerDistance, p.distance);
      }
      Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
      for (int k = 0; k < n; ++k) centroid += pointOf(mesh_, nodes[k]);
      centroid /= n;
      const int entity =
          entityDim == 2 ? classifier_.sharedFace(places, centroid)
                         : classifier_.sharedEdge(places[0], places[1], pointOf(mesh_, nodes[0]),
                                                  pointOf(mesh_, nodes[1]));
      if (entity == 0) throw offEntities(block, e, places, centroid);
      block.entity[e] = entity;
      ++(entityDim == 2 ? stats.faceCells : stats.curveCells);
      for (int k = corners; k < n; ++k) placeOnEntity(nodes[k], entityDim, entity, nodes, corners);
    }
  }

 private:
  // Where corner `i` lies (classified once); throws when on nothing.
  const CadPlace& cornerPlace(std::int64_t i) {
    CadPlace& place = places_[static_cast<std::size_t>(i)];
    if (place.dim >= 0) return place;
    const Eigen::Vector3d p = pointOf(mesh_, i);
    std::pair<int, double> nearest{0, 0.0};
    place = classifier_.classify(p, nearest);
    if (place.dim < 0)
      throw MeshingError("boundary node " + std::to_string(i + 1) + " at " + describePoint(p) +
                         " lies on no face of " + cad_.sourceName() +
                         (nearest.first > 0
                              ? " (nearest: " + cadEntityName(2, nearest.first) + " at distance " +
                                    formatNumber(nearest.second) + ")"
                              : "") +
                         ": is the mesh of this shape?");
    record(i, place.dim, place.index, place.u, place.v);
    return place;
  }

  // A non-corner node of a cell on entity (dim, index): on it, with its parameters projected
  // from the parameters of the cell's corners (a guess), unless it was already placed on an
  // entity of dimension at most `dim` (a node on the side two cells share).
  void placeOnEntity(std::int64_t i, int dim, int index, const std::int64_t* cell, int corners) {
    const auto s = static_cast<std::size_t>(i);
    if (placed_[s] != 0 && mesh_.nodeCadDim[s] <= dim) return;
    const Eigen::Vector3d p = pointOf(mesh_, i);
    if (dim == 2) {
      const SurfaceProjection proj =
          cad_.projectOnSurface(index, p, faceGuess(index, cell, corners));
      record(i, 2, index, proj.u, proj.v);
    } else {
      const CurveProjection proj = cad_.projectOnCurve(index, p, curveGuess(index, cell, corners));
      record(i, 1, index, proj.t, kNaN);
    }
  }

  std::optional<std::array<double, 2>> faceGuess(int face, const std::int64_t* cell,
                                                 int corners) const {
    for (int k = 0; k < corners; ++k) {
      const CadPlace& c = places_[static_cast<std::size_t>(cell[k])];
      if (c.dim == 2 && c.index == face) return std::array<double, 2>{c.u, c.v};
    }
    return std::nullopt;
  }

  std::optional<double> curveGuess(int edge, const std::int64_t* cell, int corners) const {
    for (int k = 0; k < corners; ++k) {
      const CadPlace& c = places_[static_cast<std::size_t>(cell[k])];
      if (c.dim == 1 && c.index == edge) return c.u;
    }
    return std::nullopt;
  }

  void record(std::int64_t i, int dim, int index, double a, double b) {
    const auto s = static_cast<std::size_t>(i);
    placed_[s] = 1;
    mesh_.nodeCadDim[s] = static_cast<std::uint8_t>(dim);
    mesh_.nodeCadIndex[s] = index;
    mesh_.nodeCadParam[2 * s] = a;
    mesh_.nodeCadParam[2 * s + 1] = b;
  }

  MeshingError offEntities(const ElementBlock& block, std::size_t e,
                           const std::vector<std::pair<int, int>>& places,
                           const Eigen::Vector3d& centroid) const {
    std::string corners, on;
    for (std::size_t k = 0; k < places.size(); ++k) {
      corners += (k == 0 ? "" : ", ") + std::to_string(block.element(e)[k] + 1);
      on += (k == 0 ? "" : ", ") + cadEntityName(places[k].first, places[k].second);
    }
    const bool face = cellDimension(block.type) == 2;
    return MeshingError{"the boundary " + cellShortName(block.type) + " " + std::to_string(e + 1) +
                        " of its block (corner nodes " + corners + ") near " +
                        describePoint(centroid) + " lies on no single " +
                        (face ? "face" : "curve") + " of " + cad_.sourceName() +
                        ": its corners lie on " + on + "; is the mesh of this shape?"};
  }

  Mesh& mesh_;
  const CadModel& cad_;
  CadPointClassifier classifier_;
  std::vector<CadPlace> places_;  // corners' places (dim -1: not classified yet)
  std::vector<char> placed_;      // nodes whose CAD record this attachment wrote
};

}  // namespace

Mesh boundaryOnCad(const Mesh& mesh, const CadModel& cad, double tolerance,
                   BoundaryOnCadStats* stats) {
  if (!(tolerance > 0.0))
    tolerance = parameterDefault("classify_tolerance") * cad.boundingDiagonal();
  Mesh out = mesh;
  const std::size_t n = out.numNodes();
  out.nodeCadDim.assign(n, static_cast<std::uint8_t>(out.dim));
  out.nodeCadIndex.assign(n, 0);
  out.nodeCadParam.assign(2 * n, kNaN);
  bool any = false;
  for (const ElementBlock& b : out.blocks) any = any || (onCad(out, b) && b.count() > 0);
  if (!any)
    throw ParameterError(
        std::string("the mesh has no boundary cells to measure against the CAD (") +
        (out.dim == 3 || out.isSurface() ? "triangles or quadrilaterals on its boundary"
                                         : "lines on its boundary") +
        "): write them with the elements (Gmsh: Mesh.SaveAll = 1 or physical groups of the "
        "boundary; NekMesh and HOMesh write them)");
  Attacher attacher(out, cad, tolerance);
  BoundaryOnCadStats s;
  for (ElementBlock& b : out.blocks)
    if (onCad(out, b)) attacher.attach(b, s);
  if (stats != nullptr) *stats = s;
  return out;
}

}  // namespace homesh

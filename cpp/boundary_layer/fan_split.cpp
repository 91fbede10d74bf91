#include <Eigen/Core>
#include <Eigen/LU>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <map>
#include <vector>

#include "boundary_layer/layer_splitter.hpp"
#include "core/error.hpp"

namespace homesh::layer_splitting {
namespace {

// The reference triangle's corner k: (0, 0), (1, 0), (0, 1).
Eigen::Vector2d referenceCorner(std::size_t k) {
  return k == 0 ? Eigen::Vector2d(0, 0) : k == 1 ? Eigen::Vector2d(1, 0) : Eigen::Vector2d(0, 1);
}

// A layer cell beside the fan may have shifted its column's nodes (Column::shift): the fan's own
// nodes follow, the shift interpolated across the sector at the same level (reference point xi).
Eigen::Vector3d sectorShift(const FanSector& s, const Eigen::Vector2d& xi) {
  const Eigen::Vector2d rb = referenceCorner(s.b) - referenceCorner(s.a),
                        rd = referenceCorner(s.d) - referenceCorner(s.a);
  Eigen::Matrix2d frame;
  frame << rb, rd;
  const Eigen::Vector2d m = frame.fullPivLu().solve(xi - referenceCorner(s.a));  // weights of B, D
  const double level = m[0] + m[1];
  if (!(level > 0.0)) return Eigen::Vector3d(Eigen::Vector3d::Zero());
  const double d = m[1] / level;
  return Eigen::Vector3d((1.0 - d) * s.colB->shiftAt(level) * s.colB->shift +
                         d * s.colD->shiftAt(level) * s.colD->shift);
}

// The sector's pieces, on its columns' levels: the first layer (C, B_1, D_1), then per band
// between levels k and k + 1 the triangles (B_k, B_k+1, D_k+1) and (B_k, D_k+1, D_k).
std::vector<SectorPiece> sectorPieces(const FanSector& s, int layers, int order) {
  const auto onColumn = [&](bool d, int k) {
    const auto kk = static_cast<std::size_t>(k);
    const double level = (d ? s.colD : s.colB)->levels[kk];
    const Eigen::Vector2d apex = referenceCorner(s.a);
    const Eigen::Vector2d end = referenceCorner(d ? s.d : s.b);
    return SectorPoint{apex + level * (end - apex), d ? order : 0, k * order};
  };
  std::vector<SectorPiece> pieces;
  pieces.push_back(
      {SectorPoint{referenceCorner(s.a), -1, 0}, onColumn(false, 1), onColumn(true, 1)});
  for (int k = 1; k < layers; ++k) {
    pieces.push_back({onColumn(false, k), onColumn(false, k + 1), onColumn(true, k + 1)});
    pieces.push_back({onColumn(false, k), onColumn(true, k + 1), onColumn(true, k)});
  }
  return pieces;
}

}  // namespace

int LayerSplitter::fanApex(const std::int64_t* v) const {
  for (int k = 0; k < 3; ++k)
    if (wallVertices_.count(v[k]) != 0) return k;
  throw MeshingError("boundary-layer split: a fan triangle has no vertex on the wall");
}

ElementBlock LayerSplitter::splitFans(const ElementBlock& b, const std::vector<char>& fan) {
  const ReferenceElement& ref = ReferenceElement::get(CellType::Triangle, p_);
  const std::map<LatticePoint, int> index = latticeIndex(ref);
  const int nn = ref.numNodes();
  ElementBlock out;
  out.type = CellType::Triangle;
  out.order = p_;
  Eigen::MatrixXd points(nn, 2);
  for (std::size_t e = 0; e < b.count(); ++e) {
    const std::int64_t* v = b.element(e);
    if (fan[e] == 0) {
      out.nodes.insert(out.nodes.end(), v, v + nn);
      out.entity.push_back(b.entity[e]);
      continue;
    }
    ++stats_.fanTriangles;
    const FanSector sector = fanSector(v, b.entity[e]);
    for (const SectorPiece& piece : sectorPieces(sector, n_, p_)) {
      for (int r = 0; r < nn; ++r) {
        const LatticePoint& c = ref.lattice()[static_cast<std::size_t>(r)];
        const double w[3] = {double(p_ - c[0] - c[1]) / p_, double(c[0]) / p_, double(c[1]) / p_};
        points.row(r) = (w[0] * piece[0].xi + w[1] * piece[1].xi + w[2] * piece[2].xi).transpose();
      }
      const Eigen::MatrixXd values = ref.valuesAt(points);
      for (int r = 0; r < nn; ++r)
        out.nodes.push_back(fanNode(sector, piece, r, ref.lattice()[static_cast<std::size_t>(r)],
                                    index, values, points));
      out.entity.push_back(b.entity[e]);
    }
  }
  return out;
}

FanSector LayerSplitter::fanSector(const std::int64_t* v, int entity) {
  FanSector s;
  s.v = v;
  const int a = fanApex(v);
  s.a = static_cast<std::size_t>(a);
  s.b = static_cast<std::size_t>((a + 1) % 3);
  s.d = static_cast<std::size_t>((a + 2) % 3);
  s.colB = &fanColumn(v[a], v[s.b]);
  s.colD = &fanColumn(v[a], v[s.d]);
  const int nn = ReferenceElement::get(CellType::Triangle, p_).numNodes();
  s.x.resize(nn, 3);
  for (int i = 0; i < nn; ++i)
    for (int d = 0; d < 3; ++d) s.x(i, d) = macro_.xyz[3 * v[i] + d];
  s.entity = entity;
  return s;
}

std::int64_t LayerSplitter::fanNode(const FanSector& s, const SectorPiece& piece, int r,
                                    const LatticePoint& c, const std::map<LatticePoint, int>& index,
                                    const Eigen::MatrixXd& values, const Eigen::MatrixXd& points) {
  const int w[3] = {p_ - c[0] - c[1], c[0], c[1]};
  // The corner's own weight makes sigma undefined only at the corner itself; elsewhere in the
  // first layer sigma follows from the two other vertices.
  int sigma = 0, level = 0, apexWeight = 0;
  for (std::size_t i = 0; i < 3; ++i) {
    if (piece[i].sigma < 0) {
      apexWeight = w[i];
      continue;
    }
    sigma += w[i] * piece[i].sigma;
    level += w[i] * piece[i].level;
  }
  if (apexWeight == p_) return s.v[s.a];
  if (level == n_ * p_ * p_) {  // the macro triangle's top edge
    const std::array<LatticePoint, 3> corner{LatticePoint{0, 0, 0}, LatticePoint{p_, 0, 0},
                                             LatticePoint{0, p_, 0}};
    const int along = sigma / p_;
    LatticePoint m{0, 0, 0};
    for (std::size_t i = 0; i < 3; ++i)
      m[i] = ((p_ - along) * corner[s.b][i] + along * corner[s.d][i]) / p_;
    return s.v[index.at(m)];
  }
  // In the first layer a node with the corner's weight lies on a column only when one of the
  // others has none; elsewhere it is the piece's own.
  const std::int64_t tb = s.v[s.b], td = s.v[s.d];
  NodeKey key{};
  if (apexWeight > 0 && w[1] > 0 && w[2] > 0) {
    key = makeKey({{{tb, w[1]}, {td, w[2]}, {s.v[s.a], apexWeight}, {kNone, 0}}}, -1);
  } else {
    const int sg = apexWeight > 0 ? (w[2] > 0 ? p_ : 0) : sigma / p_;
    key = makeKey({{{tb, p_ - sg}, {td, sg}, {kNone, 0}, {kNone, 0}}}, level / p_);
  }
  const auto it = nodes_.find(key);
  if (it != nodes_.end()) return it->second;
  const Eigen::RowVector3d pt =
      values.row(r) * s.x + sectorShift(s, points.row(r).transpose()).transpose();
  const double xyz[3] = {pt(0), pt(1), pt(2)};
  const std::int64_t id = out_.addNode(xyz, macro_.dim, s.entity, std::nan(""), std::nan(""));
  nodes_.emplace(key, id);
  return id;
}

}  // namespace homesh::layer_splitting

#include "curving/layer_split.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>

#include "core/error.hpp"
#include "curving/curve_node_placement.hpp"
#include "element/quadrature.hpp"
#include "element/reference_element.hpp"

namespace homesh {

bool isLayerCell(const Mesh& mesh, const ElementBlock& block) {
  return (block.type == CellType::Prism && mesh.dim == 3) ||
         (block.type == CellType::Quadrilateral && mesh.dim == 2);
}

namespace {

// Whether layer fans can be in the block: 2D triangles.
bool mayHoldFans(const Mesh& mesh, const ElementBlock& block) {
  return mesh.dim == 2 && block.type == CellType::Triangle;
}

// The wall vertices of a 2D mesh's layer quadrilaterals (0 and 1 of each).
std::set<std::int64_t> layerWall(const Mesh& mesh) {
  std::set<std::int64_t> wall;
  for (const ElementBlock& b : mesh.blocks)
    if (isLayerCell(mesh, b) && b.type == CellType::Quadrilateral)
      for (std::size_t e = 0; e < b.count(); ++e) wall.insert({b.element(e)[0], b.element(e)[1]});
  return wall;
}

std::vector<char> fanTriangles(const ElementBlock& block, const std::set<std::int64_t>& wall) {
  std::vector<char> fan(block.count(), 0);
  if (wall.empty()) return fan;
  for (std::size_t e = 0; e < block.count(); ++e)
    for (int k = 0; k < 3; ++k)
      if (wall.count(block.element(e)[k]) != 0) fan[e] = 1;
  return fan;
}

}  // namespace

std::vector<char> layerFanTriangles(const Mesh& mesh, const ElementBlock& block) {
  if (mayHoldFans(mesh, block)) return fanTriangles(block, layerWall(mesh));
  std::vector<char> none(block.count(), 0);  // (a braced list would hold two chars)
  return none;
}

namespace {

constexpr std::int64_t kNone = std::numeric_limits<std::int64_t>::max();

// A wall node is at a sharp corner when the mean of its cells' unit wall normals is shorter than
// this (cos 15 degrees: the normals spread by more than about 30 degrees).
constexpr double kCornerMeanNormal = 0.966;

// A node of the split layer: up to three columns (named by their macro top vertices, one per
// column even where a fan's columns share a wall vertex) with integer weights (summing to the
// order P) and the level across the layer, 0 (wall) .. n P (top).
using NodeKey = std::array<std::int64_t, 7>;

NodeKey makeKey(std::array<std::pair<std::int64_t, int>, 3> w, std::int64_t level) {
  for (auto& [id, weight] : w)
    if (weight == 0) id = kNone;
  std::sort(w.begin(), w.end());
  NodeKey k{};
  for (std::size_t i = 0; i < 3; ++i) {
    k[2 * i] = w[i].first;
    k[2 * i + 1] = w[i].first == kNone ? 0 : w[i].second;
  }
  k[6] = level;
  return k;
}

std::map<LatticePoint, int> latticeIndex(const ReferenceElement& ref) {
  std::map<LatticePoint, int> index;
  for (int r = 0; r < ref.numNodes(); ++r) index[ref.lattice()[static_cast<std::size_t>(r)]] = r;
  return index;
}

// The unit normal of a layer cell's curved wall (a prism's triangle at zeta 0; in 2D a
// quadrilateral's edge, in the plane) at wall coordinates (a, b), on the side of `towards`.
Eigen::Vector3d wallNormal(const Mesh& mesh, const ReferenceElement& ref, const std::int64_t* v,
                           double a, double b, const Eigen::Vector3d& towards) {
  const bool prism = ref.type() == CellType::Prism;
  const double xi[3] = {a, prism ? b : 0.0, 0.0};
  Eigen::VectorXd values;
  Eigen::MatrixXd gradients;
  ref.evaluate(xi, values, gradients);
  Eigen::Vector3d du = Eigen::Vector3d::Zero(), dv = Eigen::Vector3d::Zero();
  for (int i = 0; i < ref.numNodes(); ++i) {
    const Eigen::Vector3d x(&mesh.xyz[3 * static_cast<std::size_t>(v[i])]);
    du += gradients(i, 0) * x;
    if (prism) dv += gradients(i, 1) * x;
  }
  const Eigen::Vector3d plane(mesh.planeNormal[0], mesh.planeNormal[1], mesh.planeNormal[2]);
  Eigen::Vector3d n = prism ? du.cross(dv) : plane.cross(du);
  if (!(n.norm() > 0.0)) return Eigen::Vector3d::Zero();
  n.normalize();
  return n.dot(towards) < 0.0 ? Eigen::Vector3d(-n) : n;
}

// The unit normal of CAD curve `curve` in the mesh's plane at mesh node `node` (on the curve,
// or one of its vertices: the end nearer parameter `near`), on the side of `towards`; zero
// where the curve's derivative vanishes or OCCT cannot evaluate it.
Eigen::Vector3d curveNormal(const Mesh& mesh, const CadModel& cad, std::int64_t node, int curve,
                            double near, const Eigen::Vector3d& towards) {
  try {
    const double t = nodeCurveParameter(
        cad, mesh, node, curve, std::isfinite(near) ? std::optional<double>(near) : std::nullopt);
    const Eigen::Vector3d plane(mesh.planeNormal[0], mesh.planeNormal[1], mesh.planeNormal[2]);
    Eigen::Vector3d n = plane.cross(cad.evaluateCurve(curve, t).d1);
    if (!(n.norm() > 0.0)) return Eigen::Vector3d::Zero();
    n.normalize();
    return n.dot(towards) < 0.0 ? Eigen::Vector3d(-n) : n;
  } catch (const Error&) {
    return Eigen::Vector3d::Zero();
  }
}

// The height of the top (reference coordinate zeta = 1) of layer cell `v` above the wall point
// `bottom` (at wall coordinates (a, b)) along the unit wall normal `n` there: the distance to
// where the normal line meets the top, found by Newton's method on the top's offset
// perpendicular to n over the top's reference coordinates (a', b'), started at (a, b). Where
// the columns fan out (a wall curved more tightly than the layer is thick) the top point at
// (a, b) lies well to the side of the normal line, and its component along n understates the
// height. Returns nullopt when the search does not converge inside the cell's own top (the
// normal line leaves it through a neighbour's).
std::optional<double> heightAlongNormal(const Mesh& mesh, const ReferenceElement& ref,
                                        const std::int64_t* v, double a, double b,
                                        const Eigen::Vector3d& bottom, const Eigen::Vector3d& n) {
  const bool prism = ref.type() == CellType::Prism;
  Eigen::Vector3d t1, t2 = Eigen::Vector3d::Zero();
  if (prism) {
    t1 = n.unitOrthogonal();
    t2 = n.cross(t1);
  } else {
    t1 = Eigen::Vector3d(mesh.planeNormal[0], mesh.planeNormal[1], mesh.planeNormal[2]).cross(n);
    if (!(t1.norm() > 0.0)) return std::nullopt;
    t1.normalize();
  }
  Eigen::VectorXd values;
  Eigen::MatrixXd gradients;
  // Newton converges quadratically from a start within the cell; steps of 1e-12 in reference
  // coordinates (of order 1) are far below what the height needs and above rounding.
  constexpr int kIterations = 30;
  constexpr double kStep = 1e-12, kInside = 1e-9;
  for (int it = 0; it < kIterations; ++it) {
    const double xi[3] = {a, prism ? b : 1.0, 1.0};
    ref.evaluate(xi, values, gradients);
    Eigen::Vector3d x = Eigen::Vector3d::Zero(), da = x, db = x;
    for (int i = 0; i < ref.numNodes(); ++i) {
      const Eigen::Vector3d y(&mesh.xyz[3 * static_cast<std::size_t>(v[i])]);
      x += values(i) * y;
      da += gradients(i, 0) * y;
      if (prism) db += gradients(i, 1) * y;
    }
    const Eigen::Vector3d offset = x - bottom;
    Eigen::Vector2d step(0.0, 0.0);
    if (prism) {
      Eigen::Matrix2d jac;
      jac << da.dot(t1), db.dot(t1), da.dot(t2), db.dot(t2);
      step = jac.fullPivLu().solve(-Eigen::Vector2d(offset.dot(t1), offset.dot(t2)));
    } else {
      step[0] = -offset.dot(t1) / da.dot(t1);
    }
    if (!step.allFinite()) return std::nullopt;
    const bool inside = a >= -kInside && a <= 1.0 + kInside &&
                        (!prism || (b >= -kInside && a + b <= 1.0 + kInside));
    if (step.norm() < kStep) return inside ? std::optional<double>(offset.dot(n)) : std::nullopt;
    a += step[0];
    b += step[1];
  }
  return std::nullopt;
}

// Calls visit(wall, top, normal) for every column of nodes of every layer cell of `mesh`: the
// wall node, the top node above it, and the cell's unit wall normal there (towards the top).
template <class Visit>
void forEachColumn(const Mesh& mesh, Visit&& visit) {
  for (const ElementBlock& b : mesh.blocks) {
    if (!isLayerCell(mesh, b)) continue;
    const int p = b.order;
    const bool prism = b.type == CellType::Prism;
    const std::size_t across = prism ? 2 : 1;
    const ReferenceElement& ref = ReferenceElement::get(b.type, p);
    const std::map<LatticePoint, int> index = latticeIndex(ref);
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* v = b.element(e);
      for (int r = 0; r < ref.numNodes(); ++r) {
        LatticePoint c = ref.lattice()[static_cast<std::size_t>(r)];
        if (c[across] != 0) continue;
        c[across] = p;
        const std::int64_t top = v[index.at(c)];
        const Eigen::Vector3d rise = Eigen::Vector3d(&mesh.xyz[3 * static_cast<std::size_t>(top)]) -
                                     Eigen::Vector3d(&mesh.xyz[3 * static_cast<std::size_t>(v[r])]);
        visit(v[r], top,
              wallNormal(mesh, ref, v, double(c[0]) / p, prism ? double(c[1]) / p : 0.0, rise));
      }
    }
  }
}

// The unit normals of the cells meeting at a node, summed.
struct NormalSum {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  void add(const Eigen::Vector3d& n) {
    sum += n;
    ++count;
  }
  // A sharp corner: the normals spread by more than about 30 degrees (their mean is shorter
  // than cos 15 degrees).
  bool sharp() const { return sum.norm() < kCornerMeanNormal * count; }
};

class LayerSplitter {
 public:
  LayerSplitter(const Mesh& macro, const std::vector<double>& z, const CadModel* cad,
                const LayerHeights* heights, LayerSplitStats& stats)
      : macro_(macro),
        z_(z),
        cad_(cad),
        grown_(heights != nullptr ? &heights->grown : nullptr),
        plain_(heights != nullptr ? heights->plain : std::set<std::int64_t>()),
        stats_(stats),
        p_(macro.order),
        n_(static_cast<int>(z.size()) - 1) {
    if (n_ < 1) throw ParameterError("a layer split needs at least one layer");
    out_ = macro;
    out_.blocks.clear();
  }

  Mesh run() {
    if (macro_.dim == 2) wallVertices_ = layerWall(macro_);  // (fans are 2D only)
    for (const ElementBlock& b : macro_.blocks) {
      fans_.push_back(mayHoldFans(macro_, b) ? fanTriangles(b, wallVertices_)
                                             : std::vector<char>());
      const std::vector<char>& fan = fans_.back();
      for (std::size_t e = 0; e < fan.size(); ++e)
        if (fan[e] != 0) fanCorners_.insert(b.element(e)[fanApex(b.element(e))]);
    }
    for (const ElementBlock& b : macro_.blocks)
      if (layerCell(b)) pairWallAndTop(b);
    forEachColumn(macro_, [this](std::int64_t, std::int64_t top, const Eigen::Vector3d& n) {
      normals_[top].add(n);
    });
    // The layer's cells first (they set their columns' levels, which the fans between them
    // share), then the fans; the blocks keep the macro mesh's order.
    std::vector<std::optional<ElementBlock>> split(macro_.blocks.size());
    for (std::size_t i = 0; i < macro_.blocks.size(); ++i)
      if (layerCell(macro_.blocks[i])) split[i] = splitCells(macro_.blocks[i]);
    for (std::size_t i = 0; i < macro_.blocks.size(); ++i) {
      const ElementBlock& b = macro_.blocks[i];
      if (layerCell(b) || b.type == CellType::Quadrilateral || b.type == CellType::Line) continue;
      const std::vector<char>& fan = fans_[i];
      split[i] = std::find(fan.begin(), fan.end(), 1) != fan.end() ? splitFans(b, fan) : b;
    }
    for (std::optional<ElementBlock>& b : split)
      if (b) out_.blocks.push_back(std::move(*b));
    // Faces, then curves: a node on both ends on its curve.
    for (const ElementBlock& b : macro_.blocks)
      if (b.type == CellType::Quadrilateral && !layerCell(b)) out_.blocks.push_back(splitSides(b));
    for (const ElementBlock& b : macro_.blocks)
      if (b.type == CellType::Line) out_.blocks.push_back(splitSides(b));
    compactNodes(out_);
    out_.checkConsistency();
    measureFirstLayer();
    stats_.plainColumns = plain_.size();
    return std::move(out_);
  }

 private:
  const Mesh& macro_;
  const std::vector<double>& z_;
  const CadModel* cad_;
  const std::vector<double>* grown_;  // wall vertex -> height as grown (NaN elsewhere), or null
  std::set<std::int64_t> plain_;      // wall nodes whose columns are split at z as they are
  LayerSplitStats& stats_;
  int p_, n_;
  Mesh out_;
  std::map<std::int64_t, NormalSum> normals_;  // column (top node) -> its cells' wall normals
  // wall vertex -> top vertex, but at a fan's corner (several columns on one wall vertex)
  std::map<std::int64_t, std::int64_t> topOf_;
  std::set<std::int64_t> fanCorners_, wallVertices_;
  std::vector<std::vector<char>> fans_;  // per macro block: its fan flags (empty: none there)
  std::vector<char> cellCorner_;         // per macro layer cell, in split order: at a sharp corner
  std::map<NodeKey, std::int64_t> nodes_;
  std::map<std::int64_t, double> height_;  // wall vertex -> macro layer height there
  std::vector<char> projected_;

  // The macro layer's cells: prisms in 3D (wall 0, 1, 2; tops 3, 4, 5), quadrilaterals in 2D
  // (wall 0, 1; tops 3 above 0 and 2 above 1).
  bool layerCell(const ElementBlock& b) const { return isLayerCell(macro_, b); }
  static int wallVertices(const ElementBlock& b) { return b.type == CellType::Prism ? 3 : 2; }
  static std::int64_t topVertex(const ElementBlock& b, const std::int64_t* v, int k) {
    return b.type == CellType::Prism ? v[k + 3] : v[3 - k];
  }

  void pairWallAndTop(const ElementBlock& b) {
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* v = b.element(e);
      for (int k = 0; k < wallVertices(b); ++k) {
        const std::int64_t top = topVertex(b, v, k);
        height_[v[k]] =
            (Eigen::Vector3d(&macro_.xyz[3 * top]) - Eigen::Vector3d(&macro_.xyz[3 * v[k]])).norm();
        if (fanCorners_.count(v[k]) != 0) continue;
        const auto [it, fresh] = topOf_.emplace(v[k], top);
        if (!fresh && it->second != top)
          throw MeshingError("boundary-layer split: wall node " + std::to_string(v[k]) +
                             " has two top nodes");
      }
    }
  }

  // The vertex of fan triangle v on the wall (the fan's corner).
  int fanApex(const std::int64_t* v) const {
    for (int k = 0; k < 3; ++k)
      if (wallVertices_.count(v[k]) != 0) return k;
    throw MeshingError("boundary-layer split: a fan triangle has no vertex on the wall");
  }

  // Splits the fan triangles of a triangle block (`fan`: layerFanTriangles), keeping the others.
  // Fan triangle (C, B, D) (C its corner on the wall, counter-clockwise) is a sector whose
  // columns C -> B and C -> D are split at their levels s_0 = 0 < ... < s_n = 1: the first
  // layer is the triangle (C, B_1, D_1), each further one the two triangles (B_k, B_k+1, D_k+1)
  // and (B_k, D_k+1, D_k) of the band between levels, every one the macro triangle's own map on
  // a triangle of its reference element (a sub-map: valid where the macro triangle is). A node
  // has integer coordinates (sigma, L) in the sector, sigma 0 .. P from C -> B to C -> D and
  // level L 0 .. n P, which name it (the columns' nodes are the layer cells' beside them).
  ElementBlock splitFans(const ElementBlock& b, const std::vector<char>& fan) {
    const ReferenceElement& ref = ReferenceElement::get(CellType::Triangle, p_);
    const std::map<LatticePoint, int> index = latticeIndex(ref);
    const int nn = ref.numNodes();
    ElementBlock out;
    out.type = CellType::Triangle;
    out.order = p_;
    const std::array<Eigen::Vector2d, 3> corner{Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0),
                                                Eigen::Vector2d(0, 1)};
    const std::array<LatticePoint, 3> cornerLattice{LatticePoint{0, 0, 0}, LatticePoint{p_, 0, 0},
                                                    LatticePoint{0, p_, 0}};
    Eigen::MatrixXd x(nn, 3);
    Eigen::MatrixXd points(nn, 2);
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* v = b.element(e);
      if (fan[e] == 0) {
        out.nodes.insert(out.nodes.end(), v, v + nn);
        out.entity.push_back(b.entity[e]);
        continue;
      }
      ++stats_.fanTriangles;
      const int a = fanApex(v), bi = (a + 1) % 3, di = (a + 2) % 3;
      const auto ua = static_cast<std::size_t>(a), ub = static_cast<std::size_t>(bi),
                 ud = static_cast<std::size_t>(di);
      const std::int64_t tb = v[bi], td = v[di];
      const Column& colB = fanColumn(v[a], tb);
      const Column& colD = fanColumn(v[a], td);
      const std::vector<double>& sb = colB.levels;
      const std::vector<double>& sd = colD.levels;
      // A layer cell beside the fan may have shifted its column's nodes (Column::shift): the
      // fan's own nodes follow, the shift interpolated across the sector at the same level.
      const auto shiftAt = [&](const Eigen::Vector2d& xi) {
        const Eigen::Vector2d rb = corner[ub] - corner[ua], rd = corner[ud] - corner[ua];
        Eigen::Matrix2d frame;
        frame << rb, rd;
        const Eigen::Vector2d m = frame.fullPivLu().solve(xi - corner[ua]);  // weights of B, D
        const double level = m[0] + m[1];
        if (!(level > 0.0)) return Eigen::Vector3d(Eigen::Vector3d::Zero());
        const double d = m[1] / level;
        return Eigen::Vector3d((1.0 - d) * colB.shiftAt(level) * colB.shift +
                               d * colD.shiftAt(level) * colD.shift);
      };
      for (int i = 0; i < nn; ++i)
        for (int d = 0; d < 3; ++d) x(i, d) = macro_.xyz[3 * v[i] + d];
      // A point of the sector: its reference coordinates and its (sigma, L); the corner has
      // sigma -1.
      struct SectorPoint {
        Eigen::Vector2d xi;
        int sigma, level;
      };
      const auto onColumn = [&](bool d, int k) {
        const auto kk = static_cast<std::size_t>(k);
        const double s = (d ? sd : sb)[kk];
        return SectorPoint{corner[ua] + s * ((d ? corner[ud] : corner[ub]) - corner[ua]),
                           d ? p_ : 0, k * p_};
      };
      std::vector<std::array<SectorPoint, 3>> pieces;
      pieces.push_back({SectorPoint{corner[ua], -1, 0}, onColumn(false, 1), onColumn(true, 1)});
      for (int k = 1; k < n_; ++k) {
        pieces.push_back({onColumn(false, k), onColumn(false, k + 1), onColumn(true, k + 1)});
        pieces.push_back({onColumn(false, k), onColumn(true, k + 1), onColumn(true, k)});
      }
      for (const std::array<SectorPoint, 3>& piece : pieces) {
        for (int r = 0; r < nn; ++r) {
          const LatticePoint& c = ref.lattice()[static_cast<std::size_t>(r)];
          const double w[3] = {double(p_ - c[0] - c[1]) / p_, double(c[0]) / p_, double(c[1]) / p_};
          points.row(r) =
              (w[0] * piece[0].xi + w[1] * piece[1].xi + w[2] * piece[2].xi).transpose();
        }
        const Eigen::MatrixXd values = ref.valuesAt(points);
        for (int r = 0; r < nn; ++r) {
          const LatticePoint& c = ref.lattice()[static_cast<std::size_t>(r)];
          const int w[3] = {p_ - c[0] - c[1], c[0], c[1]};
          // The corner's own weight makes sigma undefined only at the corner itself; elsewhere
          // in the first layer sigma follows from the two other vertices.
          int sigma = 0, level = 0, apexWeight = 0;
          for (std::size_t i = 0; i < 3; ++i) {
            if (piece[i].sigma < 0) {
              apexWeight = w[i];
              continue;
            }
            sigma += w[i] * piece[i].sigma;
            level += w[i] * piece[i].level;
          }
          std::int64_t id = 0;
          if (apexWeight == p_) {
            id = v[a];
          } else if (level == n_ * p_ * p_) {  // the macro triangle's top edge
            const int along = sigma / p_;
            LatticePoint m{0, 0, 0};
            for (std::size_t i = 0; i < 3; ++i)
              m[i] = ((p_ - along) * cornerLattice[ub][i] + along * cornerLattice[ud][i]) / p_;
            id = v[index.at(m)];
          } else {
            // In the first layer a node with the corner's weight lies on a column only when
            // one of the others has none; elsewhere it is the piece's own.
            NodeKey key{};
            if (apexWeight > 0 && w[1] > 0 && w[2] > 0) {
              key = makeKey({{{tb, w[1]}, {td, w[2]}, {v[a], apexWeight}}}, -1);
            } else {
              const int sg = apexWeight > 0 ? (w[2] > 0 ? p_ : 0) : sigma / p_;
              key = makeKey({{{tb, p_ - sg}, {td, sg}, {kNone, 0}}}, level / p_);
            }
            const auto it = nodes_.find(key);
            if (it != nodes_.end()) {
              id = it->second;
            } else {
              const Eigen::RowVector3d pt =
                  values.row(r) * x + shiftAt(points.row(r).transpose()).transpose();
              const double xyz[3] = {pt(0), pt(1), pt(2)};
              id = out_.addNode(xyz, macro_.dim, b.entity[e], std::nan(""), std::nan(""));
              nodes_.emplace(key, id);
            }
          }
          out.nodes.push_back(id);
        }
        out.entity.push_back(b.entity[e]);
      }
    }
    return out;
  }

  double zAt(int k, int a) const {
    const auto kk = static_cast<std::size_t>(k);
    return z_[kk] + (z_[kk + 1] - z_[kk]) * a / p_;
  }

  // The height a wall point's layer was grown to: the wall vertices' heights interpolated
  // linearly (barycentric `l`), as blendLayerInteriors places the tops; NaN without them.
  double grownHeight(const std::int64_t* v, int walls, const double* l) const {
    if (grown_ == nullptr) return std::nan("");
    double h = 0.0;
    for (int k = 0; k < walls; ++k) {
      const auto id = static_cast<std::size_t>(v[k]);
      h += l[k] * (id < grown_->size() ? (*grown_)[id] : std::nan(""));
    }
    return h;
  }

  // How the column of nodes above the wall node at lattice point `c` (across coordinate 0) of
  // cell `v` is split: at the levels z_0 = 0 < ... < z_n = 1 of the macro map, then shifted.
  // The column runs straight from wall W to top T (blendLayerInteriors), so a level s lies at
  // the height s H above the wall, H = (T - W) . n along the wall normal n (averaged over the
  // cells at the node). With the grown heights H*, the first level is s_1 = z_1 H* / H, so the
  // first layer has the height asked for even where the optimiser has moved the top; the
  // others keep their progression in what remains. s_1 is kept within [z_1 / 2, 2 z_1] (and
  // below the second level's share) so the levels stay ordered. Where the top has also slid
  // sideways (T - W not along n), the first level's node is moved by `shift` onto the normal
  // through W (its tangential offset, s_1 times that of the top, would otherwise change the
  // height measured between the nodes), the shift fading linearly to 0 at wall and top. A node
  // shared by neighbours takes the column of the first cell that reaches it.
  struct Column {
    std::vector<double> levels;
    Eigen::Vector3d shift = Eigen::Vector3d::Zero();
    double shiftAt(double s) const {
      const double s1 = levels[1];
      return s <= s1 ? s / s1 : levels.size() > 2 ? (1.0 - s) / (1.0 - s1) : 0.0;
    }
  };
  std::map<std::int64_t, Column> columns_;      // column (top node) -> how it is split
  static constexpr double kMaxShiftLean = 1.0;  // tangent of the lean: 45 degrees
  const Column& column(const ElementBlock& b, const std::map<LatticePoint, int>& index,
                       const std::int64_t* v, LatticePoint c) {
    const std::size_t across = b.type == CellType::Prism ? 2 : 1;
    c[across] = 0;
    const std::int64_t w = v[index.at(c)];
    c[across] = p_;
    const std::int64_t topNode = v[index.at(c)];
    const auto found = columns_.find(topNode);
    if (found != columns_.end()) return found->second;
    Column col;
    col.levels = z_;
    const bool prism = b.type == CellType::Prism;
    const double l[3] = {prism ? double(p_ - c[0] - c[1]) / p_ : double(p_ - c[0]) / p_,
                         double(c[0]) / p_, prism ? double(c[1]) / p_ : 0.0};
    const double target = grownHeight(v, wallVertices(b), l);
    const auto normal = normals_.find(topNode);
    if (n_ > 1 && plain_.count(topNode) == 0 && std::isfinite(target) && target > 0.0 &&
        normal != normals_.end() && normal->second.sum.norm() > 0.0) {
      const Eigen::Vector3d x0(&macro_.xyz[3 * static_cast<std::size_t>(w)]);
      const Eigen::Vector3d rise =
          Eigen::Vector3d(&macro_.xyz[3 * static_cast<std::size_t>(topNode)]) - x0;
      const Eigen::Vector3d n = normal->second.sum.normalized();
      const double height = rise.dot(n);
      if (height > 0.0) {
        const double first = setFirstLevel(col, z_[1] * target / height);
        // Only where the column leans by less than kMaxShiftLean: at a sharp corner the column
        // follows the corner's bisector by design, and no shift gives both walls their height.
        // (Where the adjusted column makes a thin cell invalid, the pipeline splits it plain.)
        const Eigen::Vector3d lean = rise - height * n;
        if (lean.norm() < kMaxShiftLean * height) col.shift = -first * lean;
      }
    }
    return columns_.emplace(topNode, std::move(col)).first->second;
  }

  // Sets the column's levels from its first, `wanted` kept within [z_1 / 2, 2 z_1] (and below the
  // second level's share): the others keep their progression in what remains. Returns it.
  double setFirstLevel(Column& col, double wanted) const {
    const double z1 = z_[1];
    const double first = std::clamp(wanted, 0.5 * z1, std::min(2.0 * z1, 0.5 * (z1 + z_[2])));
    for (std::size_t k = 1; k + 1 < col.levels.size(); ++k)
      col.levels[k] = first + (z_[k] - z1) * (1.0 - first) / (1.0 - z1);
    return first;
  }

  // A fan's column from its corner `corner` to `top` (straight, with no wall of its own): a
  // layer cell's where one shares it, else levels that give the first layer its grown height
  // along the column (z unchanged where the column is plain).
  const Column& fanColumn(std::int64_t corner, std::int64_t top) {
    const auto found = columns_.find(top);
    if (found != columns_.end()) return found->second;
    Column col;
    col.levels = z_;
    const auto c = static_cast<std::size_t>(corner);
    const double target = grown_ != nullptr && c < grown_->size() ? (*grown_)[c] : std::nan("");
    const double height = (Eigen::Vector3d(&macro_.xyz[3 * static_cast<std::size_t>(top)]) -
                           Eigen::Vector3d(&macro_.xyz[3 * c]))
                              .norm();
    if (n_ > 1 && plain_.count(top) == 0 && std::isfinite(target) && target > 0.0 && height > 0.0)
      setFirstLevel(col, z_[1] * target / height);
    return columns_.emplace(top, std::move(col)).first->second;
  }

  // Whether the walls of the cells sharing the column below `top` meet at a sharp corner.
  bool atCorner(std::int64_t top) const {
    const auto n = normals_.find(top);
    return n != normals_.end() && n->second.sharp();
  }

  // The first split layer's height along the wall normal at the wall's quadrature points
  // (exact to degree 2P), in stats_: its range and, with grown heights, its worst deviation
  // from z_1 H*.
  void measureFirstLayer() {
    std::size_t cell = 0;  // the macro cell, in split order
    for (const ElementBlock& b : out_.blocks) {
      if (!layerCell(b)) continue;
      const bool prism = b.type == CellType::Prism;
      const ReferenceElement& ref = ReferenceElement::get(b.type, p_);
      const QuadratureRule rule =
          quadratureRule(prism ? CellType::Triangle : CellType::Line, 2 * p_);
      Eigen::VectorXd values;
      Eigen::MatrixXd gradients;
      for (std::size_t e = 0; e < b.count(); e += static_cast<std::size_t>(n_)) {
        const std::int64_t* v = b.element(e);  // the column's first layer
        const bool corner = cellCorner_.at(cell++) != 0;
        if (corner) ++stats_.cornerCells;
        for (int q = 0; q < rule.size(); ++q) {
          const auto qq = static_cast<std::size_t>(q);
          const double a = rule.points[qq * static_cast<std::size_t>(rule.dim)];
          const double bb = prism ? rule.points[qq * 2 + 1] : 0.0;
          Eigen::Vector3d bottom = Eigen::Vector3d::Zero(), top = Eigen::Vector3d::Zero();
          for (const double zeta : {0.0, 1.0}) {
            const double xi[3] = {a, prism ? bb : zeta, zeta};
            ref.evaluate(xi, values, gradients);
            for (int i = 0; i < ref.numNodes(); ++i)
              (zeta == 0.0 ? bottom : top) +=
                  values(i) * Eigen::Vector3d(&out_.xyz[3 * static_cast<std::size_t>(v[i])]);
          }
          const Eigen::Vector3d n = wallNormal(out_, ref, v, a, bb, top - bottom);
          const std::optional<double> along = heightAlongNormal(out_, ref, v, a, bb, bottom, n);
          if (!along) ++stats_.firstHeightOffNormal;
          const double h = along ? *along : (top - bottom).dot(n);
          const double l[3] = {prism ? 1.0 - a - bb : 1.0 - a, a, bb};
          const double target = z_[1] * grownHeight(v, wallVertices(b), l);
          if (stats_.firstHeightMeasured == 0) stats_.firstHeightMin = stats_.firstHeightMax = h;
          stats_.firstHeightMin = std::min(stats_.firstHeightMin, h);
          stats_.firstHeightMax = std::max(stats_.firstHeightMax, h);
          ++stats_.firstHeightMeasured;
          if (std::isfinite(target) && target > 0.0) {
            double& worst =
                corner ? stats_.firstHeightCornerDeviation : stats_.firstHeightDeviation;
            worst = std::max(worst, std::fabs(h / target - 1.0));
          }
        }
      }
    }
  }

  ElementBlock splitCells(const ElementBlock& b) {
    const bool prism = b.type == CellType::Prism;
    const ReferenceElement& ref = ReferenceElement::get(b.type, p_);
    const std::map<LatticePoint, int> index = latticeIndex(ref);
    const int nn = ref.numNodes();
    const int dim = ref.dim();
    const auto across = static_cast<std::size_t>(dim - 1);  // the lattice axis across the layer
    ElementBlock out;
    out.type = b.type;
    out.order = p_;
    out.nodes.resize(b.count() * static_cast<std::size_t>(n_) * static_cast<std::size_t>(nn));
    out.entity.resize(b.count() * static_cast<std::size_t>(n_));
    Eigen::MatrixXd x(nn, 3);
    Eigen::MatrixXd points(nn, dim);
    for (std::size_t e = 0; e < b.count(); ++e) {
      bool corner = false;
      for (int k = 0; k < wallVertices(b); ++k)
        corner = corner || atCorner(topVertex(b, b.element(e), k));
      cellCorner_.push_back(corner ? 1 : 0);
    }
    for (int k = 0; k < n_; ++k) {
      for (std::size_t e = 0; e < b.count(); ++e) {
        const std::int64_t* v = b.element(e);
        const std::int64_t t[3] = {topVertex(b, v, 0), topVertex(b, v, 1),
                                   prism ? topVertex(b, v, 2) : kNone};
        // The macro cell's basis at the k-th thin cell's nodes, on its columns' levels.
        for (int r = 0; r < nn; ++r) {
          const LatticePoint& c = ref.lattice()[static_cast<std::size_t>(r)];
          const std::vector<double>& z = column(b, index, v, c).levels;
          const auto kk = static_cast<std::size_t>(k);
          for (std::size_t a = 0; a < across; ++a)
            points(r, static_cast<Eigen::Index>(a)) = double(c[a]) / p_;
          points(r, static_cast<Eigen::Index>(across)) =
              z[kk] + (z[kk + 1] - z[kk]) * c[across] / p_;
        }
        const Eigen::MatrixXd values = ref.valuesAt(points);
        bool gathered = false;
        const std::size_t sub = e * static_cast<std::size_t>(n_) + static_cast<std::size_t>(k);
        out.entity[sub] = b.entity[e];
        for (int r = 0; r < nn; ++r) {
          const LatticePoint& c = ref.lattice()[static_cast<std::size_t>(r)];
          const std::int64_t level = std::int64_t(k) * p_ + c[across];
          const NodeKey key =
              prism ? makeKey({{{t[0], p_ - c[0] - c[1]}, {t[1], c[0]}, {t[2], c[1]}}}, level)
                    : makeKey({{{t[0], p_ - c[0]}, {t[1], c[0]}, {kNone, 0}}}, level);
          std::int64_t id = 0;
          if (level == 0 || level == std::int64_t(n_) * p_) {
            LatticePoint m = c;
            m[across] = level == 0 ? 0 : p_;
            id = v[index.at(m)];
            nodes_.emplace(key, id);
          } else {
            const auto it = nodes_.find(key);
            if (it != nodes_.end()) {
              id = it->second;
            } else {
              if (!gathered) {
                for (int i = 0; i < nn; ++i)
                  for (int d = 0; d < 3; ++d) x(i, d) = macro_.xyz[3 * v[i] + d];
                gathered = true;
              }
              const Column& col = column(b, index, v, c);
              const Eigen::RowVector3d p =
                  values.row(r) * x +
                  col.shift.transpose() * col.shiftAt(points(r, static_cast<Eigen::Index>(across)));
              const double xyz[3] = {p(0), p(1), p(2)};
              id = out_.addNode(xyz, macro_.dim, b.entity[e], std::nan(""), std::nan(""));
              nodes_.emplace(key, id);
            }
          }
          out.nodes[sub * static_cast<std::size_t>(nn) + static_cast<std::size_t>(r)] = id;
        }
      }
    }
    stats_.prisms += b.count();  // (quadrilaterals in 2D)
    return out;
  }

  // A side quadrilateral's or climbing line's frame: which corner is the wall side's start,
  // the lattice axis across the layer and whether it points away from the wall.
  struct Frame {
    std::array<std::int64_t, 2> wall{};  // wall vertices at along = 0 and along = P
    int alongAxis = 0, acrossAxis = 1;
    bool away = true;
  };

  std::optional<Frame> quadFrame(const std::int64_t* q) const {
    const auto top = [&](std::int64_t a, std::int64_t t) {
      const auto it = topOf_.find(a);
      return it != topOf_.end() && it->second == t;
    };
    if (top(q[0], q[3]) && top(q[1], q[2])) return Frame{{q[0], q[1]}, 0, 1, true};
    if (top(q[3], q[0]) && top(q[2], q[1])) return Frame{{q[3], q[2]}, 0, 1, false};
    if (top(q[0], q[1]) && top(q[3], q[2])) return Frame{{q[0], q[3]}, 1, 0, true};
    if (top(q[1], q[0]) && top(q[2], q[3])) return Frame{{q[1], q[2]}, 1, 0, false};
    return std::nullopt;
  }

  std::optional<Frame> lineFrame(const std::int64_t* l) const {
    const auto it0 = topOf_.find(l[0]), it1 = topOf_.find(l[1]);
    if (it0 != topOf_.end() && it0->second == l[1]) return Frame{{l[0], l[0]}, 1, 0, true};
    if (it1 != topOf_.end() && it1->second == l[0]) return Frame{{l[1], l[1]}, 1, 0, false};
    return std::nullopt;
  }

  ElementBlock splitSides(const ElementBlock& b) {
    const bool quad = b.type == CellType::Quadrilateral;
    const ReferenceElement& ref = ReferenceElement::get(b.type, p_);
    const std::map<LatticePoint, int> index = latticeIndex(ref);
    const int nn = ref.numNodes();
    ElementBlock out;
    out.type = b.type;
    out.order = p_;
    projected_.resize(out_.numNodes(), 0);
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* v = b.element(e);
      const std::optional<Frame> frame = quad ? quadFrame(v) : lineFrame(v);
      if (!frame) {  // not a side of the layer: kept
        out.nodes.insert(out.nodes.end(), v, v + nn);
        out.entity.push_back(b.entity[e]);
        continue;
      }
      ++(quad ? stats_.quadrilaterals : stats_.lines);
      for (int k = 0; k < n_; ++k) {
        for (int r = 0; r < nn; ++r) {
          const LatticePoint& c = ref.lattice()[static_cast<std::size_t>(r)];
          const int along = quad ? c[static_cast<std::size_t>(frame->alongAxis)] : 0;
          const int acrossLocal = c[static_cast<std::size_t>(frame->acrossAxis)];
          const int a = frame->away ? acrossLocal : p_ - acrossLocal;
          const std::int64_t level = std::int64_t(k) * p_ + a;
          const std::int64_t t0 = topOf_.at(frame->wall[0]), t1 = topOf_.at(frame->wall[1]);
          const NodeKey key = quad ? makeKey({{{t0, p_ - along}, {t1, along}, {kNone, 0}}}, level)
                                   : makeKey({{{t0, p_}, {kNone, 0}, {kNone, 0}}}, level);
          const auto it = nodes_.find(key);
          if (it == nodes_.end())
            throw MeshingError(std::string("boundary-layer split: a side ") +
                               (quad ? "quadrilateral" : "line") + " of the layer on " +
                               (quad ? "Face" : "Edge") + std::to_string(b.entity[e]) +
                               " is not a side of its prisms");
          out.nodes.push_back(it->second);
          if (level != 0 && level != std::int64_t(n_) * p_) {
            // The macro side's node nearest in level gives the projection's start.
            LatticePoint m{0, 0, 0};
            const int macroAcross = static_cast<int>(std::lround(zAt(k, a) * p_));
            m[static_cast<std::size_t>(frame->acrossAxis)] =
                frame->away ? macroAcross : p_ - macroAcross;
            if (quad) m[static_cast<std::size_t>(frame->alongAxis)] = along;
            project(it->second, quad ? 2 : 1, b.entity[e], v[index.at(m)], frame->wall[0]);
          }
        }
        out.entity.push_back(b.entity[e]);
      }
    }
    return out;
  }

  void project(std::int64_t id, int dim, int entity, std::int64_t hint, std::int64_t wall) {
    auto i = static_cast<std::size_t>(id);
    if (cad_ == nullptr || (projected_[i] != 0 && dim == 2)) return;
    projected_[i] = 1;
    const Eigen::Vector3d x(&out_.xyz[3 * i]);
    const auto h = static_cast<std::size_t>(hint);
    const bool same = macro_.nodeCadDim[h] == dim && macro_.nodeCadIndex[h] == entity;
    Eigen::Vector3d p;
    double u = 0.0, v = std::nan("");
    if (dim == 2) {
      std::optional<std::array<double, 2>> guess;
      if (same && std::isfinite(macro_.nodeCadParam[2 * h]))
        guess = std::array<double, 2>{macro_.nodeCadParam[2 * h], macro_.nodeCadParam[2 * h + 1]};
      const SurfaceProjection proj = cad_->projectOnSurface(entity, x, guess);
      p = proj.point;
      u = proj.u;
      v = proj.v;
    } else {
      std::optional<double> guess;
      if (same && std::isfinite(macro_.nodeCadParam[2 * h])) guess = macro_.nodeCadParam[2 * h];
      const CurveProjection proj = cad_->projectOnCurve(entity, x, guess);
      p = proj.point;
      u = proj.t;
    }
    const double height = height_.count(wall) != 0 ? height_.at(wall) : 0.0;
    if (height > 0.0)
      stats_.maxProjection = std::max(stats_.maxProjection, (p - x).norm() / height);
    ++stats_.projected;
    for (int d = 0; d < 3; ++d) out_.xyz[3 * i + static_cast<std::size_t>(d)] = p(d);
    out_.nodeCadDim[i] = static_cast<std::uint8_t>(dim);
    out_.nodeCadIndex[i] = entity;
    out_.nodeCadParam[2 * i] = u;
    out_.nodeCadParam[2 * i + 1] = v;
  }
};

}  // namespace

void blendLayerInteriors(Mesh& mesh, const CadModel* cad, bool tops) {
  std::vector<char> done(mesh.numNodes(), 0);
  const auto setOnCad = [&](std::size_t id, const Eigen::Vector3d& x) {
    if (mesh.dim == 3 && mesh.nodeCadDim[id] == 2 && cad != nullptr) {
      std::optional<std::array<double, 2>> guess;
      if (std::isfinite(mesh.nodeCadParam[2 * id]) && std::isfinite(mesh.nodeCadParam[2 * id + 1]))
        guess = std::array<double, 2>{mesh.nodeCadParam[2 * id], mesh.nodeCadParam[2 * id + 1]};
      const SurfaceProjection proj = cad->projectOnSurface(mesh.nodeCadIndex[id], x, guess);
      for (std::size_t d = 0; d < 3; ++d)
        mesh.xyz[3 * id + d] = proj.point(static_cast<Eigen::Index>(d));
      mesh.nodeCadParam[2 * id] = proj.u;
      mesh.nodeCadParam[2 * id + 1] = proj.v;
      return;
    }
    for (std::size_t d = 0; d < 3; ++d) mesh.xyz[3 * id + d] = x(static_cast<Eigen::Index>(d));
  };
  // Nodes this may place: inside the domain, or (3D, with the CAD) on a face, projected back.
  const auto movable = [&](std::size_t id) {
    return mesh.nodeCadDim[id] == mesh.dim ||
           (mesh.dim == 3 && mesh.nodeCadDim[id] == 2 && cad != nullptr);
  };
  for (int pass = tops ? 0 : 1; pass < 2; ++pass)  // tops first: the inner levels blend to them
    for (const ElementBlock& b : mesh.blocks) {
      // The layer's cells: prisms (wall 0, 1, 2, tops 3, 4, 5), in 2D quadrilaterals (wall 0,
      // 1, tops 3, 2); the lattice axis across the layer is the last.
      if (!isLayerCell(mesh, b) || b.order < 2) continue;
      const bool prism = b.type == CellType::Prism;
      const int p = b.order;
      const int walls = prism ? 3 : 2;
      const std::size_t across = prism ? 2 : 1;
      const ReferenceElement& ref = ReferenceElement::get(b.type, p);
      const std::map<LatticePoint, int> index = latticeIndex(ref);
      for (std::size_t e = 0; e < b.count(); ++e) {
        const std::int64_t* v = b.element(e);
        const auto x = [&](std::int64_t n) {
          return Eigen::Vector3d(&mesh.xyz[3 * static_cast<std::size_t>(n)]);
        };
        const auto top = [&](int k) { return prism ? v[k + 3] : v[3 - k]; };
        for (int r = 0; r < ref.numNodes(); ++r) {
          const LatticePoint& c = ref.lattice()[static_cast<std::size_t>(r)];
          const auto id = static_cast<std::size_t>(v[r]);
          const bool vertex =
              prism ? (c[0] == 0 || c[0] == p) && (c[1] == 0 || c[1] == p) && c[0] + c[1] <= p
                    : c[0] == 0 || c[0] == p;
          if (c[across] == 0 || !movable(id) || done[id] != 0 || (pass == 0) != (c[across] == p))
            continue;
          if (pass == 0 && vertex) continue;
          done[id] = 1;
          LatticePoint wallPoint = c;
          wallPoint[across] = 0;
          const std::int64_t w = v[index.at(wallPoint)];
          if (pass == 0) {
            // The top is the wall node offset along the wall's own normal there, corrected by
            // the vertices' deviations of their climbs from the wall normal (interpolated), by
            // the interpolated height: parallel to the curved wall, meeting the top vertices.
            const double l[3] = {prism ? double(p - c[0] - c[1]) / p : double(p - c[0]) / p,
                                 double(c[0]) / p, prism ? double(c[1]) / p : 0.0};
            const double corner[3][2] = {{0, 0}, {1, 0}, {0, 1}};
            Eigen::Vector3d rise = Eigen::Vector3d::Zero();
            double h = 0.0;
            for (int k = 0; k < walls; ++k) {
              rise += l[k] * (x(top(k)) - x(v[k]));
              h += l[k] * (x(top(k)) - x(v[k])).norm();
            }
            // In 2D the CAD curve's own normals where the wall nodes are on it: the wall's
            // polynomial tilts its normal by degrees near the ends of a short wall around a
            // tight tip (T106's trailing edge, 3 degrees on a wall 0.0035 long), which the
            // top, 0.053 away, turns into a fold.
            const int curve = mesh.dim == 2 && cad != nullptr && mesh.nodeCadDim[w] == 1
                                  ? mesh.nodeCadIndex[w]
                                  : 0;
            std::array<Eigen::Vector3d, 3> atCorner;
            Eigen::Vector3d direction = Eigen::Vector3d::Zero();
            bool exact = curve > 0;
            if (exact) {
              const double near = mesh.nodeCadParam[2 * static_cast<std::size_t>(w)];
              direction = curveNormal(mesh, *cad, w, curve, near, rise);
              for (int k = 0; k < walls; ++k)
                atCorner[static_cast<std::size_t>(k)] =
                    curveNormal(mesh, *cad, v[k], curve, near, x(top(k)) - x(v[k]));
              exact = !direction.isZero() && !atCorner[0].isZero() && !atCorner[1].isZero();
            }
            if (!exact) {
              direction =
                  wallNormal(mesh, ref, v, double(c[0]) / p, prism ? double(c[1]) / p : 0.0, rise);
              for (int k = 0; k < walls; ++k)
                atCorner[static_cast<std::size_t>(k)] =
                    wallNormal(mesh, ref, v, corner[k][0], corner[k][1], x(top(k)) - x(v[k]));
            }
            for (int k = 0; k < walls; ++k) {
              const Eigen::Vector3d climb = x(top(k)) - x(v[k]);
              direction += l[k] * (climb.normalized() - atCorner[static_cast<std::size_t>(k)]);
            }
            if (!(direction.norm() > 0.0)) continue;
            setOnCad(id, x(w) + h * direction.normalized());
            continue;
          }
          LatticePoint topPoint = c;
          topPoint[across] = p;
          const std::int64_t t = v[index.at(topPoint)];
          const double s = double(c[across]) / p;
          setOnCad(id, (1.0 - s) * x(w) + s * x(t));
        }
      }
    }
}

Mesh splitBoundaryLayer(const Mesh& macro, const std::vector<double>& z, const CadModel* cad,
                        LayerSplitStats* stats, const LayerHeights* heights) {
  LayerSplitStats local;
  return LayerSplitter(macro, z, cad, heights, stats != nullptr ? *stats : local).run();
}

void keepColumnsPlain(const Mesh& macro, int layers, std::size_t element, LayerHeights& heights) {
  std::size_t base = 0;
  std::optional<std::set<std::int64_t>> wall;  // made at the first block that may hold fans
  for (const ElementBlock& b : macro.blocks) {
    if (cellDimension(b.type) != macro.dim) continue;
    if (isLayerCell(macro, b)) {
      const std::size_t count = b.count() * static_cast<std::size_t>(layers);
      if (element >= base + count) {
        base += count;
        continue;
      }
      const std::size_t e = (element - base) / static_cast<std::size_t>(layers);
      const ReferenceElement& ref = ReferenceElement::get(b.type, b.order);
      const std::size_t across = b.type == CellType::Prism ? 2 : 1;
      for (int r = 0; r < ref.numNodes(); ++r)
        if (ref.lattice()[static_cast<std::size_t>(r)][across] == b.order)
          heights.plain.insert(b.element(e)[r]);
      return;
    }
    if (!mayHoldFans(macro, b)) {  // one element each
      if (element >= base + b.count()) {
        base += b.count();
        continue;
      }
      return;
    }
    if (!wall) wall = layerWall(macro);
    const std::vector<char> fan = fanTriangles(b, *wall);
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::size_t count = fan[e] != 0 ? 2 * static_cast<std::size_t>(layers) - 1 : 1;
      if (element >= base + count) {
        base += count;
        continue;
      }
      if (fan[e] == 0) return;
      // Its two vertices off the wall are its columns' tops (the corner is on no column).
      for (int k = 0; k < 3; ++k)
        if (wall->count(b.element(e)[k]) == 0) heights.plain.insert(b.element(e)[k]);
      return;
    }
  }
}

std::vector<double> layerTopNormals(const Mesh& mesh) {
  std::map<std::int64_t, NormalSum> tops;
  forEachColumn(
      mesh, [&](std::int64_t, std::int64_t top, const Eigen::Vector3d& n) { tops[top].add(n); });
  std::vector<double> normals(3 * mesh.numNodes(), std::nan(""));
  for (const auto& [id, n] : tops) {
    // Above a sharp corner the column follows the corner's bisector and no plane keeps both
    // walls' heights: free.
    if (n.sharp() || !(n.sum.norm() > 0.0)) continue;
    const Eigen::Vector3d unit = n.sum.normalized();
    for (std::size_t d = 0; d < 3; ++d)
      normals[3 * static_cast<std::size_t>(id) + d] = unit(static_cast<Eigen::Index>(d));
  }
  return normals;
}

std::vector<double> grownLayerHeights(const Mesh& linear) {
  std::vector<double> heights(linear.numNodes(), std::nan(""));
  for (const ElementBlock& b : linear.blocks) {
    if (!isLayerCell(linear, b)) continue;
    const bool prism = b.type == CellType::Prism;
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* v = b.element(e);
      for (int k = 0; k < (prism ? 3 : 2); ++k) {
        const std::int64_t t = prism ? v[k + 3] : v[3 - k];
        heights[static_cast<std::size_t>(v[k])] =
            (Eigen::Vector3d(&linear.xyz[3 * static_cast<std::size_t>(t)]) -
             Eigen::Vector3d(&linear.xyz[3 * static_cast<std::size_t>(v[k])]))
                .norm();
      }
    }
  }
  return heights;
}

}  // namespace homesh

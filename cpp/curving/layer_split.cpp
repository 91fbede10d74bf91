#include "curving/layer_split.hpp"

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <optional>
#include <set>

#include "core/error.hpp"
#include "element/quadrature.hpp"
#include "element/reference_element.hpp"

namespace homesh {

bool isLayerCell(const Mesh& mesh, const ElementBlock& block) {
  return (block.type == CellType::Prism && mesh.dim == 3) ||
         (block.type == CellType::Quadrilateral && mesh.dim == 2);
}

namespace {

constexpr std::int64_t kNone = std::numeric_limits<std::int64_t>::max();

// A wall node is at a sharp corner when the mean of its cells' unit wall normals is shorter than
// this (cos 15 degrees: the normals spread by more than about 30 degrees).
constexpr double kCornerMeanNormal = 0.966;

// A node of the split layer: up to three wall vertices with integer weights (summing to the
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
    for (const ElementBlock& b : macro_.blocks)
      if (layerCell(b)) pairWallAndTop(b);
    forEachColumn(macro_, [this](std::int64_t wall, std::int64_t, const Eigen::Vector3d& n) {
      normals_[wall].add(n);
    });
    for (const ElementBlock& b : macro_.blocks) {
      if (layerCell(b))
        out_.blocks.push_back(splitCells(b));
      else if (b.type != CellType::Quadrilateral && b.type != CellType::Line)
        out_.blocks.push_back(b);
    }
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
  std::map<std::int64_t, NormalSum> normals_;   // wall node -> its cells' wall normals
  std::map<std::int64_t, std::int64_t> topOf_;  // wall vertex -> top vertex
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
        const auto [it, fresh] = topOf_.emplace(v[k], top);
        if (!fresh && it->second != top)
          throw MeshingError("boundary-layer split: wall node " + std::to_string(v[k]) +
                             " has two top nodes");
        height_[v[k]] =
            (Eigen::Vector3d(&macro_.xyz[3 * top]) - Eigen::Vector3d(&macro_.xyz[3 * v[k]])).norm();
      }
    }
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
  std::map<std::int64_t, Column> columns_;      // wall node -> how its column is split
  static constexpr double kMaxShiftLean = 1.0;  // tangent of the lean: 45 degrees
  const Column& column(const ElementBlock& b, const std::map<LatticePoint, int>& index,
                       const std::int64_t* v, LatticePoint c) {
    const std::size_t across = b.type == CellType::Prism ? 2 : 1;
    c[across] = 0;
    const std::int64_t w = v[index.at(c)];
    const auto found = columns_.find(w);
    if (found != columns_.end()) return found->second;
    Column col;
    col.levels = z_;
    const bool prism = b.type == CellType::Prism;
    const double l[3] = {prism ? double(p_ - c[0] - c[1]) / p_ : double(p_ - c[0]) / p_,
                         double(c[0]) / p_, prism ? double(c[1]) / p_ : 0.0};
    const double target = grownHeight(v, wallVertices(b), l);
    const auto normal = normals_.find(w);
    if (n_ > 1 && plain_.count(w) == 0 && std::isfinite(target) && target > 0.0 &&
        normal != normals_.end() && normal->second.sum.norm() > 0.0) {
      LatticePoint t = c;
      t[across] = p_;
      const Eigen::Vector3d x0(&macro_.xyz[3 * static_cast<std::size_t>(w)]);
      const Eigen::Vector3d rise =
          Eigen::Vector3d(&macro_.xyz[3 * static_cast<std::size_t>(v[index.at(t)])]) - x0;
      const Eigen::Vector3d n = normal->second.sum.normalized();
      const double height = rise.dot(n);
      if (height > 0.0) {
        const double z1 = z_[1];
        const double first =
            std::clamp(z1 * target / height, 0.5 * z1, std::min(2.0 * z1, 0.5 * (z1 + z_[2])));
        for (std::size_t k = 1; k + 1 < col.levels.size(); ++k)
          col.levels[k] = first + (z_[k] - z1) * (1.0 - first) / (1.0 - z1);
        // Only where the column leans by less than kMaxShiftLean: at a sharp corner the column
        // follows the corner's bisector by design, and no shift gives both walls their height.
        // (Where the adjusted column makes a thin cell invalid, the pipeline splits it plain.)
        const Eigen::Vector3d lean = rise - height * n;
        if (lean.norm() < kMaxShiftLean * height) col.shift = -first * lean;
      }
    }
    return columns_.emplace(w, std::move(col)).first->second;
  }

  // Whether the walls of the cells around wall vertex `w` meet at a sharp corner.
  bool atCorner(std::int64_t w) const {
    const auto n = normals_.find(w);
    return n != normals_.end() && n->second.sharp();
  }

  // The first split layer's height along the wall normal at the wall's quadrature points
  // (exact to degree 2P), in stats_: its range and, with grown heights, its worst deviation
  // from z_1 H*.
  void measureFirstLayer() {
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
        bool corner = false;
        for (int k = 0; k < wallVertices(b); ++k) corner = corner || atCorner(v[k]);
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
    for (int k = 0; k < n_; ++k) {
      for (std::size_t e = 0; e < b.count(); ++e) {
        const std::int64_t* v = b.element(e);
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
              prism ? makeKey({{{v[0], p_ - c[0] - c[1]}, {v[1], c[0]}, {v[2], c[1]}}}, level)
                    : makeKey({{{v[0], p_ - c[0]}, {v[1], c[0]}, {kNone, 0}}}, level);
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
          const NodeKey key =
              quad ? makeKey({{{frame->wall[0], p_ - along}, {frame->wall[1], along}, {kNone, 0}}},
                             level)
                   : makeKey({{{frame->wall[0], p_}, {kNone, 0}, {kNone, 0}}}, level);
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
            Eigen::Vector3d direction =
                wallNormal(mesh, ref, v, double(c[0]) / p, prism ? double(c[1]) / p : 0.0, rise);
            for (int k = 0; k < walls; ++k) {
              const Eigen::Vector3d climb = x(top(k)) - x(v[k]);
              direction += l[k] * (climb.normalized() -
                                   wallNormal(mesh, ref, v, corner[k][0], corner[k][1], climb));
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
  for (const ElementBlock& b : macro.blocks) {
    if (cellDimension(b.type) != macro.dim) continue;
    const bool cell = isLayerCell(macro, b);
    const std::size_t count = b.count() * static_cast<std::size_t>(cell ? layers : 1);
    if (element >= base + count) {
      base += count;
      continue;
    }
    if (!cell) return;
    const std::size_t e = (element - base) / static_cast<std::size_t>(layers);
    const ReferenceElement& ref = ReferenceElement::get(b.type, b.order);
    const std::size_t across = b.type == CellType::Prism ? 2 : 1;
    for (int r = 0; r < ref.numNodes(); ++r)
      if (ref.lattice()[static_cast<std::size_t>(r)][across] == 0)
        heights.plain.insert(b.element(e)[r]);
    return;
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

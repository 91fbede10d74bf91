#include "curving/face_fidelity_fit.hpp"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <numeric>
#include <optional>
#include <utility>

#include "cad/cad_model.hpp"
#include "core/error.hpp"
#include "element/quadrature.hpp"
#include "element/reference_element.hpp"
#include "element/symmetric_quadrature.hpp"

namespace homesh {
namespace {

// Gauss-Newton steps at most, and the relative fall of F below which the fit stops: the
// sphere's order-5 triangles settle in 3 to 4 steps.
constexpr int kMaxSteps = 8;
constexpr double kStopFall = 1e-3;
// Halvings of a step that raised F before the fit gives up.
constexpr int kHalvings = 4;
// Newton steps of a point's projection onto the face: from a node's (u, v) at the start, from
// the last foot after (a step moves the points by a small fraction of the triangle).
constexpr int kFirstProjectionSteps = 6;
constexpr int kProjectionSteps = 2;
// A foot whose point is off the face's normal through it by more than this (relative to its
// triangle's size) after those steps is found again by the CAD's own projection: near a pole
// the chart's (u, v) steps stop short, and a triangle at a sphere's pole read 2.7 degrees off
// the normal where the report's projection read 0.02.
constexpr double kFootSlip = 1e-6;
// Weight of each free node's squared distance from its start (relative to the triangle's size):
// where the points do not see a slide (along a plane or a cylinder's axis) the node stays. Small
// against what the fit moves for: on the sphere the nodes move by 0.002 of the size, which this
// prices at 4e-10 where F falls from 3e-5 to 5e-6.
constexpr double kStay = 1e-4;
// Rounds of the boundary's patches at most (BoundaryFitter::fit): on the sphere in a box at size
// 0.8, order 5 (the stage fitting every triangle), the largest normal angle after 1, 2 and 3
// rounds was 0.0117, 0.0086 and 0.0084 degrees.
constexpr int kRounds = 3;
// A patch whose F is below this has nothing to gain (a plane's: zero up to rounding; the
// normals within 1e-7 radians).
constexpr double kNothingToFit = 1e-14;
// A fit is kept where it lowers F by at least 1 %: not for rounding's gains.
constexpr double kKeptFall = 0.99;

// The lattice-indexed basis of an order-P triangle at its quadrature points.
struct FitTable {
  int nodes = 0, points = 0;
  Eigen::MatrixXd values, dxi, deta;  // points x nodes, columns in latticeIndex order
  std::vector<double> weights;
};

// `check`: the points the report's geometry samples instead (the same rule of degree 2P + 2 and
// the nodes, quality/geometry_accuracy.cpp), weights zero at the nodes: for the largest angle.
const FitTable& fitTable(int order, bool check = false) {
  static std::mutex lock;
  static std::array<std::array<std::unique_ptr<FitTable>, 2>, kMaxOrder + 1> tables;
  const std::lock_guard<std::mutex> guard(lock);
  std::unique_ptr<FitTable>& t = tables[static_cast<std::size_t>(order)][check ? 1 : 0];
  if (t) return *t;
  t = std::make_unique<FitTable>();
  const int degree = check ? 2 * order + 2 : 2 * order;
  const std::optional<QuadratureRule> symmetric =
      check ? std::nullopt : symmetricRule(CellType::Triangle, degree);
  const QuadratureRule rule = symmetric ? *symmetric : quadratureRule(CellType::Triangle, degree);
  const ReferenceElement& ref = ReferenceElement::get(CellType::Triangle, order);
  const Eigen::MatrixXd points = pointRows(rule, check ? ref.nodes() : Eigen::MatrixXd());
  const Eigen::MatrixXd values = ref.valuesAt(points);
  const std::vector<Eigen::MatrixXd> grads = ref.derivativesAt(points);
  t->nodes = ref.numNodes();
  t->points = static_cast<int>(points.rows());
  t->values.resize(t->points, t->nodes);
  t->dxi.resize(t->points, t->nodes);
  t->deta.resize(t->points, t->nodes);
  for (int n = 0; n < t->nodes; ++n) {
    const LatticePoint& l = ref.lattice()[static_cast<std::size_t>(n)];
    const int k = latticeIndex(order, l[0], l[1]);
    t->values.col(k) = values.col(n);
    t->dxi.col(k) = grads[0].col(n);
    t->deta.col(k) = grads[1].col(n);
  }
  t->weights = rule.weights;
  t->weights.resize(static_cast<std::size_t>(t->points), 0.0);  // the nodes': zero
  return *t;
}

// One quadrature point's target on the face: its foot's parameters, position and unit normal
// (zero where the face's normal is undefined).
struct Foot {
  FaceParameter uv{};
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  // How the normal turns as the point moves: dn = -curvature dx (the Weingarten map on the
  // tangential part of dx, J G^-1 B G^-1 J^T, for `normal`'s orientation).
  Eigen::Matrix3d curvature = Eigen::Matrix3d::Zero();
};

// A patch of order-P triangles on one face sharing nodes: slot per node, each triangle's slots in
// lattice order; F summed over the triangles, the free slots moving.
struct Patch {
  std::vector<FaceParameter> uv;
  std::vector<Eigen::Vector3d> x;
  std::vector<char> free;
  std::vector<char> onFace;  // uv is the node's own (not a corner on a curve or vertex)
  std::vector<std::vector<int>> triangles;  // slots, latticeIndex order
};

class Fit {
 public:
  // `check`: the points are the report's (fitTable), for largestSine.
  Fit(const FaceChart& chart, int order, Patch patch, bool check = false)
      : chart_(chart), p_(order), table_(fitTable(order, check)), patch_(std::move(patch)) {
    for (std::size_t k = 0; k < patch_.free.size(); ++k)
      if (patch_.free[k] != 0) {
        free_.push_back(static_cast<int>(k));
        patch_.x[k] = chart_.point(patch_.uv[k]);
      }
    start_ = patch_.x;
    for (const std::vector<int>& t : patch_.triangles) {
      const Eigen::Vector3d& a = patch_.x[static_cast<std::size_t>(t[latticeIndex(p_, 0, 0)])];
      const Eigen::Vector3d& b = patch_.x[static_cast<std::size_t>(t[latticeIndex(p_, p_, 0)])];
      const Eigen::Vector3d& c = patch_.x[static_cast<std::size_t>(t[latticeIndex(p_, 0, p_)])];
      size_.push_back(std::sqrt(0.5 * (b - a).cross(c - a).norm()));
    }
    // Each point's projection starts from the free node of its triangle whose basis function is
    // largest there (a corner's (u, v) may be a pole's arbitrary one), else its interior's.
    for (const std::vector<int>& t : patch_.triangles)
      for (int q = 0; q < table_.points; ++q) {
        int best = -1;
        for (int k = 0; k < table_.nodes; ++k) {
          const auto slot = static_cast<std::size_t>(t[k]);
          const bool candidate =
              patch_.onFace.empty() ? patch_.free[slot] != 0 : patch_.onFace[slot] != 0;
          if (candidate && (best < 0 || table_.values(q, k) > table_.values(q, best))) best = k;
        }
        if (best < 0) best = latticeIndex(p_, 1, 1);
        Foot foot;
        foot.uv = patch_.uv[static_cast<std::size_t>(t[best])];
        feet_.push_back(foot);
      }
  }

  // The largest squared sine of the angle between the patch's and the face's normals at its
  // quadrature points (what the report's largest normal angle sees); infinity where the patch
  // cannot be measured.
  double largestSine() {
    const bool sized = std::all_of(size_.begin(), size_.end(), [](double h) { return h > 0.0; });
    if (!sized || !refreshFeet(kFirstProjectionSteps))
      return std::numeric_limits<double>::infinity();
    double largest = 0.0;
    if (!std::isfinite(objective(nullptr, nullptr, &largest)))
      return std::numeric_limits<double>::infinity();
    return largest;
  }

  TriangleFit run() {
    TriangleFit result;
    const bool sized = std::all_of(size_.begin(), size_.end(), [](double h) { return h > 0.0; });
    if (free_.empty() || !sized || !refreshFeet(kFirstProjectionSteps)) {
      result.uv = patch_.uv;
      return result;
    }
    double f = objective(nullptr, nullptr, &result.largestBefore);
    result.before = result.after = f;
    result.largestAfter = result.largestBefore;
    if (!(f > kNothingToFit)) {
      result.uv = patch_.uv;
      return result;
    }
    for (int step = 0; step < kMaxSteps; ++step) {
      Eigen::VectorXd residual;
      Eigen::MatrixXd jacobian;
      objective(&residual, &jacobian);
      const Eigen::MatrixXd normal = jacobian.transpose() * jacobian;
      const Eigen::VectorXd gradient = jacobian.transpose() * residual;
      // A small Levenberg-Marquardt diagonal: the model is good near the surface; the stay term
      // (kStay) already holds the directions the points do not see.
      Eigen::MatrixXd damped = normal;
      damped.diagonal() += 1e-6 * normal.diagonal() +
                           Eigen::VectorXd::Constant(normal.rows(), 1e-14 * normal.trace());
      const Eigen::VectorXd delta = -damped.ldlt().solve(gradient);
      if (!delta.allFinite()) break;
      const std::vector<FaceParameter> uv0 = patch_.uv;
      const std::vector<Eigen::Vector3d> x0 = patch_.x;
      const std::vector<Foot> feet0 = feet_;
      bool kept = false;
      double scale = 1.0;
      for (int h = 0; h <= kHalvings && !kept; ++h, scale *= 0.5) {
        for (std::size_t n = 0; n < free_.size(); ++n) {
          const auto k = static_cast<std::size_t>(free_[n]);
          patch_.uv[k] = {uv0[k][0] + scale * delta(static_cast<Eigen::Index>(2 * n)),
                          uv0[k][1] + scale * delta(static_cast<Eigen::Index>(2 * n + 1))};
          patch_.x[k] = chart_.point(patch_.uv[k]);
        }
        feet_ = feet0;
        if (!refreshFeet(kProjectionSteps)) break;
        double trialLargest = 0.0;
        const double trial = objective(nullptr, nullptr, &trialLargest);
        if (trial < f) {
          kept = true;
          result.largestAfter = trialLargest;
          const double fall = (f - trial) / f;
          f = trial;
          ++result.steps;
          if (fall < kStopFall) step = kMaxSteps;
        }
      }
      if (!kept) {
        patch_.uv = uv0;
        patch_.x = x0;
        feet_ = feet0;
        break;
      }
    }
    result.after = f;
    result.uv = patch_.uv;
    return result;
  }

 private:
  // The points' feet and normals on the face, from their last feet; false where a point left
  // the face's parametrisation (a non-finite evaluation).
  bool refreshFeet(int steps) {
    for (std::size_t t = 0; t < patch_.triangles.size(); ++t)
      for (int q = 0; q < table_.points; ++q) {
        Foot& foot =
            feet_[t * static_cast<std::size_t>(table_.points) + static_cast<std::size_t>(q)];
        const Eigen::Vector3d target = pointAt(patch_.triangles[t], q);
        SurfaceDerivatives d{};
        Eigen::Vector2d step = Eigen::Vector2d::Zero();
        bool stepped = false;
        for (int s = 0; s <= steps; ++s) {
          d = chart_.cad().evaluateSurface(chart_.face(), foot.uv[0], foot.uv[1]);
          stepped = tangentStep(d, target, step);
          if (s == steps || !stepped) break;
          foot.uv = {foot.uv[0] + step[0], foot.uv[1] + step[1]};
        }
        if (!d.point.allFinite()) return false;
        // Settled: the offset left is along the normal, to kFootSlip of the triangle's size.
        const bool settled =
            stepped && (d.du * step[0] + d.dv * step[1]).norm() <= kFootSlip * size_[t];
        if (!settled) {
          try {
            const SurfaceProjection p =
                chart_.cad().projectOnSurface(chart_.face(), target, foot.uv);
            foot.uv = {p.u, p.v};
            d = chart_.cad().evaluateSurface(chart_.face(), p.u, p.v);
          } catch (const CadError&) {
            return false;
          }
          if (!d.point.allFinite()) return false;
        }
        foot.point = d.point;
        const std::optional<Eigen::Vector3d> n = d.normalDirection();
        foot.normal = n ? Eigen::Vector3d(n->normalized()) : Eigen::Vector3d::Zero();
        foot.curvature.setZero();
        if (n) {
          Eigen::Matrix<double, 3, 2> j;
          j << d.du, d.dv;
          Eigen::Matrix2d b;
          b << d.duu.dot(foot.normal), d.duv.dot(foot.normal), d.duv.dot(foot.normal),
              d.dvv.dot(foot.normal);
          const Eigen::Matrix2d gInverse = (j.transpose() * j).inverse();
          foot.curvature = j * gInverse * b * gInverse * j.transpose();
        }
      }
    return true;
  }

  // Sets `step` to the (u, v) step that takes the point `d` describes to `target`'s foot on the
  // tangent plane (Gauss-Newton on the distance); false, `step` unset, where the chart degenerates.
  static bool tangentStep(const SurfaceDerivatives& d, const Eigen::Vector3d& target,
                          Eigen::Vector2d& step) {
    Eigen::Matrix<double, 3, 2> j;
    j << d.du, d.dv;
    const Eigen::Matrix2d jtj = j.transpose() * j;
    if (!(std::abs(jtj.determinant()) > 1e-14 * jtj.trace() * jtj.trace())) return false;
    step = jtj.ldlt().solve(j.transpose() * (target - d.point));
    return true;
  }

  Eigen::Vector3d pointAt(const std::vector<int>& t, int q) const {
    Eigen::Vector3d s = Eigen::Vector3d::Zero();
    for (int k = 0; k < table_.nodes; ++k)
      s += table_.values(q, k) * patch_.x[static_cast<std::size_t>(t[k])];
    return s;
  }

  // F at the held feet; with `residual`, its residual vector (per triangle and point: the
  // sine's three components and the distance; then three rows per free node for kStay) and its
  // Jacobian in the free nodes' (u, v).
  double objective(Eigen::VectorXd* residual, Eigen::MatrixXd* jacobian = nullptr,
                   double* largestSine = nullptr) const {
    const auto m = static_cast<Eigen::Index>(free_.size());
    const auto pointRows = static_cast<Eigen::Index>(4 * static_cast<std::size_t>(table_.points) *
                                                     patch_.triangles.size());
    std::vector<int> column(patch_.free.size(), -1);  // a free slot's first column / 2
    for (Eigen::Index n = 0; n < m; ++n)
      column[static_cast<std::size_t>(free_[n])] = static_cast<int>(n);
    if (residual != nullptr) {
      residual->setZero(pointRows + 3 * m);
      jacobian->setZero(pointRows + 3 * m, 2 * m);
    }
    std::vector<Eigen::Matrix<double, 3, 2>> tangents;
    if (jacobian != nullptr)
      for (const int k : free_)
        tangents.push_back(chart_.map(patch_.uv[static_cast<std::size_t>(k)].data()).jacobian);
    double f = 0.0;
    const double meanSize = std::accumulate(size_.begin(), size_.end(), 0.0) / size_.size();
    const double stay = std::sqrt(kStay) / meanSize;
    for (Eigen::Index n = 0; n < m; ++n) {
      const auto k = static_cast<std::size_t>(free_[static_cast<std::size_t>(n)]);
      const Eigen::Vector3d r = stay * (patch_.x[k] - start_[k]);
      f += r.squaredNorm();
      if (residual == nullptr) continue;
      residual->segment<3>(pointRows + 3 * n) = r;
      jacobian->block<3, 2>(pointRows + 3 * n, 2 * n) =
          stay * tangents[static_cast<std::size_t>(n)];
    }
    for (std::size_t t = 0; t < patch_.triangles.size(); ++t) {
      const std::vector<int>& slots = patch_.triangles[t];
      for (int q = 0; q < table_.points; ++q) {
        const Foot& foot =
            feet_[t * static_cast<std::size_t>(table_.points) + static_cast<std::size_t>(q)];
        if (foot.normal.isZero()) continue;
        Eigen::Vector3d xq = Eigen::Vector3d::Zero(), t1 = Eigen::Vector3d::Zero(),
                        t2 = Eigen::Vector3d::Zero();
        for (int k = 0; k < table_.nodes; ++k) {
          const Eigen::Vector3d& xk = patch_.x[static_cast<std::size_t>(slots[k])];
          xq += table_.values(q, k) * xk;
          t1 += table_.dxi(q, k) * xk;
          t2 += table_.deta(q, k) * xk;
        }
        const Eigen::Vector3d mq = t1.cross(t2);
        const double area = mq.norm();
        if (!(area > 0.0)) return std::numeric_limits<double>::infinity();
        const Eigen::Vector3d nh = mq / area;
        const double sign = nh.dot(foot.normal) >= 0.0 ? 1.0 : -1.0;
        const Eigen::Vector3d nc = sign * foot.normal;
        const Eigen::Vector3d offset = xq - foot.point;
        const double sw = std::sqrt(table_.weights[static_cast<std::size_t>(q)]);
        if (largestSine != nullptr)
          *largestSine = std::max(*largestSine, nh.cross(nc).squaredNorm());
        const Eigen::Vector3d sine = sw * nh.cross(nc);
        const double distance = sw * offset.dot(nc) / size_[t];
        f += sine.squaredNorm() + distance * distance;
        if (residual == nullptr) continue;
        const auto row = static_cast<Eigen::Index>(4 * (t * table_.points + q));
        residual->segment<3>(row) = sine;
        (*residual)(row + 3) = distance;
        for (int k = 0; k < table_.nodes; ++k) {
          const int n = column[static_cast<std::size_t>(slots[k])];
          if (n < 0) continue;
          for (int c = 0; c < 2; ++c) {
            const Eigen::Vector3d e = tangents[static_cast<std::size_t>(n)].col(c);
            const Eigen::Vector3d dm =
                table_.dxi(q, k) * e.cross(t2) + table_.deta(q, k) * t1.cross(e);
            const Eigen::Vector3d dn = (dm - nh * nh.dot(dm)) / area;
            // The point moves by l_k e, and its foot's normal turns with it.
            const Eigen::Vector3d dx = table_.values(q, k) * e;
            const Eigen::Vector3d dnc = -sign * (foot.curvature * dx);
            jacobian->block<3, 1>(row, 2 * n + c) += sw * (dn.cross(nc) + nh.cross(dnc));
            (*jacobian)(row + 3, 2 * n + c) += sw * (dx.dot(nc) + offset.dot(dnc)) / size_[t];
          }
        }
      }
    }
    return f;
  }

  const FaceChart& chart_;
  int p_;
  const FitTable& table_;
  Patch patch_;
  std::vector<Eigen::Vector3d> start_;
  std::vector<int> free_;
  std::vector<Foot> feet_;
  std::vector<double> size_;
};

}  // namespace

TriangleFit fitTriangleInterior(const FaceChart& chart, int order,
                                const std::vector<FaceParameter>& uv,
                                const std::vector<Eigen::Vector3d>& x) {
  if (order < 3) {
    TriangleFit result;
    result.uv = uv;
    return result;
  }
  Patch patch;
  patch.uv = uv;
  patch.x = x;
  patch.free.assign(uv.size(), 0);
  for (int j = 1; j < order; ++j)
    for (int i = 1; i + j < order; ++i)
      patch.free[static_cast<std::size_t>(latticeIndex(order, i, j))] = 1;
  std::vector<int> slots(uv.size());
  for (std::size_t k = 0; k < slots.size(); ++k) slots[k] = static_cast<int>(k);
  patch.triangles.push_back(std::move(slots));
  return Fit(chart, order, std::move(patch)).run();
}

namespace {

// A boundary triangle of the mesh: its nodes in lattice order and the face its interior lies on.
struct BoundaryTriangle {
  std::vector<std::int64_t> nodes;
  int face = 0;
};

// The nodes of edge `side` (0: corner 0 to 1, 1: 1 to 2, 2: 2 to 0) strictly between its corners,
// in lattice order from its first corner.
std::vector<int> edgeSlots(int p, int side) {
  std::vector<int> slots;
  for (int k = 1; k < p; ++k)
    slots.push_back(side == 0   ? latticeIndex(p, k, 0)
                    : side == 1 ? latticeIndex(p, p - k, k)
                                : latticeIndex(p, 0, p - k));
  return slots;
}

}  // namespace

class BoundaryFitter::Impl {
 public:
  Impl(Mesh& mesh, const CadModel& cad) : mesh_(mesh), cad_(cad) { collect(); }

  std::size_t triangles() const { return triangles_.size(); }

  std::vector<double> largestSines(const std::vector<char>* which) {
    std::vector<double> sines(triangles_.size(), 0.0);
    for (std::size_t t = 0; t < triangles_.size(); ++t)
      if (which == nullptr || (*which)[t] != 0) sines[t] = largestSine(triangles_[t]);
    return sines;
  }

  std::vector<char> touching(const std::vector<char>& nodes) const {
    std::vector<char> active(triangles_.size(), 0);
    for (std::size_t t = 0; t < triangles_.size(); ++t)
      for (const std::int64_t n : triangles_[t].nodes)
        if (nodes[static_cast<std::size_t>(n)] != 0) active[t] = 1;
    return active;
  }

  std::vector<std::int64_t> starVertices() const {
    std::vector<std::int64_t> vertices;
    for (const auto& [vertex, star] : stars_) vertices.push_back(vertex);
    return vertices;
  }

  std::vector<std::size_t> starOf(std::int64_t vertex) const {
    std::vector<std::size_t> triangles;
    const auto it = stars_.find(vertex);
    if (it != stars_.end())
      for (const auto& [t, c] : it->second) triangles.push_back(t);
    return triangles;
  }

  std::vector<std::vector<std::int64_t>> fitVertices(const std::vector<std::int64_t>& vertices,
                                                     const std::vector<char>* frozen) {
    frozen_ = frozen;
    std::vector<std::vector<std::int64_t>> moved(vertices.size());
    std::vector<Eigen::Vector3d> shifts(vertices.size(), Eigen::Vector3d::Zero());
    for (std::size_t i = 0; i < vertices.size(); ++i) {
      const auto it = stars_.find(vertices[i]);
      // A frozen vertex: its sides' and interiors' patches are the tiers'.
      if (it == stars_.end() ||
          (frozen != nullptr && (*frozen)[static_cast<std::size_t>(vertices[i])] != 0))
        continue;
      std::vector<const BoundaryTriangle*> patch;
      std::vector<std::int64_t> free{vertices[i]};
      for (const auto& [t, c] : it->second) {
        const BoundaryTriangle& tri = triangles_[t];
        patch.push_back(&tri);
        for (const std::int64_t n : interior(tri)) free.push_back(n);
        // The two sides at the vertex's corner c: side c runs from it, side c + 2 to it.
        for (const int side : {c, (c + 2) % 3})
          for (const int k : edgeSlots(order_, side))
            free.push_back(tri.nodes[static_cast<std::size_t>(k)]);
      }
      std::sort(free.begin(), free.end());
      free.erase(std::unique(free.begin(), free.end()), free.end());
      if (frozen != nullptr)  // as fit() would, so that `moved` names only the nodes written
        free.erase(std::remove_if(
                       free.begin(), free.end(),
                       [&](std::int64_t n) { return (*frozen)[static_cast<std::size_t>(n)] != 0; }),
                   free.end());
      const Eigen::Vector3d from = point(vertices[i]);
      if (!fit(patch, free, true)) continue;
      moved[i] = free;
      shifts[i] = point(vertices[i]) - from;
    }
    // The volume's nodes follow each kept vertex by their share of it, so that the tetrahedra
    // around it move as their straight-sided maps would, instead of bending at the vertex.
    std::vector<std::int64_t> kept;
    for (std::size_t i = 0; i < vertices.size(); ++i)
      if (!moved[i].empty()) kept.push_back(vertices[i]);
    const std::map<std::int64_t, std::vector<Dragged>> dragged = draggedNodes(kept);
    for (std::size_t i = 0; i < vertices.size(); ++i) {
      const auto around = dragged.find(vertices[i]);
      if (moved[i].empty() || around == dragged.end()) continue;
      for (const Dragged& d : around->second) {
        const auto n = static_cast<std::size_t>(d.node);
        for (int c = 0; c < 3; ++c) mesh_.xyz[3 * n + c] += d.share * shifts[i][c];
        moved[i].push_back(d.node);
      }
    }
    return moved;
  }

  void fit(const std::vector<char>& active, const std::vector<char>* frozen) {
    frozen_ = frozen;
    // Rounds over the edges inside a face, each fitted with the interiors of its two
    // triangles, then over every triangle's interior with its edges as they now are: a
    // Gauss-Seidel sweep of patches sharing nodes, repeated while one is kept.
    for (int round = 0; round < kRounds; ++round) {
      bool any = false;
      for (const auto& [edge, owners] : edges_) {
        if (owners.size() != 2 || (active[owners[0].first] == 0 && active[owners[1].first] == 0))
          continue;
        const BoundaryTriangle& a = triangles_[owners[0].first];
        const BoundaryTriangle& b = triangles_[owners[1].first];
        if (a.face != b.face || !onFace(a.nodes, edgeSlots(order_, owners[0].second), a.face))
          continue;
        std::vector<std::int64_t> free = interior(a);
        for (const std::int64_t n : interior(b)) free.push_back(n);
        for (const int k : edgeSlots(order_, owners[0].second))
          free.push_back(a.nodes[static_cast<std::size_t>(k)]);
        if (fit({&a, &b}, free)) any = true;
      }
      for (std::size_t t = 0; t < triangles_.size() && order_ >= 3; ++t)
        if (active[t] != 0 && fit({&triangles_[t]}, interior(triangles_[t]))) any = true;
      if (!any) break;
    }
  }

 private:
  // The boundary triangles whose interior nodes lie on one face, and their edges.
  void collect() {
    for (const ElementBlock& b : mesh_.blocks) {
      if (b.type != CellType::Triangle || b.order < 2) continue;
      order_ = b.order;
      const ReferenceElement& ref = ReferenceElement::get(CellType::Triangle, order_);
      const auto count = static_cast<std::size_t>(ref.numNodes());
      for (std::size_t e = 0; e < b.count(); ++e) {
        BoundaryTriangle t;
        t.nodes.resize(count);
        const std::int64_t* v = b.element(e);
        for (std::size_t n = 0; n < count; ++n) {
          const LatticePoint& l = ref.lattice()[n];
          t.nodes[static_cast<std::size_t>(latticeIndex(order_, l[0], l[1]))] = v[n];
        }
        // The face: the interior's (order 3 and up), else that of an edge node inside a face.
        std::vector<int> inner;
        for (int j = 1; j < order_; ++j)
          for (int i = 1; i + j < order_; ++i) inner.push_back(latticeIndex(order_, i, j));
        t.face = 0;
        for (const int side : {0, 1, 2})
          for (const int k : edgeSlots(order_, side)) {
            const auto n = static_cast<std::size_t>(t.nodes[static_cast<std::size_t>(k)]);
            if (mesh_.nodeCadDim[n] == 2) t.face = mesh_.nodeCadIndex[n];
          }
        if (!inner.empty()) {
          const auto first =
              static_cast<std::size_t>(t.nodes[static_cast<std::size_t>(inner.front())]);
          t.face = mesh_.nodeCadDim[first] == 2 ? mesh_.nodeCadIndex[first] : 0;
        }
        // On a plane every triangle already lies in the face: nothing to fit.
        if (t.face == 0 || cad_.isPlanar(t.face) || !onFace(t.nodes, inner, t.face)) continue;
        const std::size_t index = triangles_.size();
        for (int side = 0; side < 3; ++side) {
          const std::int64_t c0 = t.nodes[static_cast<std::size_t>(corner(side))];
          const std::int64_t c1 = t.nodes[static_cast<std::size_t>(corner((side + 1) % 3))];
          edges_[{std::min(c0, c1), std::max(c0, c1)}].emplace_back(index, side);
        }
        triangles_.push_back(std::move(t));
      }
    }
    collectStars();
  }

  // The vertices inside a face whose star of triangles is closed on it (every side at the vertex
  // shared by two of them), with each triangle's corner at the vertex.
  void collectStars() {
    std::map<std::int64_t, std::vector<std::pair<std::size_t, int>>> stars;
    for (std::size_t t = 0; t < triangles_.size(); ++t)
      for (int c = 0; c < 3; ++c)
        stars[triangles_[t].nodes[static_cast<std::size_t>(corner(c))]].emplace_back(t, c);
    for (auto& [vertex, star] : stars) {
      const auto v = static_cast<std::size_t>(vertex);
      const int face = triangles_[star.front().first].face;
      if (mesh_.nodeCadDim[v] != 2 || mesh_.nodeCadIndex[v] != face ||
          !std::isfinite(mesh_.nodeCadParam[2 * v]))
        continue;
      std::map<std::int64_t, int> spokes;  // the far end of each side at the vertex: its count
      bool closed = true;
      for (const auto& [t, c] : star) {
        const BoundaryTriangle& tri = triangles_[t];
        closed = closed && tri.face == face;
        for (const int side : {c, (c + 2) % 3}) {
          closed = closed && onFace(tri.nodes, edgeSlots(order_, side), face);
          const int far = side == c ? (c + 1) % 3 : (c + 2) % 3;
          ++spokes[tri.nodes[static_cast<std::size_t>(corner(far))]];
        }
      }
      for (const auto& [w, count] : spokes) closed = closed && count == 2;
      if (closed) stars_.emplace(vertex, std::move(star));
    }
  }

  int corner(int c) const {
    return c == 0   ? latticeIndex(order_, 0, 0)
           : c == 1 ? latticeIndex(order_, order_, 0)
                    : latticeIndex(order_, 0, order_);
  }

  bool onFace(const std::vector<std::int64_t>& nodes, const std::vector<int>& slots,
              int face) const {
    return std::all_of(slots.begin(), slots.end(), [&](int k) {
      const auto n = static_cast<std::size_t>(nodes[static_cast<std::size_t>(k)]);
      return mesh_.nodeCadDim[n] == 2 && mesh_.nodeCadIndex[n] == face &&
             std::isfinite(mesh_.nodeCadParam[2 * n]);
    });
  }

  std::vector<std::int64_t> interior(const BoundaryTriangle& t) const {
    std::vector<std::int64_t> nodes;
    for (int j = 1; j < order_; ++j)
      for (int i = 1; i + j < order_; ++i)
        nodes.push_back(t.nodes[static_cast<std::size_t>(latticeIndex(order_, i, j))]);
    return nodes;
  }

  const FaceChart& chart(int face) {
    auto it = charts_.find(face);
    if (it == charts_.end()) it = charts_.try_emplace(face, cad_, face).first;
    return it->second;
  }

  Eigen::Vector3d point(std::int64_t node) const {
    const auto n = static_cast<std::size_t>(node);
    return {mesh_.xyz[3 * n], mesh_.xyz[3 * n + 1], mesh_.xyz[3 * n + 2]};
  }

  // The largest squared sine of one triangle as it is (Fit::largestSine).
  double largestSine(const BoundaryTriangle& t) {
    Patch patch = makePatch({&t}, {});
    return Fit(chart(t.face), order_, std::move(patch)).largestSine();
  }

  // The patch of `triangles` (one face), `free` its moving nodes; `slot` receives each node's.
  Patch makePatch(const std::vector<const BoundaryTriangle*>& triangles,
                  const std::vector<std::int64_t>& free,
                  std::map<std::int64_t, int>* slots = nullptr) {
    const FaceChart& ch = chart(triangles.front()->face);
    std::map<std::int64_t, int> own;
    std::map<std::int64_t, int>& slot = slots != nullptr ? *slots : own;
    Patch patch;
    bool referenced = false;
    FaceParameter reference{};
    for (const BoundaryTriangle* t : triangles)
      for (const std::int64_t node : t->nodes) {
        const auto n = static_cast<std::size_t>(node);
        if (!referenced && mesh_.nodeCadDim[n] == 2 && mesh_.nodeCadIndex[n] == ch.face()) {
          reference = {mesh_.nodeCadParam[2 * n], mesh_.nodeCadParam[2 * n + 1]};
          referenced = true;
        }
      }
    const auto slotOf = [&](std::int64_t node) {
      const auto [it, added] = slot.try_emplace(node, static_cast<int>(patch.x.size()));
      if (added) {
        const auto n = static_cast<std::size_t>(node);
        patch.x.push_back(point(node));
        const bool onFace = mesh_.nodeCadDim[n] == 2 && mesh_.nodeCadIndex[n] == ch.face() &&
                            std::isfinite(mesh_.nodeCadParam[2 * n]);
        patch.uv.push_back(
            onFace ? ch.unwrapNear({mesh_.nodeCadParam[2 * n], mesh_.nodeCadParam[2 * n + 1]},
                                   reference)
                   : reference);
        patch.onFace.push_back(onFace ? 1 : 0);
        patch.free.push_back(0);
      }
      return it->second;
    };
    for (const BoundaryTriangle* t : triangles) {
      std::vector<int> slotsOfTriangle;
      for (const std::int64_t n : t->nodes) slotsOfTriangle.push_back(slotOf(n));
      patch.triangles.push_back(std::move(slotsOfTriangle));
    }
    for (const std::int64_t n : free) patch.free[static_cast<std::size_t>(slot.at(n))] = 1;
    return patch;
  }

  // Fits the `free` nodes of `triangles` (one face) and writes them back where F falls by
  // kKeptFall and every free node stays inside the face's trimming; with `holdLargest`, only
  // where the largest angle at the report's points (checkedLargest) does not rise either.
  bool fit(const std::vector<const BoundaryTriangle*>& triangles, std::vector<std::int64_t> free,
           bool holdLargest = false) {
    if (frozen_ != nullptr)
      free.erase(std::remove_if(
                     free.begin(), free.end(),
                     [&](std::int64_t n) { return (*frozen_)[static_cast<std::size_t>(n)] != 0; }),
                 free.end());
    if (free.empty()) return false;
    const FaceChart& ch = chart(triangles.front()->face);
    std::map<std::int64_t, int> slot;
    Patch patch = makePatch(triangles, free, &slot);
    const TriangleFit result = Fit(ch, order_, std::move(patch)).run();
    if (!(result.after < kKeptFall * result.before)) return false;
    if (holdLargest && !(result.largestAfter <= result.largestBefore)) return false;
    for (const std::int64_t n : free)
      if (!ch.contains(result.uv[static_cast<std::size_t>(slot.at(n))])) return false;
    const double largestBefore = holdLargest ? checkedLargest(triangles) : 0.0;
    std::vector<double> xyz, param;
    for (const std::int64_t node : free) {
      const auto n = static_cast<std::size_t>(node);
      xyz.insert(xyz.end(), mesh_.xyz.begin() + 3 * n, mesh_.xyz.begin() + 3 * n + 3);
      param.insert(param.end(), mesh_.nodeCadParam.begin() + 2 * n,
                   mesh_.nodeCadParam.begin() + 2 * n + 2);
    }
    for (const std::int64_t node : free) {
      const FaceParameter& uv = result.uv[static_cast<std::size_t>(slot.at(node))];
      const Eigen::Vector3d x = ch.point(uv);
      const FaceParameter stored = ch.wrap(uv);
      const auto n = static_cast<std::size_t>(node);
      for (int c = 0; c < 3; ++c) mesh_.xyz[3 * n + c] = x[c];
      mesh_.nodeCadParam[2 * n] = stored[0];
      mesh_.nodeCadParam[2 * n + 1] = stored[1];
    }
    // Where the points the report samples see a larger angle than before (its corners: a
    // vertex patch tilts them, and the fit's rule has no point there), the patch goes back.
    if (holdLargest && !(checkedLargest(triangles) <= largestBefore)) {
      for (std::size_t i = 0; i < free.size(); ++i) {
        const auto n = static_cast<std::size_t>(free[i]);
        for (std::size_t c = 0; c < 3; ++c) mesh_.xyz[3 * n + c] = xyz[3 * i + c];
        for (std::size_t c = 0; c < 2; ++c) mesh_.nodeCadParam[2 * n + c] = param[2 * i + c];
      }
      return false;
    }
    return true;
  }

  // A node inside the volume that a vertex drags: its share of the vertex's moves (the vertex's
  // barycentric coordinate at the node in a tetrahedron around it).
  struct Dragged {
    std::int64_t node = 0;
    double share = 0.0;
  };

  // Per vertex in `vertices`: the nodes of the tetrahedra around it that lie inside the volume
  // (nodeCadDim 3) with a share above zero. A vertex with another cell around it (a layer's
  // prism, a pyramid) drags none, and a node two of them would drag (on a tetrahedron's edge
  // between them) stays: each patch is put back alone.
  std::map<std::int64_t, std::vector<Dragged>> draggedNodes(
      const std::vector<std::int64_t>& vertices) const {
    std::map<std::int64_t, std::map<std::int64_t, double>> shares;
    for (const std::int64_t v : vertices) shares[v];
    std::vector<std::int64_t> mixed;
    for (const ElementBlock& b : mesh_.blocks) {
      if (cellDimension(b.type) != 3) continue;
      const auto corners = static_cast<std::size_t>(cellNumVertices(b.type));
      const ReferenceElement* ref =
          b.type == CellType::Tetrahedron ? &ReferenceElement::get(b.type, b.order) : nullptr;
      const auto count = static_cast<std::size_t>(b.nodesPerElement());
      for (std::size_t e = 0; e < b.count(); ++e) {
        const std::int64_t* nodes = b.element(e);
        for (std::size_t c = 0; c < corners; ++c) {
          const auto it = shares.find(nodes[c]);
          if (it == shares.end()) continue;
          if (ref == nullptr) {
            mixed.push_back(nodes[c]);
            continue;
          }
          for (std::size_t k = corners; k < count; ++k) {
            const int share = simplexBarycentric(ref->lattice()[k], 3, b.order)[c];
            const auto n = static_cast<std::size_t>(nodes[k]);
            if (share > 0 && mesh_.nodeCadDim[n] == 3)
              it->second[nodes[k]] = static_cast<double>(share) / b.order;
          }
        }
      }
    }
    for (const std::int64_t v : mixed) shares.erase(v);
    std::map<std::int64_t, int> draggers;
    for (const auto& [v, nodes] : shares)
      for (const auto& [n, share] : nodes) ++draggers[n];
    std::map<std::int64_t, std::vector<Dragged>> dragged;
    for (const auto& [v, nodes] : shares)
      for (const auto& [n, share] : nodes)
        if (draggers[n] == 1) dragged[v].push_back({n, share});
    return dragged;
  }

  // The largest squared sine of `triangles` (one face) at the report's points.
  double checkedLargest(const std::vector<const BoundaryTriangle*>& triangles) {
    Patch patch = makePatch(triangles, {});
    return Fit(chart(triangles.front()->face), order_, std::move(patch), true).largestSine();
  }

  Mesh& mesh_;
  const CadModel& cad_;
  const std::vector<char>* frozen_ = nullptr;
  int order_ = 0;
  std::vector<BoundaryTriangle> triangles_;
  // Per edge (its corners, sorted): the triangles on it and the side it is of each.
  std::map<std::pair<std::int64_t, std::int64_t>, std::vector<std::pair<std::size_t, int>>> edges_;
  // Per vertex inside a face with a closed star (collectStars): its triangles and their corner.
  std::map<std::int64_t, std::vector<std::pair<std::size_t, int>>> stars_;
  std::map<int, FaceChart> charts_;
};

BoundaryFitter::BoundaryFitter(Mesh& mesh, const CadModel& cad)
    : impl_(std::make_unique<Impl>(mesh, cad)) {}
BoundaryFitter::~BoundaryFitter() = default;
std::size_t BoundaryFitter::triangles() const {
  return impl_->triangles();
}
std::vector<double> BoundaryFitter::largestSines(const std::vector<char>* which) {
  return impl_->largestSines(which);
}
std::vector<char> BoundaryFitter::touching(const std::vector<char>& nodes) const {
  return impl_->touching(nodes);
}
void BoundaryFitter::fit(const std::vector<char>& active, const std::vector<char>* frozen) {
  impl_->fit(active, frozen);
}
std::vector<std::int64_t> BoundaryFitter::starVertices() const {
  return impl_->starVertices();
}
std::vector<std::size_t> BoundaryFitter::starOf(std::int64_t vertex) const {
  return impl_->starOf(vertex);
}
std::vector<std::vector<std::int64_t>> BoundaryFitter::fitVertices(
    const std::vector<std::int64_t>& vertices, const std::vector<char>* frozen) {
  return impl_->fitVertices(vertices, frozen);
}

}  // namespace homesh

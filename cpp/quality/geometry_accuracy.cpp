#include "quality/geometry_accuracy.hpp"
#include "core/thread_count.hpp"

#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <optional>
#include <vector>

#include "core/error.hpp"
#include "core/first_failure.hpp"
#include "element/quadrature.hpp"
#include "element/reference_element.hpp"

namespace homesh {
namespace {

constexpr double kPi = 3.14159265358979323846;

// Where a block's cells are sampled: quadrature points of degree 2P + 2, then the nodes.
struct Sampling {
  int dim = 0;
  Eigen::MatrixXd values;                 // samples x nodes
  std::array<Eigen::MatrixXd, 2> grads;   // d/dxi_k of the basis, samples x nodes
  std::vector<std::vector<int>> nearest;  // per sample: nodes by reference distance
};

Sampling makeSampling(CellType type, int order) {
  const ReferenceElement& ref = ReferenceElement::get(type, order);
  const QuadratureRule rule = quadratureRule(type, 2 * order + 2);
  const int dim = ref.dim(), nodes = ref.numNodes(), count = rule.size() + nodes;
  const Eigen::MatrixXd points = pointRows(rule, ref.nodes());

  Sampling s;
  s.dim = dim;
  s.values.resize(count, nodes);
  for (int k = 0; k < dim; ++k) s.grads[k].resize(count, nodes);
  Eigen::VectorXd values;
  Eigen::MatrixXd gradients;
  for (int i = 0; i < count; ++i) {
    const Eigen::VectorXd xi = points.row(i).transpose();
    ref.evaluate(xi.data(), values, gradients);
    s.values.row(i) = values.transpose();
    for (int k = 0; k < dim; ++k) s.grads[k].row(i) = gradients.col(k).transpose();
    std::vector<int> byDistance(static_cast<std::size_t>(nodes));
    std::iota(byDistance.begin(), byDistance.end(), 0);
    std::stable_sort(byDistance.begin(), byDistance.end(), [&](int a, int b) {
      return (ref.nodes().row(a) - points.row(i)).squaredNorm() <
             (ref.nodes().row(b) - points.row(i)).squaredNorm();
    });
    s.nearest.push_back(std::move(byDistance));
  }
  return s;
}

// One cell's share of the result, summarised in cell order afterwards (thread-count independent).
struct CellRecord {
  std::size_t samples = 0, angleSamples = 0, undefined = 0;
  double maxDistance = -1.0, sumDistance = 0.0;
  double maxAngle = -1.0, sumAngle = 0.0;  // radians
  Eigen::Vector3d distancePoint = Eigen::Vector3d::Zero(), anglePoint = Eigen::Vector3d::Zero();

  void addDistance(double d, const Eigen::Vector3d& x) {
    ++samples;
    sumDistance += d;
    if (d > maxDistance) {
      maxDistance = d;
      distancePoint = x;
    }
  }
  void addAngle(double a, const Eigen::Vector3d& x) {
    ++angleSamples;
    sumAngle += a;
    if (a > maxAngle) {
      maxAngle = a;
      anglePoint = x;
    }
  }
};

// Unsigned angle between two lines with directions a and b, accurate near 0 (unlike acos).
double lineAngle(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), std::abs(a.dot(b)));
}

bool finite(double x) {
  return std::isfinite(x);
}

// Parameters on curve `edge` of the cell's nodes, where they are known.
std::vector<std::optional<double>> curveGuesses(const Mesh& mesh, const std::int64_t* nodes, int n,
                                                int edge, const CadModel& cad) {
  std::vector<std::optional<double>> guess(static_cast<std::size_t>(n));
  std::optional<double> any;
  for (int i = 0; i < n; ++i) {
    const std::int64_t id = nodes[i];
    const double t = mesh.nodeCadParam[2 * id];
    if (mesh.nodeCadDim[id] == 1 && mesh.nodeCadIndex[id] == edge && finite(t)) any = guess[i] = t;
  }
  for (int i = 0; i < n; ++i) {
    const std::int64_t id = nodes[i];
    if (mesh.nodeCadDim[id] != 0 || mesh.nodeCadIndex[id] < 1) continue;
    try {  // a vertex of a closed curve has two parameters: take the one near the others
      guess[i] = cad.vertexParameter(mesh.nodeCadIndex[id], edge, any);
    } catch (const CadError&) {
      // not a vertex of this edge (inconsistent classification): no guess from this node
    }
  }
  return guess;
}

// Parameters on face `face` of the cell's nodes: their own (u, v), or through the p-curve of
// the CAD curve they lie on.
std::vector<std::optional<std::array<double, 2>>> faceGuesses(const Mesh& mesh,
                                                              const std::int64_t* nodes, int n,
                                                              int face, const CadModel& cad) {
  std::vector<std::optional<std::array<double, 2>>> guess(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const std::int64_t id = nodes[i];
    const double a = mesh.nodeCadParam[2 * id], b = mesh.nodeCadParam[2 * id + 1];
    const int index = mesh.nodeCadIndex[id];
    if (mesh.nodeCadDim[id] == 2 && index == face && finite(a) && finite(b)) {
      guess[i] = std::array<double, 2>{a, b};
    } else if (mesh.nodeCadDim[id] == 1 && index >= 1 && finite(a)) {
      try {
        guess[i] = cad.edgeParameterOnFace(index, face, a);
      } catch (const CadError&) {
        // the curve does not bound this face: no guess from this node
      }
    }
  }
  return guess;
}

template <typename T>
std::optional<T> nearestGuess(const std::vector<int>& nearest,
                              const std::vector<std::optional<T>>& guess) {
  for (const int i : nearest)
    if (guess[static_cast<std::size_t>(i)]) return guess[static_cast<std::size_t>(i)];
  return std::nullopt;
}

// A curve's typical speed |dC/dt|: the larger half-chord over half the parameter range (a
// closed curve's full chord is 0).
double typicalSpeed(const CadModel& cad, int edge) {
  const ParameterRange r = cad.edgeRange(edge);
  const double mid = 0.5 * (r.first + r.last);
  const Eigen::Vector3d a = cad.evaluateCurve(edge, r.first).point;
  const Eigen::Vector3d b = cad.evaluateCurve(edge, mid).point;
  const Eigen::Vector3d c = cad.evaluateCurve(edge, r.last).point;
  return std::max((b - a).norm(), (c - b).norm()) / (0.5 * (r.last - r.first));
}

// Samples one boundary cell lying on CAD entity (entityDim, entity); `speed`: the curve's
// typicalSpeed (curves only).
CellRecord sampleCell(const Mesh& mesh, const std::int64_t* nodes, int n, const Sampling& s,
                      int entityDim, int entity, double speed, const CadModel& cad) {
  Eigen::MatrixXd x(n, 3);
  for (int i = 0; i < n; ++i)
    for (int c = 0; c < 3; ++c) x(i, c) = mesh.xyz[3 * nodes[i] + c];
  CellRecord r;
  const auto samples = static_cast<int>(s.values.rows());
  if (entityDim == 2) {
    const auto guess = faceGuesses(mesh, nodes, n, entity, cad);
    for (int q = 0; q < samples; ++q) {
      const Eigen::Vector3d p = (s.values.row(q) * x).transpose();
      const SurfaceProjection proj =
          cad.projectOnSurface(entity, p, nearestGuess(s.nearest[q], guess));
      r.addDistance((p - proj.point).norm(), p);
      const Eigen::Vector3d t1 = (s.grads[0].row(q) * x).transpose();
      const Eigen::Vector3d t2 = (s.grads[1].row(q) * x).transpose();
      const SurfaceDerivatives d = cad.evaluateSurface(entity, proj.u, proj.v);
      const std::optional<Eigen::Vector3d> m = d.normalDirection();
      if (!m) {
        ++r.undefined;
        continue;
      }
      const Eigen::Vector3d normal = t1.cross(t2);
      r.addAngle(normal.norm() > 1e-12 * t1.norm() * t2.norm() ? lineAngle(normal, *m) : 0.5 * kPi,
                 p);
    }
  } else {
    const auto guess = curveGuesses(mesh, nodes, n, entity, cad);
    // In 3D (and on a surface mesh) curves only bound faces: distance only.
    const bool angle = mesh.dim == 2 && !mesh.isSurface();
    for (int q = 0; q < samples; ++q) {
      const Eigen::Vector3d p = (s.values.row(q) * x).transpose();
      const CurveProjection proj = cad.projectOnCurve(entity, p, nearestGuess(s.nearest[q], guess));
      r.addDistance((p - proj.point).norm(), p);
      if (!angle) continue;
      const Eigen::Vector3d c = cad.evaluateCurve(entity, proj.t).d1;
      // Where the speed nearly vanishes (a cosine-spaced aerofoil's trailing edge) the tangent's
      // direction is the CAD fit's error (|dC/dt| ~ 3e-7 there, direction arbitrary): undefined
      // below a thousandth of the typical speed.
      if (!(c.norm() > 1e-3 * speed) || !c.allFinite()) {
        ++r.undefined;
        continue;
      }
      const Eigen::Vector3d t = (s.grads[0].row(q) * x).transpose();
      r.addAngle(t.norm() > 0.0 ? lineAngle(t, c) : 0.5 * kPi, p);
    }
  }
  return r;
}

}  // namespace

GeometryAccuracy measureGeometryAccuracy(const Mesh& mesh, const CadModel& cad, int threads) {
  threads = threadsToUse(threads);
  GeometryAccuracy result;
  result.diagonal = cad.boundingDiagonal();
  std::vector<CadModel> perThread;  // CadModel's caches are not thread-safe
  perThread.reserve(static_cast<std::size_t>(threads));
  for (int t = 0; t < threads; ++t) perThread.push_back(cad.clone());

  double sumDistance = 0.0, sumAngle = 0.0, maxAngle = -1.0;
  result.maxDistance = -1.0;
  for (const ElementBlock& block : mesh.blocks) {
    const int cellDim = cellDimension(block.type);
    // A surface mesh's elements are themselves on CAD faces: measured like a volume's
    // boundary triangles.
    const bool onFaces = mesh.isSurface() && cellDim == 2;
    if (cellDim == 0 || (cellDim >= mesh.dim && !onFaces) || block.count() == 0) continue;
    const int entityDim = cellDim;  // faces carry faces, lines carry curves
    const int entities = entityDim == 2 ? cad.numFaces() : cad.numEdges();
    for (const std::int32_t entity : block.entity)
      if (entity < 1 || entity > entities)
        throw Error("geometry accuracy: a boundary " + cellShortName(block.type) + " lies on " +
                    cadEntityName(entityDim, entity) + " but " + cad.sourceName() + " has " +
                    std::to_string(entities) + (entityDim == 2 ? " faces" : " edges"));
    const Sampling sampling = makeSampling(block.type, block.order);
    std::vector<double> speeds(static_cast<std::size_t>(entities) + 1, 0.0);
    if (entityDim == 1 && mesh.dim == 2 && !mesh.isSurface())  // the tangent angle needs them
      for (const std::int32_t entity : block.entity)
        if (speeds[static_cast<std::size_t>(entity)] == 0.0 && !cad.isDegenerated(entity))
          speeds[static_cast<std::size_t>(entity)] = typicalSpeed(cad, entity);
    const int n = block.nodesPerElement();
    const auto count = static_cast<std::int64_t>(block.count());
    std::vector<CellRecord> records(block.count());
    FirstFailure failure;
#pragma omp parallel for num_threads(threads) schedule(dynamic, 16)
    for (std::int64_t e = 0; e < count; ++e) {
      try {
        const CadModel& local = perThread[static_cast<std::size_t>(omp_get_thread_num())];
        const int entity = block.entity[static_cast<std::size_t>(e)];
        // A degenerated edge (a sphere's pole) is a point: lines on it have no curve to follow.
        if (entityDim == 1 && local.isDegenerated(entity)) continue;
        records[static_cast<std::size_t>(e)] =
            sampleCell(mesh, block.element(static_cast<std::size_t>(e)), n, sampling, entityDim,
                       entity, speeds[static_cast<std::size_t>(entity)], local);
      } catch (...) {
        failure.capture();
      }
    }
    failure.rethrow();
    for (std::size_t e = 0; e < block.count(); ++e) {
      const CellRecord& r = records[e];
      result.samples += r.samples;
      result.angleSamples += r.angleSamples;
      result.undefinedNormals += r.undefined;
      sumDistance += r.sumDistance;
      sumAngle += r.sumAngle;
      if (r.samples > 0 && r.maxDistance > result.maxDistance) {
        result.maxDistance = r.maxDistance;
        result.worstEntity = cadEntityName(entityDim, block.entity[e]);
        result.worstPoint = r.distancePoint;
      }
      if (r.angleSamples > 0 && r.maxAngle > maxAngle) {
        maxAngle = r.maxAngle;
        result.worstAngleEntity = cadEntityName(entityDim, block.entity[e]);
        result.worstAnglePoint = r.anglePoint;
      }
    }
  }
  result.maxDistance = std::max(result.maxDistance, 0.0);
  if (result.samples > 0) result.meanDistance = sumDistance / static_cast<double>(result.samples);
  const double degrees = 180.0 / kPi;
  if (result.angleSamples > 0) {
    result.maxAngleDeg = maxAngle * degrees;
    result.meanAngleDeg = sumAngle / static_cast<double>(result.angleSamples) * degrees;
  }
  return result;
}

}  // namespace homesh

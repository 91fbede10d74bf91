#include "pipeline/boundary_fidelity.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include "curving/face_fidelity_fit.hpp"

namespace homesh {
namespace {

// The trade against the worst element: no element may end more than this fraction below the
// lower of its own value and the mesh's worst before the stage: the certified measure's own
// resolution (its Jacobian bounds are refined to 1e-3 of the largest |J|,
// quality/bezier_jacobian.hpp), so the mesh's worst does not measurably fall. On the sphere in a
// box at size 0.8, order 6, the worst element went 0.4329 -> 0.4325 for a fit that took the
// largest normal angle from 0.022 to 0.0014 degrees; with no loss at all its nodes stayed and so
// did the angle. (Allowing 1 % cost the long and the bent cylinder 0.6 and 0.8 % of their worst
// for no change in their largest angle.)
constexpr double kWorstLoss = 1e-3;
// Fits per tier at most: after each, the moved nodes of elements that broke the promise go back
// and are frozen there, and the patches around them are fitted again; then the tier is undone.
constexpr int kFreezeRounds = 6;
// A tier: the triangles not fitted yet whose largest normal angle is at least half the largest
// among them (squared sines: a quarter). Tiers are fitted from the largest angles down, and the
// stage stops once a triangle next to a frozen node (the volume held it) keeps an angle at least
// as large as any left to fit: the largest angle is held there. Why tiers and that stop: the
// largest angle is what the fit is for, and fitting every triangle costs as much as the optimiser
// on a boundary of many alike triangles (a cylinder of radius 1 and length 1000 at order 4: 38,349
// triangles in 45 s, where the optimiser took 32 s) while the largest angle stays where the volume
// holds it (0.61 -> 0.55 degrees there).
constexpr double kTierShare = 0.25;
// At most this many triangles a tier, or this share of the boundary's if more: on the cylinder
// above, the first tier's 11,383 triangles took 7 s and the frozen nodes then kept the largest
// angle where it was.
constexpr std::size_t kTierTriangles = 64;
constexpr double kTierFraction = 0.01;
// Rounds of vertex patches after the tiers (fitVertexStars) at most, and patches a round at most.
constexpr int kVertexRounds = 8;
constexpr std::size_t kVertexPatches = 8;

// A verdict's rank: a change to a lower one is a worse verdict.
int rank(Validity v) {
  return v == Validity::Valid ? 2 : v == Validity::Undecided ? 1 : 0;
}

// Whether element e's new verdict keeps the stage's promise (header): no worse verdict, and a
// value at most kWorstLoss of its size below the lower of its own and the mesh's worst (negative
// values included: an element left invalid by the repair rounds may not fall either).
bool keeps(const QualitySummary& before, const QualitySummary& after, std::size_t e) {
  if (rank(after.validity[e]) < rank(before.validity[e])) return false;
  const double floor = std::min(before.scaledJacobian[e], before.scaled.min);
  return after.scaledJacobian[e] >= floor - kWorstLoss * std::abs(floor);
}

// Per node: whether its position in `now` differs from that in `reference`.
std::vector<char> movedNodes(const std::vector<double>& now, const std::vector<double>& reference) {
  std::vector<char> moved(now.size() / 3, 0);
  for (std::size_t i = 0; i < now.size(); ++i)
    if (now[i] != reference[i]) moved[i / 3] = 1;
  return moved;
}

// The largest finite entry of `sines` among the triangles set in `which` (0 if none).
double largestOf(const std::vector<double>& sines, const std::vector<char>& which) {
  double largest = 0.0;
  for (std::size_t t = 0; t < sines.size(); ++t)
    if (which[t] != 0 && std::isfinite(sines[t])) largest = std::max(largest, sines[t]);
  return largest;
}

// Per entry: 1 where `values` holds `value`, else 0.
std::vector<char> valued(const std::vector<char>& values, char value) {
  std::vector<char> out(values.size(), 0);
  for (std::size_t i = 0; i < values.size(); ++i) out[i] = values[i] == value ? 1 : 0;
  return out;
}

// Per node: 2 for the nodes of prisms, pyramids and hexahedra (a boundary layer's, whose heights
// are measured from its wall: they stay), else 0 (1 marks the nodes the certification freezes).
std::vector<char> layerNodes(const Mesh& mesh) {
  std::vector<char> nodes(mesh.numNodes(), 0);
  for (const ElementBlock& b : mesh.blocks) {
    if (cellDimension(b.type) != 3 || b.type == CellType::Tetrahedron) continue;
    for (const std::int64_t n : b.nodes) nodes[static_cast<std::size_t>(n)] = 2;
  }
  return nodes;
}

// The stage's state between tiers: the quality at its input (the promise's reference), the nodes
// that stay (layer cells') or were frozen by the certification, and the quality last measured
// with the positions it measured.
class TierFitter {
 public:
  TierFitter(Mesh& mesh, QualitySummary& quality, const CadModel& cad, int threads,
             BoundaryFitRecord& record)
      : mesh_(mesh),
        quality_(quality),
        threads_(threads),
        record_(record),
        fitter_(mesh, cad),
        inputQuality_(quality),
        measuredXyz_(mesh.xyz),
        frozen_(layerNodes(mesh)) {}

  BoundaryFitter& fitter() { return fitter_; }
  Mesh& mesh() { return mesh_; }
  const std::vector<char>& frozen() const { return frozen_; }

  // Fits the triangles set in `tier`, certifies, freezes and fits again (kFreezeRounds); on
  // success the mesh and quality_ hold the result, otherwise the tier is undone. Returns whether
  // it was kept.
  bool fitTier(std::vector<char> active) {
    const std::vector<double> xyz = mesh_.xyz, param = mesh_.nodeCadParam;
    const std::vector<char> frozenBefore = frozen_;
    const QualitySummary qualityBefore = quality_;
    for (int round = 0; round < kFreezeRounds; ++round) {
      fitter_.fit(active, &frozen_);
      const KnownQuality known{&mesh_, &measuredXyz_, &quality_, {}};
      QualitySummary after = evaluateQuality(mesh_, threads_, &known);
      record_.remeasured += after.scaledJacobian.size() - after.known;
      measuredXyz_ = mesh_.xyz;
      const std::vector<char> newlyFrozen = breakers(after, movedNodes(mesh_.xyz, xyz));
      quality_ = std::move(after);
      if (newlyFrozen.empty()) return true;
      for (std::size_t node = 0; node < mesh_.numNodes(); ++node) {
        if (newlyFrozen[node] == 0) continue;
        frozen_[node] = 1;
        for (int c = 0; c < 3; ++c) mesh_.xyz[3 * node + c] = xyz[3 * node + c];
        for (int c = 0; c < 2; ++c) mesh_.nodeCadParam[2 * node + c] = param[2 * node + c];
      }
      active = fitter_.touching(newlyFrozen);
    }
    // No round kept every element: the mesh as the tier found it, and its quality.
    mesh_.xyz = xyz;
    mesh_.nodeCadParam = param;
    frozen_ = frozenBefore;
    quality_ = qualityBefore;
    measuredXyz_ = xyz;
    return false;
  }

  // Fits the patches of `vertices` (no two in one triangle), certifies, and puts back every
  // patch with a node in an element that breaks the promise, certifying again until none does
  // (each pass puts back at least one patch). Returns the vertices whose patch was kept.
  std::vector<std::int64_t> fitVertices(const std::vector<std::int64_t>& vertices) {
    const std::vector<double> xyz = mesh_.xyz, param = mesh_.nodeCadParam;
    std::vector<std::vector<std::int64_t>> kept = fitter_.fitVertices(vertices, &frozen_);
    if (std::all_of(kept.begin(), kept.end(), [](const auto& k) { return k.empty(); })) return {};
    std::vector<int> owner(mesh_.numNodes(), -1);
    for (std::size_t i = 0; i < kept.size(); ++i)
      for (const std::int64_t n : kept[i]) owner[static_cast<std::size_t>(n)] = static_cast<int>(i);
    while (true) {
      const KnownQuality known{&mesh_, &measuredXyz_, &quality_, {}};
      QualitySummary after = evaluateQuality(mesh_, threads_, &known);
      record_.remeasured += after.scaledJacobian.size() - after.known;
      measuredXyz_ = mesh_.xyz;
      quality_ = std::move(after);
      std::vector<char> undo(kept.size(), 0);
      bool any = false;
      forEachBreaker(quality_, [&](const std::int64_t* v, std::size_t n) {
        for (std::size_t k = 0; k < n; ++k) {
          const int i = owner[static_cast<std::size_t>(v[k])];
          if (i < 0) continue;
          undo[static_cast<std::size_t>(i)] = 1;
          any = true;
        }
      });
      if (!any) break;
      for (std::size_t i = 0; i < kept.size(); ++i) {
        if (undo[i] == 0) continue;
        for (const std::int64_t node : kept[i]) {
          const auto n = static_cast<std::size_t>(node);
          for (int c = 0; c < 3; ++c) mesh_.xyz[3 * n + c] = xyz[3 * n + c];
          for (int c = 0; c < 2; ++c) mesh_.nodeCadParam[2 * n + c] = param[2 * n + c];
          owner[n] = -1;
        }
        kept[i].clear();
      }
    }
    std::vector<std::int64_t> moved;
    for (std::size_t i = 0; i < kept.size(); ++i)
      if (!kept[i].empty()) moved.push_back(vertices[i]);
    return moved;
  }

 private:
  // Calls `visit(nodes, count)` for every element whose verdict in `after` breaks the promise
  // against the input's.
  template <typename Visit>
  void forEachBreaker(const QualitySummary& after, Visit&& visit) const {
    std::size_t e = 0;
    for (const ElementBlock& b : mesh_.blocks) {
      if (cellDimension(b.type) != mesh_.dim) continue;
      const auto n = static_cast<std::size_t>(b.nodesPerElement());
      for (std::size_t c = 0; c < b.count(); ++c, ++e)
        if (!keeps(inputQuality_, after, e)) visit(b.element(c), n);
    }
  }

  // The `moved` nodes of every element whose verdict `after` breaks the promise against the
  // input's; empty when none does (an element none of whose nodes moved is not the tier's doing).
  std::vector<char> breakers(const QualitySummary& after, const std::vector<char>& moved) const {
    std::vector<char> nodes(mesh_.numNodes(), 0);
    bool any = false;
    forEachBreaker(after, [&](const std::int64_t* v, std::size_t n) {
      for (std::size_t k = 0; k < n; ++k) {
        const auto node = static_cast<std::size_t>(v[k]);
        if (moved[node] == 0) continue;
        nodes[node] = 1;
        any = true;
      }
    });
    return any ? nodes : std::vector<char>{};
  }

  Mesh& mesh_;
  QualitySummary& quality_;
  int threads_;
  BoundaryFitRecord& record_;
  BoundaryFitter fitter_;
  const QualitySummary inputQuality_;
  std::vector<double> measuredXyz_;
  std::vector<char> frozen_;
};

// After the tiers, whose patches hold the triangles' corners: rounds of vertex patches
// (BoundaryFitter::fitVertices) around the triangles with the largest angles left: each vertex
// that stays free (not a layer's) whose star holds a triangle with at least a quarter
// (kTierShare) of the largest squared sine, largest first, no two in one triangle, at most
// kVertexPatches a round; a patch that breaks the promise is put back whole, and the rounds end
// after kVertexRounds, with no candidate, once one keeps none or once the largest angle does not
// fall. Why: an order-2 triangle's normal is set by its corners and edge nodes, and the
// optimiser's sliding leaves corners where an edge spans far more of a curved face than its
// neighbours; with the corners held the fit cannot shorten it. Why after the tiers, not within
// their rounds: a vertex reshapes every element around it, and frozen there by the
// certification (alone) its triangles were held and ended the stage: the thin cylinder's
// largest angle doubled.
void fitVertexStars(TierFitter& tiers, std::vector<double>& sines, const std::vector<char>& movable,
                    BoundaryFitRecord& record, const std::function<bool()>& stop) {
  BoundaryFitter& fitter = tiers.fitter();
  std::vector<std::int64_t> vertices = fitter.starVertices();
  for (int round = 0; round < kVertexRounds; ++round) {
    if (stop && stop()) {
      record.stopped = true;
      return;
    }
    const double largest = largestOf(sines, movable);
    if (!(largest > 0.0)) return;
    std::vector<std::pair<double, std::int64_t>> candidates;
    for (const std::int64_t v : vertices) {
      if (tiers.frozen()[static_cast<std::size_t>(v)] != 0) continue;
      double star = 0.0;
      for (const std::size_t t : fitter.starOf(v))
        if (std::isfinite(sines[t])) star = std::max(star, sines[t]);
      if (star >= kTierShare * largest) candidates.emplace_back(star, v);
    }
    std::sort(candidates.begin(), candidates.end(), [](const auto& a, const auto& b) {
      return a.first != b.first ? a.first > b.first : a.second < b.second;
    });
    // No two in one triangle, so that a patch put back takes no other's nodes with it.
    std::vector<char> blocked(sines.size(), 0);  // per triangle
    std::vector<std::int64_t> chosen;
    for (const auto& [star, v] : candidates) {
      const std::vector<std::size_t> triangles = fitter.starOf(v);
      if (std::any_of(triangles.begin(), triangles.end(),
                      [&](std::size_t t) { return blocked[t] != 0; }))
        continue;
      chosen.push_back(v);
      if (chosen.size() == kVertexPatches) break;
      // A neighbour's star shares a triangle with it (the two patches would share nodes).
      for (const std::size_t t : triangles) blocked[t] = 1;
    }
    if (chosen.empty()) return;
    const std::vector<double> before = tiers.mesh().xyz;
    const std::vector<std::int64_t> moved = tiers.fitVertices(chosen);
    record.verticesMoved += moved.size();
    if (moved.empty()) return;
    const std::vector<char> touched = fitter.touching(movedNodes(tiers.mesh().xyz, before));
    const std::vector<double> again = fitter.largestSines(&touched);
    for (std::size_t t = 0; t < sines.size(); ++t)
      if (touched[t] != 0) sines[t] = again[t];
    if (!(largestOf(sines, movable) < largest)) return;
  }
}

}  // namespace

BoundaryFitRecord fitBoundaryFidelity(Mesh& mesh, QualitySummary& quality, const CadModel& cad,
                                      int threads, const std::function<bool()>& stop) {
  BoundaryFitRecord record;
  if (mesh.dim != 3 || mesh.order < 2) return record;
  const std::vector<double> input = mesh.xyz;
  TierFitter tiers(mesh, quality, cad, threads, record);
  BoundaryFitter& fitter = tiers.fitter();
  record.triangles = fitter.triangles();
  if (record.triangles == 0) return record;
  std::vector<double> sines = fitter.largestSines();
  // A boundary layer's wall: triangles every node of which stays (none to fit, none held by the
  // certification), and those with a layer node (held there once tried: a far-field face's are
  // not, so the wall's angles do not end the stage before the rest is fitted).
  const std::vector<char> onLayer = fitter.touching(valued(tiers.frozen(), 2));
  const std::vector<char> movable = fitter.touching(valued(tiers.frozen(), 0));
  std::vector<char> untried(record.triangles, 0);
  for (std::size_t t = 0; t < record.triangles; ++t)
    untried[t] = movable[t] != 0 && std::isfinite(sines[t]) && sines[t] > 0.0 ? 1 : 0;
  const std::size_t capacity = std::max(
      kTierTriangles,
      static_cast<std::size_t>(std::ceil(kTierFraction * static_cast<double>(record.triangles))));
  while (true) {
    if (stop && stop()) {
      record.stopped = true;
      break;
    }
    const double reach = largestOf(sines, untried);
    if (!(reach > 0.0)) break;
    // A triangle next to a frozen node (the volume held it there) keeps an angle at least this
    // large: the largest angle is held, and further tiers would only spend time.
    std::vector<char> held = fitter.touching(valued(tiers.frozen(), 1));
    for (std::size_t t = 0; t < record.triangles; ++t)
      if (onLayer[t] != 0 && movable[t] != 0 && untried[t] == 0) held[t] = 1;
    if (largestOf(sines, held) >= reach) break;
    std::vector<std::size_t> candidates;
    for (std::size_t t = 0; t < record.triangles; ++t)
      if (untried[t] != 0 && sines[t] >= kTierShare * reach) candidates.push_back(t);
    const std::size_t count = std::min(candidates.size(), capacity);
    // Ties broken by number, so that the tier does not depend on the sort's implementation.
    std::partial_sort(candidates.begin(), candidates.begin() + static_cast<std::ptrdiff_t>(count),
                      candidates.end(), [&](std::size_t a, std::size_t b) {
                        return sines[a] != sines[b] ? sines[a] > sines[b] : a < b;
                      });
    std::vector<char> tier(record.triangles, 0);
    for (std::size_t k = 0; k < count; ++k) {
      tier[candidates[k]] = 1;
      untried[candidates[k]] = 0;
    }
    const std::vector<double> before = mesh.xyz;
    if (!tiers.fitTier(tier)) break;
    ++record.tiers;
    // The triangles a node of which moved (edge patches reach the tier's neighbours): measured
    // again.
    const std::vector<char> touched = fitter.touching(movedNodes(mesh.xyz, before));
    const std::vector<double> again = fitter.largestSines(&touched);
    for (std::size_t t = 0; t < record.triangles; ++t)
      if (touched[t] != 0) sines[t] = again[t];
  }
  if (!record.stopped) fitVertexStars(tiers, sines, movable, record, stop);
  const std::vector<char> fitted = fitter.touching(movedNodes(mesh.xyz, input));
  record.fitted = static_cast<std::size_t>(std::count(fitted.begin(), fitted.end(), 1));
  record.frozenNodes =
      static_cast<std::size_t>(std::count(tiers.frozen().begin(), tiers.frozen().end(), 1));
  return record;
}

}  // namespace homesh

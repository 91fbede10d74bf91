#include "sizing/sizing_octree.hpp"
#include "core/thread_count.hpp"

#include <BRepClass3d_SolidClassifier.hxx>
#include <BRepClass_FaceClassifier.hxx>
#include <algorithm>
#include <cmath>
#include <limits>
#include <queue>
#include <unordered_map>

#include <Eigen/Geometry>

#include "cad/cad_model.hpp"
#include "cad/model_dimension.hpp"
#include "cad/occt_access.hpp"
#include "core/error.hpp"
#include "core/first_failure.hpp"
#include "core/format.hpp"
#include "sizing/automatic_min_delta.hpp"
#include "sizing/wall_thickness.hpp"

namespace homesh {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kMaxLevel = 20;  // corner keys pack 21 bits per axis
constexpr int kMinLevel = 2;
constexpr std::size_t kMaxCandidates = 24;
constexpr int kGroupVotes = 15;
// A vote counts only where the direction from the nearest boundary sample to the leaf is at
// least this far from the sample's tangent plane (|cos| against its normal): seen past a
// face's rim, a far leaf's nearest sample can lie on the side wall, whose normal is then
// nearly perpendicular to the direction and its sign is chance (a cylinder of radius 0.01 and
// length 1 had its outside counted as inside, 3.2e3 times its volume).
constexpr double kDecidingCosine = 0.3;
// About 1 GB of octree: sizes that need more are refused (they would also make far more
// elements than a machine can hold).
constexpr std::size_t kMaxNodes =
    10'000'000;  // boundary samples judging a boundary leaf's sub-cells

gp_Pnt toGp(const Eigen::Vector3d& p) {
  return {p.x(), p.y(), p.z()};
}

// Bit k of c as a bool: the side along axis k of child or corner c.
bool bit(int c, int k) {
  return ((c >> k) & 1) != 0;
}

std::uint64_t cornerKey(std::int64_t i, std::int64_t j, std::int64_t k) {
  return (static_cast<std::uint64_t>(i) << 42) | (static_cast<std::uint64_t>(j) << 21) |
         static_cast<std::uint64_t>(k);
}

}  // namespace

// Builds a SizingOctree in stages; see sizing_octree.hpp for what each stage guarantees.
class OctreeBuilder {
 public:
  OctreeBuilder(const CadModel& cad, SizingOctree& tree, int threads)
      : cad_(cad), t_(tree), threads_(threadsToUse(threads)) {}

  void run() {
    prepareFrame();
    prepareRoot();
    std::vector<std::int32_t> allSamples(samples_.size()), allSources(t_.params_.sources.size());
    for (std::size_t i = 0; i < allSamples.size(); ++i)
      allSamples[i] = static_cast<std::int32_t>(i);
    for (std::size_t i = 0; i < allSources.size(); ++i)
      allSources[i] = static_cast<std::int32_t>(i);
    content_.push_back({std::move(allSamples), std::move(allSources)});
    std::vector<std::int32_t> work{0};
    while (!work.empty()) {
      const std::int32_t n = work.back();
      work.pop_back();
      if (wantsSplit(n)) {
        split(n);
        for (int c = 0; c < t_.children(); ++c) work.push_back(t_.nodes_[n].firstChild + c);
      }
    }
    balance();
    collectLeaves();
    findNeighbours();
    classify();
    grade();
    setCorners();
  }

 private:
  // Samples within the node's box widened by half their spacing (every boundary point lies
  // that close to a sample, so a leaf the boundary passes through always has one), and the sources
  // that may reach it.
  struct Content {
    std::vector<std::int32_t> samples, sources;
  };

  void prepareFrame() {
    Eigen::Vector3d normal(0.0, 0.0, 1.0);
    t_.dim_ = modelMeshDimension(cad_, normal);
    if (t_.dim_ == 2 && normal.isZero()) {  // a surface mesh: faces in 3D
      t_.dim_ = 3;
      t_.surface_ = true;
    }
    if (t_.dim_ == 2) {
      t_.origin_ = cad_.plane(1).first;
      const Eigen::Vector3d n = normal.normalized();
      int least = 0;
      for (int k = 1; k < 3; ++k)
        if (std::abs(n[k]) < std::abs(n[least])) least = k;
      const Eigen::Vector3d e1 = n.cross(Eigen::Vector3d::Unit(least)).normalized();
      t_.axes_.col(0) = e1;
      t_.axes_.col(1) = n.cross(e1);
      t_.axes_.col(2) = n;
    }
    // An automatic MinDelta is sampled at its floor and then set to what the samples ask for.
    SizingParameters sampling = t_.params_;
    sampling.minDelta = samplingMinDelta(t_.params_);
    t_.samples_ = sampleBoundary(cad_, t_.dim_, sampling);
    if (t_.samples_.empty())
      throw CadError(cad_.sourceName() + " has no boundary to size the mesh from");
    t_.stats_.thinWallSamples = applyThinWallSizes(t_.samples_, sampling, threads_);
    resolveAutomaticMinDelta(t_.samples_, t_.params_, t_.dim_);
    for (const BoundarySample& s : t_.samples_) {
      BoundarySample local = s;
      local.x = t_.toLocal(s.x);
      local.outward = t_.axes_.transpose() * s.outward;
      if (t_.dim_ == 2) local.x.z() = 0.0;
      samples_.push_back(local);
      if (s.delta > 0.0) ++t_.stats_.sizedSamples;
      if (s.narrowFace) ++t_.stats_.narrowFaceSamples;
    }
    t_.stats_.boundarySamples = samples_.size();
  }

  void prepareRoot() {
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(kInf), hi = -lo;
    for (const BoundarySample& s : samples_) {
      lo = lo.cwiseMin(s.x);
      hi = hi.cwiseMax(s.x);
    }
    geometryLo_ = lo;
    geometryHi_ = hi;
    const int d = t_.dim_;
    double extent = 0.0;
    for (int k = 0; k < d; ++k) extent = std::max(extent, hi[k] - lo[k]);
    SizingOctree::Node root;
    root.centre = 0.5 * (lo + hi);
    if (d == 2) root.centre.z() = 0.0;
    root.half = 0.5 * extent * 1.001 + 1e-9 * cad_.boundingDiagonal();
    t_.nodes_.push_back(root);
    // Leaves within the model's box are at most 2 maxDelta wide.
    double cells = 1.0;
    for (int k = 0; k < d; ++k)
      cells *= std::max(1.0, (hi[k] - lo[k]) / (2.0 * t_.params_.maxDelta));
    if (cells > double(kMaxNodes)) tooLarge();
  }

  Eigen::Vector3d halfVector(const SizingOctree::Node& n) const {
    return {n.half, n.half, t_.dim_ == 3 ? n.half : t_.nodes_[0].half};
  }

  bool separatesDomain(const BoundarySample& s) const { return !s.internal && s.weight > 0.0; }

  bool onDomainBoundary(const Content& c) const {
    return std::any_of(c.samples.begin(), c.samples.end(),
                       [&](std::int32_t s) { return separatesDomain(samples_[s]); });
  }

  bool wantsSplit(std::int32_t n) const {
    const SizingOctree::Node& node = t_.nodes_[n];
    if (node.level >= kMaxLevel) return false;
    if (node.level < kMinLevel) return true;
    const Content& c = content_[n];
    const SizingParameters& p = t_.params_;
    const double side = 2.0 * node.half;
    double smallest = kInf;
    for (const std::int32_t s : c.samples)
      if (samples_[s].delta > 0.0) smallest = std::min(smallest, samples_[s].delta);
    for (const std::int32_t s : c.sources) smallest = std::min(smallest, p.sources[s].delta);
    if (side > smallest) return true;
    if (!c.samples.empty() && side > p.maxDelta) return true;
    // Leaves within the model's box stay within twice maxDelta, so that the graded field is
    // resolved where elements are made.
    const Eigen::Vector3d half = halfVector(node);
    const bool nearModel =
        ((node.centre - half).array() <= geometryHi_.array()).head(t_.dim_).all() &&
        ((node.centre + half).array() >= geometryLo_.array()).head(t_.dim_).all();
    return nearModel && side > 2.0 * p.maxDelta;
  }

  [[noreturn]] void tooLarge() const {
    const SizingParameters& p = t_.params_;
    std::string culprit = "MinDelta " + formatNumber(p.minDelta) + " and MaxDelta " +
                          formatNumber(p.maxDelta) + " are";
    bool source = false;
    for (std::size_t i = 0; i < p.sources.size(); ++i)
      if (p.sources[i].delta < p.minDelta) {
        culprit =
            "refinement source " + std::to_string(i + 1) + " (" + p.sources[i].describe() + ") is";
        source = true;
        break;
      }
    throw OctreeTooLarge(culprit + " too small for " + cad_.sourceName() +
                             " (bounding-box diagonal " + formatNumber(cad_.boundingDiagonal()) +
                             "): the sizing octree would need more than " +
                             std::to_string(kMaxNodes) + " cells",
                         p.minDelta, source);
  }

  void split(std::int32_t n) {
    if (t_.nodes_.size() > kMaxNodes) tooLarge();
    const auto first = static_cast<std::int32_t>(t_.nodes_.size());
    const Eigen::Vector3d parentCentre = t_.nodes_[n].centre;
    const double h = 0.5 * t_.nodes_[n].half;
    const int parentLevel = t_.nodes_[n].level;
    const std::array<std::int32_t, 3> parentIndex = t_.nodes_[n].index;
    t_.nodes_[n].firstChild = first;
    for (int c = 0; c < t_.children(); ++c) {
      SizingOctree::Node child;
      child.level = parentLevel + 1;
      child.half = h;
      child.centre = parentCentre;
      for (int k = 0; k < t_.dim_; ++k) {
        const bool on = bit(c, k);
        child.centre[k] += on ? h : -h;
        child.index[k] = 2 * parentIndex[k] + (on ? 1 : 0);
      }
      t_.nodes_.push_back(child);
    }
    Content parentContent = std::move(content_[n]);
    content_[n] = Content{};
    content_.resize(t_.nodes_.size());
    // A sample goes to every child within half its spacing: per axis, the low side, the high
    // side or both (it already lies within that reach of the parent).
    for (const std::int32_t s : parentContent.samples) {
      const double reach = 0.5 * samples_[s].spacing;
      int low = 0, high = 0;
      for (int k = 0; k < t_.dim_; ++k) {
        const double x = samples_[s].x[k] - parentCentre[k];
        if (x <= reach) low |= 1 << k;
        if (x >= -reach) high |= 1 << k;
      }
      for (int c = 0; c < t_.children(); ++c)
        if ((c & ~high) == 0 && (~c & ~low & (t_.children() - 1)) == 0)
          content_[first + c].samples.push_back(s);
    }
    for (int c = 0; c < t_.children(); ++c) {
      const SizingOctree::Node& child = t_.nodes_[first + c];
      Content& cc = content_[first + c];
      // In 2D the model lies in the plane z = 0 of the local frame: only that slice counts.
      const Eigen::Vector3d centre = t_.toModel(child.centre);
      const Eigen::Vector3d slice(child.half, child.half, t_.dim_ == 3 ? child.half : 0.0);
      for (const std::int32_t s : parentContent.sources)
        if (t_.params_.sources[s].mayMeetBox(centre, t_.axes_.cwiseAbs() * slice))
          cc.sources.push_back(s);
    }
  }

  // The node covering cell `index` at `level` (or the leaf above it). -1 outside the root.
  std::int32_t descend(int level, const std::array<std::int64_t, 3>& index) const {
    for (int k = 0; k < t_.dim_; ++k)
      if (index[k] < 0 || index[k] >= (std::int64_t{1} << level)) return -1;
    std::int32_t n = 0;
    for (int l = 1; l <= level && t_.nodes_[n].firstChild >= 0; ++l) {
      int c = 0;
      for (int k = 0; k < t_.dim_; ++k)
        if (((index[k] >> (level - l)) & 1) != 0) c |= 1 << k;
      n = t_.nodes_[n].firstChild + c;
    }
    return n;
  }

  // Splits leaves until face neighbours differ by at most one level.
  void balance() {
    for (;;) {
      std::vector<std::int32_t> marked;
      for (const SizingOctree::Node& node : t_.nodes_) {
        if (node.firstChild >= 0 || node.level <= kMinLevel) continue;
        for (int k = 0; k < t_.dim_; ++k)
          for (const int step : {-1, 1}) {
            std::array<std::int64_t, 3> idx{node.index[0], node.index[1], node.index[2]};
            idx[k] += step;
            const std::int32_t m = descend(node.level, idx);
            if (m >= 0 && t_.nodes_[m].firstChild < 0 && t_.nodes_[m].level < node.level - 1)
              marked.push_back(m);
          }
      }
      if (marked.empty()) return;
      std::sort(marked.begin(), marked.end());
      marked.erase(std::unique(marked.begin(), marked.end()), marked.end());
      for (const std::int32_t m : marked) split(m);
    }
  }

  void collectLeaves() {
    t_.leafOfNode_.assign(t_.nodes_.size(), -1);
    for (std::int32_t n = 0; n < static_cast<std::int32_t>(t_.nodes_.size()); ++n)
      if (t_.nodes_[n].firstChild < 0) {
        t_.leafOfNode_[n] = static_cast<std::int32_t>(t_.leaves_.size());
        SizingOctree::LeafData leaf;
        leaf.node = n;
        t_.leaves_.push_back(std::move(leaf));
        t_.stats_.maxLevel = std::max(t_.stats_.maxLevel, t_.nodes_[n].level);
      }
  }

  void touchingLeaves(std::int32_t n, int axis, int side, std::vector<std::int32_t>& out) const {
    const SizingOctree::Node& node = t_.nodes_[n];
    if (node.firstChild < 0) {
      out.push_back(t_.leafOfNode_[n]);
      return;
    }
    for (int c = 0; c < t_.children(); ++c)
      if (((c >> axis) & 1) == side) touchingLeaves(node.firstChild + c, axis, side, out);
  }

  void findNeighbours() {
    t_.neighbourStart_.assign(1, 0);
    std::vector<std::int32_t> found;
    for (const SizingOctree::LeafData& leaf : t_.leaves_) {
      const SizingOctree::Node& node = t_.nodes_[leaf.node];
      found.clear();
      for (int k = 0; k < t_.dim_; ++k)
        for (const int step : {-1, 1}) {
          std::array<std::int64_t, 3> idx{node.index[0], node.index[1], node.index[2]};
          idx[k] += step;
          const std::int32_t m = descend(node.level, idx);
          if (m >= 0) touchingLeaves(m, k, step > 0 ? 0 : 1, found);
        }
      std::sort(found.begin(), found.end());
      found.erase(std::unique(found.begin(), found.end()), found.end());
      t_.neighbours_.insert(t_.neighbours_.end(), found.begin(), found.end());
      t_.neighbourStart_.push_back(static_cast<std::int64_t>(t_.neighbours_.size()));
    }
  }

  bool insideModel(const Eigen::Vector3d& local) const {
    const gp_Pnt p = toGp(t_.toModel(local));
    const double tol = 1e-9 * cad_.boundingDiagonal();
    return withOcctErrors("classifying a point of " + cad_.sourceName(), [&] {
      if (t_.dim_ == 3) {
        for (int s = 1; s <= cad_.numSolids(); ++s) {
          BRepClass3d_SolidClassifier classifier(occtSolid(cad_, s), p, tol);
          if (classifier.State() == TopAbs_IN) return true;
        }
        return false;
      }
      for (int f = 1; f <= cad_.numFaces(); ++f) {
        BRepClass_FaceClassifier classifier(occtFace(cad_, f), p, tol);
        if (classifier.State() == TopAbs_IN) return true;
      }
      return false;
    });
  }

  // Whether local point q is inside, judged by the outward normal of the nearest of
  // `candidates` (DESIGN.md: the CAD normal at the nearest boundary sample).
  bool insideBySamples(const Eigen::Vector3d& q,
                       const std::vector<std::int32_t>& candidates) const {
    return nearestSampleSide(q, candidates) < 0.0;
  }

  // The cosine between the outward normal of the nearest of `candidates` and the direction
  // from it to q: negative inside, and near 0 where that sample does not decide (q seen past
  // the rim of a face, the sample on its side wall).
  double nearestSampleSide(const Eigen::Vector3d& q,
                           const std::vector<std::int32_t>& candidates) const {
    double best = kInf, side = 0.0;
    for (const std::int32_t i : candidates) {
      const BoundarySample& s = samples_[i];
      const Eigen::Vector3d d = q - s.x;
      const double dist = d.squaredNorm();
      if (dist < best) {
        best = dist;
        side = dist > 0.0 ? s.outward.dot(d) / std::sqrt(dist) : 0.0;
      }
    }
    return side;
  }

  void classify() {
    const std::size_t nLeaves = t_.leaves_.size();
    if (t_.surface_) {
      // A surface mesh has no inside: the leaves its faces pass through are its domain (the
      // ones drawn and written), whole, and the rest is outside.
      const int s = t_.subdivisions();
      for (SizingOctree::LeafData& leaf : t_.leaves_) {
        const Content& c = content_[leaf.node];
        const bool onFaces = std::any_of(c.samples.begin(), c.samples.end(), [&](std::int32_t k) {
          return samples_[k].weight > 0.0 && !samples_[k].outward.isZero();
        });
        leaf.location =
            onFaces ? SizingOctree::Location::Boundary : SizingOctree::Location::Outside;
        leaf.insideFraction = onFaces ? 1.0f : 0.0f;
        if (onFaces) leaf.insideMask.assign(static_cast<std::size_t>(s) * s * s, 1);
      }
      return;
    }
    std::vector<bool> boundary(nLeaves, false);
    for (std::size_t i = 0; i < nLeaves; ++i)
      boundary[i] = onDomainBoundary(content_[t_.leaves_[i].node]);
    // Leaves off the boundary: flood-fill connected groups; classify each group by the nearest
    // boundary samples seen from its members next to the boundary (a vote of the samples that
    // decide, kDecidingCosine); OCCT's classifier for a group whose votes are split (one
    // unlucky sample at a sharp corner) or that has none (it touches no boundary leaf).
    std::vector<std::int32_t> group(nLeaves, -1);
    std::vector<bool> groupInside;
    std::vector<std::int32_t> candidates;
    for (std::size_t start = 0; start < nLeaves; ++start) {
      if (boundary[start] || group[start] >= 0) continue;
      const auto g = static_cast<std::int32_t>(groupInside.size());
      int votesIn = 0, votesOut = 0;
      std::vector<std::size_t> stack{start};
      group[start] = g;
      std::size_t largest = start;
      while (!stack.empty()) {
        const std::size_t i = stack.back();
        stack.pop_back();
        if (t_.nodes_[t_.leaves_[i].node].half > t_.nodes_[t_.leaves_[largest].node].half)
          largest = i;
        for (std::int64_t k = t_.neighbourStart_[i]; k < t_.neighbourStart_[i + 1]; ++k) {
          const auto j = static_cast<std::size_t>(t_.neighbours_[k]);
          if (boundary[j]) {
            if (votesIn + votesOut < kGroupVotes) {
              candidates.clear();
              for (const std::int32_t c : content_[t_.leaves_[j].node].samples)
                if (separatesDomain(samples_[c])) candidates.push_back(c);
              const double side =
                  nearestSampleSide(t_.nodes_[t_.leaves_[i].node].centre, candidates);
              if (std::abs(side) >= kDecidingCosine) (side < 0.0 ? votesIn : votesOut)++;
            }
          } else if (group[j] < 0) {
            group[j] = g;
            stack.push_back(j);
          }
        }
      }
      // Unanimous votes decide; split or no votes, OCCT's classifier at the group's largest
      // leaf (farthest from the boundary, where its ray casting is surest).
      groupInside.push_back(votesIn > 0 && votesOut == 0 ? true
                            : votesOut > 0 && votesIn == 0
                                ? false
                                : insideModel(t_.nodes_[t_.leaves_[largest].node].centre));
    }
    // Each leaf is judged on its own, in parallel (an allocation failure is carried out).
    FirstFailure failure;
#pragma omp parallel num_threads(threads_)
    {
      std::vector<std::int32_t> near;
#pragma omp for schedule(dynamic, 64)
      for (std::int64_t n = 0; n < static_cast<std::int64_t>(nLeaves); ++n) {
        try {
          const auto i = static_cast<std::size_t>(n);
          SizingOctree::LeafData& leaf = t_.leaves_[i];
          if (boundary[i]) {
            classifyBoundaryLeaf(leaf, near);
          } else {
            const bool in = groupInside[group[i]];
            leaf.location = in ? SizingOctree::Location::Inside : SizingOctree::Location::Outside;
            leaf.insideFraction = in ? 1.0f : 0.0f;
          }
        } catch (...) {
          failure.capture();
        }
      }
    }
    failure.rethrow();
  }

  // Sub-cells of a boundary leaf, judged by the nearest boundary sample.
  void classifyBoundaryLeaf(SizingOctree::LeafData& leaf,
                            std::vector<std::int32_t>& candidates) const {
    const int s = t_.subdivisions();
    const int cells = t_.dim_ == 3 ? s * s * s : s * s;
    candidates.clear();
    for (const std::int32_t k : content_[leaf.node].samples)
      if (separatesDomain(samples_[k])) candidates.push_back(k);
    // Samples on a curved face can be far denser than the sub-cells need: keep an even
    // selection of them (they lie in parameter order).
    if (candidates.size() > kMaxCandidates) {
      const std::size_t stride = (candidates.size() + kMaxCandidates - 1) / kMaxCandidates;
      std::size_t kept = 0;
      for (std::size_t k = 0; k < candidates.size(); k += stride)
        candidates[kept++] = candidates[k];
      candidates.resize(kept);
    }
    const SizingOctree::Node& node = t_.nodes_[leaf.node];
    leaf.insideMask.assign(cells, 0);
    int inside = 0;
    for (int c = 0; c < cells; ++c) {
      Eigen::Vector3d q = node.centre;
      int rest = c;
      for (int k = 0; k < t_.dim_; ++k) {
        q[k] += node.half * (2.0 * ((rest % s) + 0.5) / s - 1.0);
        rest /= s;
      }
      if (insideBySamples(q, candidates)) {
        leaf.insideMask[c] = 1;
        ++inside;
      }
    }
    // Near the boundary but wholly outside (the samples reach a little beyond their leaf).
    leaf.location = inside > 0 ? SizingOctree::Location::Boundary : SizingOctree::Location::Outside;
    leaf.insideFraction = static_cast<float>(inside) / static_cast<float>(cells);
  }

  // Leaf sizes: the smallest sample or source size in the leaf (else maxDelta), then graded
  // outward along the leaf graph, shortest-path fashion.
  void grade() {
    const SizingParameters& p = t_.params_;
    using Item = std::pair<double, std::size_t>;
    std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
    for (std::size_t i = 0; i < t_.leaves_.size(); ++i) {
      SizingOctree::LeafData& leaf = t_.leaves_[i];
      const Content& c = content_[leaf.node];
      double d = p.maxDelta;
      for (const std::int32_t s : c.samples)
        if (samples_[s].delta > 0.0) d = std::min(d, samples_[s].delta);
      d = std::max(d, p.minDelta);
      for (const std::int32_t s : c.sources) {
        const RefinementSource& src = p.sources[s];
        const SizingOctree::Node& node = t_.nodes_[leaf.node];
        // Only sources reaching the leaf's centre region set its size outright.
        if (src.distance(t_.toModel(node.centre)) <= node.half * std::sqrt(double(t_.dim_)))
          d = std::min(d, src.delta);
      }
      leaf.delta = d;
      if (d < p.maxDelta) queue.push({d, i});
    }
    while (!queue.empty()) {
      const auto [d, i] = queue.top();
      queue.pop();
      if (d > t_.leaves_[i].delta) continue;
      const Eigen::Vector3d ci = t_.nodes_[t_.leaves_[i].node].centre;
      for (std::int64_t k = t_.neighbourStart_[i]; k < t_.neighbourStart_[i + 1]; ++k) {
        SizingOctree::LeafData& other = t_.leaves_[t_.neighbours_[k]];
        const double candidate = d + p.gradation * (t_.nodes_[other.node].centre - ci).norm();
        if (candidate < other.delta) {
          other.delta = candidate;
          queue.push({candidate, static_cast<std::size_t>(t_.neighbours_[k])});
        }
      }
    }
    double smallest = kInf;
    for (const SizingOctree::LeafData& leaf : t_.leaves_) {
      switch (leaf.location) {
        case SizingOctree::Location::Inside:
          ++t_.stats_.insideLeaves;
          break;
        case SizingOctree::Location::Boundary:
          ++t_.stats_.boundaryLeaves;
          break;
        case SizingOctree::Location::Outside:
          ++t_.stats_.outsideLeaves;
          break;
      }
      if (leaf.location != SizingOctree::Location::Outside)
        smallest = std::min(smallest, leaf.delta);
    }
    t_.stats_.leaves = t_.leaves_.size();
    t_.stats_.smallestDelta = std::isfinite(smallest) ? smallest : p.maxDelta;
  }

  // Corner sizes: the mean of the sizes of the leaves that have that corner; then, where a
  // corner of small leaves lies on a face or edge of a larger leaf (a hanging corner), the
  // larger leaf's interpolation there, so that delta(x) is continuous across the two.
  void setCorners() {
    const int top = t_.stats_.maxLevel;
    const int corners = t_.children();
    std::unordered_map<std::uint64_t, std::pair<double, int>> sums;
    sums.reserve(t_.leaves_.size() * 4);
    const auto index = [&](const SizingOctree::Node& node, int c) {
      std::array<std::int64_t, 3> idx{0, 0, 0};
      for (int k = 0; k < t_.dim_; ++k)
        idx[k] = (std::int64_t{node.index[k]} + ((c >> k) & 1)) << (top - node.level);
      return idx;
    };
    const auto key = [&](const SizingOctree::Node& node, int c) {
      const auto idx = index(node, c);
      return cornerKey(idx[0], idx[1], idx[2]);
    };
    for (const SizingOctree::LeafData& leaf : t_.leaves_)
      for (int c = 0; c < corners; ++c) {
        auto& slot = sums[key(t_.nodes_[leaf.node], c)];
        slot.first += leaf.delta;
        ++slot.second;
      }
    for (SizingOctree::LeafData& leaf : t_.leaves_)
      for (int c = 0; c < corners; ++c) {
        const auto& slot = sums[key(t_.nodes_[leaf.node], c)];
        leaf.corner[c] = static_cast<float>(slot.first / slot.second);
      }
    // Hanging corners: a leaf's corners on the face it shares with a larger face neighbour that
    // are not that neighbour's corners take the neighbour's interpolated value. Levels are
    // done from coarse to fine, so that a larger leaf's own hanging corners are settled before
    // its values are passed on. (A corner on the edge of a larger leaf that is only an edge
    // neighbour is not looked at: with faces balanced that is rare, and the jump small.)
    const SizingOctree::Node& root = t_.nodes_[0];
    const double unit = 2.0 * root.half / double(std::int64_t{1} << top);
    std::vector<std::vector<std::size_t>> byLevel(static_cast<std::size_t>(top) + 1);
    for (std::size_t i = 0; i < t_.leaves_.size(); ++i)
      byLevel[t_.nodes_[t_.leaves_[i].node].level].push_back(i);
    std::unordered_map<std::uint64_t, float> hanging;
    for (std::size_t level = 0; level < byLevel.size(); ++level) {
      std::unordered_map<std::uint64_t, float> found;
      for (const std::size_t i : byLevel[level]) {
        const SizingOctree::Node& node = t_.nodes_[t_.leaves_[i].node];
        for (std::int64_t nb = t_.neighbourStart_[i]; nb < t_.neighbourStart_[i + 1]; ++nb) {
          const SizingOctree::LeafData& larger = t_.leaves_[t_.neighbours_[nb]];
          const SizingOctree::Node& other = t_.nodes_[larger.node];
          if (other.level >= node.level) continue;
          // The axis across the shared face: where the centres are farthest apart.
          int axis = 0;
          for (int k = 1; k < t_.dim_; ++k)
            if (std::abs(other.centre[k] - node.centre[k]) >
                std::abs(other.centre[axis] - node.centre[axis]))
              axis = k;
          const int side = other.centre[axis] > node.centre[axis] ? 1 : 0;
          for (int c = 0; c < corners; ++c) {
            if (((c >> axis) & 1) != side) continue;
            const auto idx = index(node, c);
            const std::uint64_t k = cornerKey(idx[0], idx[1], idx[2]);
            bool shared = false;
            for (int oc = 0; oc < corners && !shared; ++oc) shared = key(other, oc) == k;
            if (shared || found.count(k) != 0 || hanging.count(k) != 0) continue;
            Eigen::Vector3d p = root.centre;
            for (int d = 0; d < t_.dim_; ++d) p[d] += -root.half + double(idx[d]) * unit;
            found[k] = static_cast<float>(t_.interpolate(larger, p));
          }
        }
      }
      if (found.empty()) continue;
      // Every leaf with such a corner takes the value now: this level and finer ones (a coarser
      // leaf with that corner would have found it first).
      for (std::size_t finer = level; finer < byLevel.size(); ++finer)
        for (const std::size_t i : byLevel[finer]) {
          SizingOctree::LeafData& leaf = t_.leaves_[i];
          for (int c = 0; c < corners; ++c)
            if (const auto it = found.find(key(t_.nodes_[leaf.node], c)); it != found.end())
              leaf.corner[c] = it->second;
        }
      hanging.insert(found.begin(), found.end());
    }
  }

  const CadModel& cad_;
  SizingOctree& t_;
  int threads_;
  std::vector<BoundarySample> samples_;  // local coordinates
  std::vector<Content> content_;         // per node; emptied when split
  Eigen::Vector3d geometryLo_, geometryHi_;
};

SizingOctree SizingOctree::build(const CadModel& cad, const SizingParameters& params, int threads) {
  params.validate();
  SizingOctree tree;
  tree.params_ = params;
  tree.params_.sources = resolveCurveSources(params.sources, cad);
  OctreeBuilder(cad, tree, threads).run();
  return tree;
}

std::int32_t SizingOctree::findLeafNode(const Eigen::Vector3d& q) const {
  std::int32_t n = 0;
  while (nodes_[n].firstChild >= 0) {
    const Node& node = nodes_[n];
    int c = 0;
    for (int k = 0; k < dim_; ++k)
      if (q[k] >= node.centre[k]) c |= 1 << k;
    n = node.firstChild + c;
  }
  return n;
}

std::array<double, 3> SizingOctree::leafCoordinates(const Node& node,
                                                    const Eigen::Vector3d& q) const {
  std::array<double, 3> t{0.0, 0.0, 0.0};
  for (int k = 0; k < dim_; ++k)
    t[k] = std::clamp((q[k] - node.centre[k] + node.half) / (2.0 * node.half), 0.0, 1.0);
  return t;
}

double SizingOctree::interpolate(const LeafData& leaf, const Eigen::Vector3d& q) const {
  const Node& node = nodes_[leaf.node];
  const std::array<double, 3> t = leafCoordinates(node, q);
  double value = 0.0;
  for (int c = 0; c < children(); ++c) {
    double w = 1.0;
    for (int k = 0; k < dim_; ++k) w *= bit(c, k) ? t[k] : 1.0 - t[k];
    value += w * leaf.corner[c];
  }
  return value;
}

double SizingOctree::delta(const Eigen::Vector3d& x) const {
  Eigen::Vector3d q = toLocal(x);
  const Node& root = nodes_[0];
  for (int k = 0; k < dim_; ++k)
    q[k] = std::clamp(q[k], root.centre[k] - root.half, root.centre[k] + root.half);
  const LeafData& leaf = leaves_[leafOfNode_[findLeafNode(q)]];
  double d = std::clamp(interpolate(leaf, q), params_.minDelta, params_.maxDelta);
  for (const RefinementSource& s : params_.sources)
    if (s.delta < d && s.contains(x)) d = s.delta;
  return d;
}

SizingOctree::Leaf SizingOctree::leaf(std::size_t i) const {
  const LeafData& data = leaves_.at(i);
  const Node& node = nodes_[data.node];
  Leaf out;
  out.centre = toModel(node.centre);
  out.halfWidth = node.half;
  out.level = node.level;
  out.delta = data.delta;
  out.location = data.location;
  out.insideFraction = data.insideFraction;
  return out;
}

std::vector<std::size_t> SizingOctree::leafNeighbours(std::size_t i) const {
  std::vector<std::size_t> out;
  for (std::int64_t k = neighbourStart_.at(i); k < neighbourStart_.at(i + 1); ++k)
    out.push_back(static_cast<std::size_t>(neighbours_[k]));
  return out;
}

double SizingOctree::domainMeasure() const {
  double total = 0.0;
  for (const LeafData& leaf : leaves_)
    total += leaf.insideFraction * std::pow(2.0 * nodes_[leaf.node].half, dim_);
  return total;
}

double SizingOctree::gradientNorm(const LeafData& leaf, const Eigen::Vector3d& q) const {
  const Node& node = nodes_[leaf.node];
  const std::array<double, 3> t = leafCoordinates(node, q);
  double g2 = 0.0;
  for (int axis = 0; axis < dim_; ++axis) {
    double g = 0.0;
    for (int c = 0; c < children(); ++c) {
      double w = bit(c, axis) ? 1.0 : -1.0;
      for (int k = 0; k < dim_; ++k)
        if (k != axis) w *= bit(c, k) ? t[k] : 1.0 - t[k];
      g += w * leaf.corner[c];
    }
    g /= 2.0 * node.half;
    g2 += g * g;
  }
  return std::sqrt(g2);
}

void SizingOctree::leafQuadrature(std::size_t i, std::vector<QuadraturePoint>& points,
                                  bool withGradient) const {
  points.clear();
  const LeafData& leaf = leaves_[i];
  if (leaf.location == Location::Outside) return;
  const Node& node = nodes_[leaf.node];
  const double measure = std::pow(2.0 * node.half, dim_);
  const auto add = [&](const Eigen::Vector3d& q, double weight) {
    points.push_back({toModel(q), weight, withGradient ? gradientNorm(leaf, q) : 0.0});
  };
  if (leaf.location == Location::Inside) {
    const double g = node.half / std::sqrt(3.0);
    for (int c = 0; c < children(); ++c) {
      Eigen::Vector3d q = node.centre;
      for (int k = 0; k < dim_; ++k) q[k] += bit(c, k) ? g : -g;
      add(q, measure / children());
    }
    return;
  }
  const int s = subdivisions();
  const int cells = static_cast<int>(leaf.insideMask.size());
  for (int c = 0; c < cells; ++c) {
    if (leaf.insideMask[c] == 0) continue;
    Eigen::Vector3d q = node.centre;
    int rest = c;
    for (int k = 0; k < dim_; ++k) {
      q[k] += node.half * (2.0 * ((rest % s) + 0.5) / s - 1.0);
      rest /= s;
    }
    add(q, measure / cells);
  }
}

}  // namespace homesh

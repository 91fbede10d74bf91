// The sizing octree: the mesh size field delta(x) of a CAD model (DESIGN.md section 2).
//
// Built once from the CAD and the SizingParameters: curvature samples and user sources set the
// sizes of the octants they fall in; octants are divided until each is no larger than its size
// (and boundary octants no larger than maxDelta), neighbours differ by at most one level (2:1
// balance), sizes are graded outward (|delta_i - delta_j| <= gradation * distance between
// centres, propagated shortest-path fashion from the sized octants) and every leaf is classified
// inside, outside or on the boundary of the domain (with the fraction of it inside).
//
// A 2D (planar) model gets a quadtree in the model's plane; everything else is the same.
//
// delta(x) interpolates the leaf sizes (multilinearly between corner values, each the mean of the
// leaves meeting at that corner), clamps to [minDelta, maxDelta] and takes the minimum with the
// sources containing x. It is const and allocation-free: any number of threads may query one
// octree at once.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "core/parameters.hpp"
#include "sizing/boundary_sampling.hpp"
#include "sizing/sizing_parameters.hpp"

namespace homesh {

class CadModel;

// The sizes ask for more octree cells than the octree may have (a ParameterError naming the
// sizes or the refinement source responsible): an automatic MinDelta is then raised
// (pipeline/mesh_pipeline.cpp, runSizing).
class OctreeTooLarge : public ParameterError {
 public:
  OctreeTooLarge(const std::string& message, double builtWith, bool sourceBlamed)
      : ParameterError(message), minDelta(builtWith), sourceTooSmall(sourceBlamed) {}
  double minDelta;      // the MinDelta the octree was built with (resolved, when automatic)
  bool sourceTooSmall;  // a refinement source's size below it is to blame, not MinDelta
};

struct OctreeStatistics {
  std::size_t leaves = 0, insideLeaves = 0, boundaryLeaves = 0, outsideLeaves = 0;
  int maxLevel = 0;
  std::size_t boundarySamples = 0, sizedSamples = 0;
  std::size_t thinWallSamples = 0;    // samples whose size the thin-wall bound made smaller
  std::size_t narrowFaceSamples = 0;  // curve samples whose size a narrow face made smaller
  double smallestDelta = 0.0;         // over leaves that are not outside
};

class SizingOctree {
 public:
  enum class Location : std::uint8_t { Outside, Boundary, Inside };

  struct Leaf {
    Eigen::Vector3d centre;  // model coordinates
    double halfWidth = 0.0;
    int level = 0;
    double delta = 0.0;  // the leaf's size after gradation
    Location location = Location::Outside;
    double insideFraction = 0.0;  // of its volume (area in 2D)
  };

  // Uses up to `threads` threads. Throws ParameterError (bad parameters; OctreeTooLarge: sizes
  // too small for the model), CadError (no solid and not planar, OCCT failure).
  static SizingOctree build(const CadModel& cad, const SizingParameters& params,
                            int threads = defaultOf<int>("threads"));

  // The size at x (model coordinates). Thread-safe.
  double delta(const Eigen::Vector3d& x) const;

  // 3 for a volume (and for a surface mesh, whose sizes live in 3D too), 2 for a planar model.
  int dim() const { return dim_; }
  // Built for a surface mesh (a model of faces, no solid, not in one plane): the sizes follow
  // its faces; which leaves lie inside means nothing there.
  bool surface() const { return surface_; }
  const SizingParameters& parameters() const { return params_; }
  const OctreeStatistics& statistics() const { return stats_; }
  std::size_t numLeaves() const { return leaves_.size(); }
  Leaf leaf(std::size_t i) const;
  // Leaves sharing a face (an edge in 2D) with leaf i.
  std::vector<std::size_t> leafNeighbours(std::size_t i) const;
  // The boundary samples the octree was built from (model coordinates).
  const std::vector<BoundarySample>& samples() const { return samples_; }

  // A point of the rule that integrates over the domain: position (model coordinates), weight,
  // and the norm of the gradient of the leaf's interpolated size there.
  struct QuadraturePoint {
    Eigen::Vector3d x;
    double weight = 0.0;
    double gradient = 0.0;
  };

  // Volume (area in 2D) of the domain as the octree sees it.
  double domainMeasure() const;

  // The points integrating over the inside part of leaf i (their weights sum to its inside
  // volume or area): a 2-point Gauss rule per axis inside, the inside sub-cells'
  // centres on the boundary, none outside. The gradients are left 0 unless `withGradient`.
  void leafQuadrature(std::size_t i, std::vector<QuadraturePoint>& points,
                      bool withGradient = true) const;

  // The octree's axes in model coordinates (columns): x, y and, in 2D, the model plane's unit
  // normal as the third; the identity in 3D.
  const Eigen::Matrix3d& axes() const { return axes_; }

  // Sub-cells per axis of a boundary leaf, each classified inside or outside by its centre.
  int subdivisions() const { return dim_ == 3 ? 3 : 6; }

 private:
  struct Node {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();  // local coordinates
    double half = 0.0;
    std::int32_t firstChild = -1;
    std::int32_t level = 0;
    std::array<std::int32_t, 3> index{0, 0, 0};  // integer position at its level
  };
  struct LeafData {
    std::int32_t node = 0;
    double delta = 0.0;
    Location location = Location::Outside;
    float insideFraction = 0.0f;
    std::array<float, 8> corner{};         // sizes at the corners, bit k of the index for axis k
    std::vector<std::uint8_t> insideMask;  // boundary leaves: which sub-cells are inside
  };

  Eigen::Vector3d toLocal(const Eigen::Vector3d& x) const {
    return axes_.transpose() * (x - origin_);
  }
  Eigen::Vector3d toModel(const Eigen::Vector3d& q) const { return origin_ + axes_ * q; }
  std::int32_t findLeafNode(const Eigen::Vector3d& q) const;
  // q's position in the node's box, 0..1 per axis (clamped).
  std::array<double, 3> leafCoordinates(const Node& node, const Eigen::Vector3d& q) const;
  double interpolate(const LeafData& leaf, const Eigen::Vector3d& q) const;
  double gradientNorm(const LeafData& leaf, const Eigen::Vector3d& q) const;
  int children() const { return 1 << dim_; }

  friend class OctreeBuilder;

  int dim_ = 3;
  bool surface_ = false;
  SizingParameters params_;
  Eigen::Vector3d origin_ = Eigen::Vector3d::Zero();
  Eigen::Matrix3d axes_ = Eigen::Matrix3d::Identity();  // columns: local x, y, z (normal in 2D)
  std::vector<Node> nodes_;
  std::vector<LeafData> leaves_;
  std::vector<std::int32_t> leafOfNode_;  // node -> leaf index, -1 for internal nodes
  std::vector<std::int64_t> neighbourStart_;
  std::vector<std::int32_t> neighbours_;
  std::vector<BoundarySample> samples_;
  OctreeStatistics stats_;
};

}  // namespace homesh

// Quality of a whole mesh: per element, per cell type and mesh-wide.
//
// Per element of the mesh's dimension:
//   - scaled Jacobian: the certified lower bound of min J / max J from Bezier bounds refined to
//     1e-3 (see bezier_jacobian.hpp; Gmsh's AnalyseMeshQuality measure), with a validity
//     verdict (valid, invalid, undecided);
//   - distortion quality against the straight-sided element (see distortion.hpp).
// Per boundary cell (triangles on CAD faces, lines on CAD curves): the ratio of the smallest to
// the largest area (length) element, sampled: how unevenly curving stretched it.
// Summaries: worst, mean and a 20-bin histogram on [0, 1] per measure, invalid and undecided
// counts, per cell type and overall; `certified` says that every verdict is certain.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <map>
#include <vector>

#include "core/mesh.hpp"
#include "core/parameters.hpp"
#include "quality/bezier_jacobian.hpp"

namespace homesh {

// 20 equal bins on [0, 1]; values outside are counted apart.
struct Histogram {
  static constexpr int kBins = 20;
  std::array<std::size_t, kBins> counts{};
  std::size_t below = 0;  // values < 0 (invalid elements) or undefined (NaN)
  std::size_t above = 0;  // values > 1 (never for these measures, kept for honesty)
  void add(double value);
};

struct MeasureSummary {
  double min = 1.0;
  double mean = 0.0;
  Histogram histogram;
};

struct TypeQuality {
  std::size_t count = 0;
  std::size_t invalid = 0;
  std::size_t undecided = 0;
  MeasureSummary scaledJacobian, distortion;
};

struct QualitySummary {
  // Per element of dimension mesh.dim, in block order. The element's true min J / max J lies
  // in [scaledJacobian, scaledJacobianUpper]: the certified bound and the ratio of values of J
  // actually found.
  std::vector<double> scaledJacobian;
  std::vector<double> scaledJacobianUpper;
  std::vector<double> distortion;
  std::vector<Validity> validity;
  // Per lower-dimensional cell, in block order (distortion of a line is 1 by definition).
  std::vector<double> boundaryScaledJacobian;
  std::vector<double> boundaryDistortion;

  std::size_t invalid = 0;    // certified invalid (a value of J <= 0 was found)
  std::size_t undecided = 0;  // neither proven valid nor invalid
  bool certified = true;      // every element's verdict is certain and Bezier-certified
  std::size_t known = 0;      // elements whose values were taken from a KnownQuality
  MeasureSummary scaled, distortionSummary;
  std::map<CellType, TypeQuality> byType;
};

// An element that is not proven valid: where it is, its verdict, and the interval holding its
// min J / max J.
struct FlaggedElement {
  std::size_t index = 0;  // among the elements of dimension mesh.dim, in block order
  CellType type = CellType::Tetrahedron;
  int entity = 0;  // its CAD entity (solid or face)
  Validity validity = Validity::Undecided;
  double lower = 0.0, upper = 0.0;
  // The CAD faces and curves its nodes lie on (1-based indices, sorted; from the mesh's node
  // classification, empty for a mesh without CAD): where the problem sits on the model.
  std::vector<int> cadFaces, cadCurves, cadVertices;
};

// The invalid and undecided elements, at most `limit` of them, in element order.
std::vector<FlaggedElement> flaggedElements(const Mesh& mesh, const QualitySummary& quality,
                                            std::size_t limit);

// Mesh::cellNormal as a vector: what the Jacobian of 2D cell `cell` is measured along.
inline Eigen::Vector3d cellNormal(const Mesh& mesh, const std::int64_t* cell) {
  const std::array<double, 3> n = mesh.cellNormal(cell);
  return {n[0], n[1], n[2]};
}

// Certified Jacobian bounds of one element of `block` (of dimension mesh.dim), computed on its
// node coordinates moved to the origin and scaled to unit size (every measure here is invariant
// under both). `tolerance` as boundJacobian's.
JacobianBounds elementJacobianBounds(const Mesh& mesh, const ElementBlock& block, std::size_t e,
                                     double tolerance = kJacobianBoundTolerance);

// Quality measured before on another mesh, for evaluateQuality to take instead of measuring
// again: an element whose nodes have the (finite) coordinates of its source element's nodes
// (same type and order, the meshes of one dimension and plane normal) has that element's
// values, since every measure here is a function of those alone. (Boundary cells' stretch is
// measured again on all of them: it is cheap.) A repair round changes a few hundred of a model's
// 200,000 elements; measuring only those saves the whole-mesh check (5 s at order 4).
struct KnownQuality {
  const Mesh* mesh = nullptr;  // the mesh `quality` was measured on (its cells) ...
  // ... with these node coordinates, when they have changed since (null: mesh->xyz)
  const std::vector<double>* xyz = nullptr;
  const QualitySummary* quality = nullptr;
  // Per element of the mesh being evaluated (block order): the index of its source element
  // among `mesh`'s, or -1 for none. Empty: each element's source has its own index.
  std::vector<std::int64_t> source;
};

// Evaluates every element on `threads` threads (the result does not depend on their number),
// taking from `known` the values of the elements it has unchanged (the result is the same as
// without it). Throws Error for a mesh without elements.
QualitySummary evaluateQuality(const Mesh& mesh, int threads = defaultOf<int>("threads"),
                               const KnownQuality* known = nullptr);

}  // namespace homesh

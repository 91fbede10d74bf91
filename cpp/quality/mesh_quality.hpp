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
#include <map>
#include <vector>

#include "core/mesh.hpp"
#include "quality/bezier_jacobian.hpp"

namespace homesh {

// 20 equal bins on [0, 1]; values outside are counted apart.
struct Histogram {
  static constexpr int kBins = 20;
  std::array<std::size_t, kBins> counts{};
  std::size_t below = 0;  // values < 0 (invalid elements)
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
  // Per element of dimension mesh.dim, in block order.
  std::vector<double> scaledJacobian;
  std::vector<double> distortion;
  std::vector<Validity> validity;
  // Per lower-dimensional cell, in block order (distortion of a line is 1 by definition).
  std::vector<double> boundaryScaledJacobian;
  std::vector<double> boundaryDistortion;

  std::size_t invalid = 0;    // certified invalid (a value of J <= 0 was found)
  std::size_t undecided = 0;  // neither proven valid nor invalid
  bool certified = true;      // every element's verdict is certain and Bezier-certified
  MeasureSummary scaled, distortionSummary;
  std::map<CellType, TypeQuality> byType;
};

// Evaluates every element on `threads` threads (the result does not depend on their number).
// Throws Error for a mesh without elements.
QualitySummary evaluateQuality(const Mesh& mesh, int threads = 1);

}  // namespace homesh

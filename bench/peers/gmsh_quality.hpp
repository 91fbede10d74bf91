// Gmsh's own verdict on a mesh, for tests and benchmarks that compare HOMesh with it:
// Plugin(AnalyseMeshQuality), the worst minJ/maxJ from Bezier bounds refined to 1e-3.
// Header-only so that the tests and the benchmarks share it without a library of their own.
#pragma once

#include <gmsh.h>

#include <algorithm>
#include <cstddef>
#include <string>
#include <vector>

namespace homesh::peers {

// Runs the plugin on the model Gmsh has open (elements of dimension `dim`); returns the worst
// minJ/maxJ and removes the views it made.
inline double gmshAnalyseScaledJacobian(int dim) {
  gmsh::plugin::setNumber("AnalyseMeshQuality", "JacobianDeterminant", 1);
  gmsh::plugin::setNumber("AnalyseMeshQuality", "IGEMeasure", 0);
  gmsh::plugin::setNumber("AnalyseMeshQuality", "ICNMeasure", 0);
  gmsh::plugin::setNumber("AnalyseMeshQuality", "DimensionOfElements", dim);
  gmsh::plugin::setNumber("AnalyseMeshQuality", "Recompute", 1);
  gmsh::plugin::setNumber("AnalyseMeshQuality", "CreateView", 1);
  gmsh::plugin::run("AnalyseMeshQuality");
  std::vector<int> views;
  gmsh::view::getTags(views);
  double worst = 1e300;
  for (const int v : views) {
    std::string type;
    std::vector<std::size_t> tags;
    std::vector<std::vector<double>> data;
    double time = 0;
    int components = 0;
    gmsh::view::getModelData(v, 0, type, tags, data, time, components);
    for (const auto& d : data) worst = std::min(worst, d[0]);
    gmsh::view::remove(v);
  }
  return worst;
}

// The same on a mesh file, in a Gmsh session of its own.
inline double gmshWorstScaledJacobian(const std::string& path, int dim) {
  gmsh::initialize(0, nullptr, false);
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::open(path);
  const double worst = gmshAnalyseScaledJacobian(dim);
  gmsh::finalize();
  return worst;
}

}  // namespace homesh::peers

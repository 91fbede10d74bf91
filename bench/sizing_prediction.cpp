// Sizing octree benchmark: for each case, the time to build the octree and predict the element
// count against the time Gmsh takes to make the linear mesh from it (in the same process), and
// the predicted against the actual element count.
//
//   bench_sizing_prediction [--threads N] [--calibrate [--gradient-term]] [CASE...]
//   CASE = a NekMesh .mcf, or CAD:MIN:MAX:EPS[:SCALE] (sizes from curvature; MIN == MAX gives
//          a uniform size; SCALE 0.001 reads a millimetre CAD in metres, as NekMesh does).
//   Without cases: the five NekMesh meshgen peer cases (../shared/peer-cases/nekmesh/meshgen).
//
// Prints one line per case and, with --calibrate, the fitted densities of the prediction model
// (see cpp/sizing/element_count.hpp) by least squares over all cases (of one dimension; the 3D
// densities in use were fitted on FreeCAD-built shapes by bench/prediction_shapes --calibrate,
// and --gradient-term applies to 2D).
#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "cad/cad_model.hpp"
#include "linear/linear_mesher.hpp"
#include "pipeline/case_setup.hpp"
#include "sizing/element_count.hpp"
#include "sizing/sizing_octree.hpp"

namespace {

double seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

struct Case {
  std::string name;
  homesh::CadSource source;
  homesh::SizingParameters params;
};

Case parseCase(const std::string& text) {
  if (text.size() > 4 && text.substr(text.size() - 4) == ".mcf") {
    const homesh::CaseSetup setup = homesh::setupCase(text);
    if (!setup.options.sizing) throw std::runtime_error(text + " has no MinDelta/MaxDelta/EPS");
    return {text.substr(text.find_last_of('/') + 1), setup.source, *setup.options.sizing};
  }
  Case c;
  std::vector<std::string> parts;
  std::stringstream in(text);
  for (std::string item; std::getline(in, item, ':');) parts.push_back(item);
  if (parts.size() != 4 && parts.size() != 5)
    throw std::runtime_error("case must be CAD:MIN:MAX:EPS[:SCALE], got " + text);
  c.source = homesh::CadSource::file(parts[0]);
  if (parts.size() == 5) c.source.scale = std::stod(parts[4]);
  c.name = parts[0].substr(parts[0].find_last_of('/') + 1) + ":" + parts[2];
  c.params.minDelta = std::stod(parts[1]);
  c.params.maxDelta = std::stod(parts[2]);
  c.params.eps = std::stod(parts[3]);
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    int threads = 1;
    bool calibrate = false, gradientTerm = false;
    std::vector<Case> cases;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--threads" && i + 1 < argc)
        threads = std::atoi(argv[++i]);
      else if (a == "--calibrate")
        calibrate = true;
      else if (a == "--gradient-term")
        gradientTerm = true;
      else
        cases.push_back(parseCase(a));
    }
    if (cases.empty())
      for (const char* peer :
           {"3d_sphere", "3d_bl_cyl", "2d_bl_aerofoil", "2d_bl_t106", "2d_bl_naca0012"})
        cases.push_back(parseCase(std::string(HOMESH_SOURCE_DIR) +
                                  "/../shared/peer-cases/nekmesh/meshgen/" + peer + ".mcf"));
    std::vector<Eigen::VectorXd> rows;  // the model's terms (element_count.hpp) per case
    std::vector<int> dims;
    std::vector<double> actual;
    std::printf("%-28s %8s %8s %9s %9s %9s %7s %7s\n", "case", "leaves", "octree_s", "predict_s",
                "mesh_s", "predicted", "actual", "ratio");
    for (const Case& c : cases) {
      const homesh::CadModel cad = c.source.load();
      auto t0 = std::chrono::steady_clock::now();
      const homesh::SizingOctree tree = homesh::SizingOctree::build(cad, c.params, threads);
      const double octreeSeconds = seconds(t0);
      t0 = std::chrono::steady_clock::now();
      const homesh::ElementCountPrediction p = homesh::predictElementCount(tree, cad, threads);
      const double predictSeconds = seconds(t0);
      homesh::LinearMeshOptions options;
      options.sizeField = [&tree](const Eigen::Vector3d& x) { return tree.delta(x); };
      options.minSize = c.params.minDelta;
      options.maxSize = c.params.maxDelta;
      t0 = std::chrono::steady_clock::now();
      const homesh::Mesh mesh = homesh::generateLinearMesh(cad, options);
      const double meshSeconds = seconds(t0);
      const auto n = static_cast<double>(mesh.numElements());
      std::printf("%-28s %8zu %8.3f %9.3f %9.3f %9.0f %7.0f %7.3f  (octree+predict / mesh %.3f)\n",
                  c.name.c_str(), tree.numLeaves(), octreeSeconds, predictSeconds, meshSeconds,
                  p.elements, n, p.elements / n, (octreeSeconds + predictSeconds) / meshSeconds);
      if (p.dim == 3) {
        std::printf(
            "    core integral %.6g, boundary integral %.6g, curve integral %.6g, convexity "
            "integral %.6g, gradient integral %.6g, volume integral %.6g, domain %.6g\n",
            p.coreIntegral, p.boundaryIntegral, p.curveIntegral, p.convexityIntegral,
            p.gradientIntegral, p.volumeIntegral, p.domainMeasure);
        Eigen::VectorXd terms(5);
        terms << p.coreIntegral, p.boundaryIntegral, p.curveIntegral, p.convexityIntegral,
            p.gradientIntegral;
        rows.push_back(terms);
      } else {
        std::printf(
            "    volume integral %.6g, boundary integral %.6g, gradient integral %.6g, domain "
            "%.6g\n",
            p.volumeIntegral, p.boundaryIntegral, p.gradientIntegral, p.domainMeasure);
        Eigen::VectorXd terms(gradientTerm ? 3 : 2);
        terms << p.volumeIntegral, p.boundaryIntegral;
        if (gradientTerm) terms[2] = p.gradientIntegral;
        rows.push_back(terms);
      }
      dims.push_back(p.dim);
      actual.push_back(n);
    }
    if (calibrate && rows.size() >= 2) {
      if (std::adjacent_find(dims.begin(), dims.end(), std::not_equal_to<>()) != dims.end())
        throw std::runtime_error("--calibrate needs cases of one dimension (2D or 3D)");
      // Relative least squares: minimise sum ((terms . densities) / N - 1)^2.
      const auto terms = static_cast<Eigen::Index>(rows[0].size());
      Eigen::MatrixXd A(rows.size(), terms);
      Eigen::VectorXd y = Eigen::VectorXd::Ones(static_cast<Eigen::Index>(rows.size()));
      for (std::size_t i = 0; i < rows.size(); ++i)
        A.row(static_cast<Eigen::Index>(i)) = rows[i].transpose() / actual[i];
      const Eigen::VectorXd fit = A.colPivHouseholderQr().solve(y);
      if (dims[0] == 3)
        std::printf(
            "fit: core density %.4f, boundary %.4f, curve %.4f, convexity %.4f, gradient %.4f\n",
            fit[0], fit[1], fit[2], fit[3], fit[4]);
      else
        std::printf("fit: area density %.4f, boundary density %.4f, gradient density %.4f\n",
                    fit[0], fit[1], terms == 3 ? fit[2] : 0.0);
      for (std::size_t i = 0; i < rows.size(); ++i)
        std::printf("    case %zu: fitted/actual %.3f\n", i + 1, rows[i].dot(fit) / actual[i]);
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_sizing_prediction: %s\n", e.what());
    return 1;
  }
}

// Quality evaluation throughput on curved tetrahedra (order 4 by default), HOMesh against Gmsh's
// Plugin(AnalyseMeshQuality) on the same mesh file in the same process.
//
// Both compute the certified worst scaled Jacobian min J / max J of every element from Bezier
// bounds refined to a relative 1e-3. Gmsh's plugin runs on one thread; HOMesh is timed on one
// thread (the fair ratio) and on all threads asked for. HOMesh's full quality pass (adding the
// distortion measure and the summaries) is timed too. Times are the best of --repeat runs.
//
// usage: bench_quality_throughput [--mesh FILE.msh | --cad FILE --size H] [--order P]
//                                 [--threads N] [--repeat R]
// Without --mesh, the mesh is made by HOMesh's pipeline from --cad (default: the bundled
// examples/bracket.step at size 2.5, about 10 000 tetrahedra).
#include <gmsh.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/mesh_readers.hpp"
#include "io/mesh_writers.hpp"
#include "peers/gmsh_quality.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "quality/bezier_jacobian.hpp"
#include "quality/mesh_quality.hpp"

namespace {

using homesh::Mesh;

struct Options {
  std::string mesh;
  std::string cad = std::string(HOMESH_SOURCE_DIR) + "/examples/bracket.step";
  double size = 2.5;
  int order = 4;
  int threads = 2;
  int repeat = 3;
};

Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto next = [&]() -> std::string {
      if (i + 1 >= argc) throw homesh::ParameterError(a + " needs a value");
      return argv[++i];
    };
    if (a == "--mesh") {
      o.mesh = next();
    } else if (a == "--cad") {
      o.cad = next();
    } else if (a == "--size") {
      o.size = std::stod(next());
    } else if (a == "--order") {
      o.order = std::stoi(next());
    } else if (a == "--threads") {
      o.threads = std::stoi(next());
    } else if (a == "--repeat") {
      o.repeat = std::max(1, std::stoi(next()));
    } else {
      throw homesh::ParameterError("unknown argument '" + a + "'");
    }
  }
  return o;
}

double bestSeconds(int repeat, const std::function<void()>& run) {
  double best = 1e300;
  for (int r = 0; r < repeat; ++r) {
    const auto start = std::chrono::steady_clock::now();
    run();
    const std::chrono::duration<double> s = std::chrono::steady_clock::now() - start;
    best = std::min(best, s.count());
  }
  return best;
}

// HOMesh's certified scaled Jacobian alone (what Gmsh's plugin computes): its worst value.
double homeshScaledJacobian(const Mesh& mesh, int threads) {
  double worst = 1e300;
  for (const homesh::ElementBlock& block : mesh.blocks) {
    if (homesh::cellDimension(block.type) != mesh.dim) continue;
    const int n = block.nodesPerElement();
    const auto count = static_cast<long>(block.count());
#pragma omp parallel for num_threads(threads) schedule(dynamic, 16) reduction(min : worst)
    for (long e = 0; e < count; ++e) {
      const std::int64_t* nodes = block.element(static_cast<std::size_t>(e));
      homesh::NodeCoordinates x(n, 3);
      for (int i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) x(i, c) = mesh.xyz[3 * nodes[i] + c];
      worst = std::min(worst,
                       homesh::boundJacobian(block.type, block.order, x, nullptr).scaledJacobian());
    }
  }
  return worst;
}

int run(const Options& o) {
  std::string path = o.mesh;
  std::string generated;  // a mesh file we made, removed at the end
  Mesh mesh;
  if (path.empty()) {
    homesh::MeshingOptions m;
    m.order = o.order;
    m.size = o.size;
    m.threads = o.threads;
    std::printf("meshing %s at size %g, order %d ...\n", o.cad.c_str(), o.size, o.order);
    mesh = homesh::runMeshPipeline(homesh::CadSource::file(o.cad), m).mesh;
    path = (std::filesystem::temp_directory_path() /
            ("homesh_bench_quality_" + std::to_string(getpid()) + ".msh"))
               .string();
    homesh::writeMesh(mesh, path, {}, {true, false, {}});
    generated = path;
  } else {
    mesh = homesh::readMesh(path);
  }
  if (mesh.dim != 3) throw homesh::ParameterError("the benchmark mesh must be 3D");
  const auto elements = static_cast<double>(mesh.numElements());
  std::printf("mesh: %zu elements of order %d, %zu nodes (%s)\n", mesh.numElements(), mesh.order,
              mesh.numNodes(), path.c_str());

  gmsh::initialize(0, nullptr, false);
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::open(path);
  double gmshWorst = 0.0;
  const double gmshSeconds =
      bestSeconds(o.repeat, [&] { gmshWorst = homesh::peers::gmshAnalyseScaledJacobian(3); });
  gmsh::finalize();
  if (!generated.empty()) std::filesystem::remove(generated);

  double worst1 = 0.0, worstN = 0.0;
  const double one = bestSeconds(o.repeat, [&] { worst1 = homeshScaledJacobian(mesh, 1); });
  const double many =
      bestSeconds(o.repeat, [&] { worstN = homeshScaledJacobian(mesh, o.threads); });
  const double full1 = bestSeconds(o.repeat, [&] { homesh::evaluateQuality(mesh, 1); });
  const double fullN = bestSeconds(o.repeat, [&] { homesh::evaluateQuality(mesh, o.threads); });

  std::printf("\nworst scaled Jacobian: Gmsh %.6f, HOMesh %.6f (difference %.1e)\n", gmshWorst,
              worst1, std::abs(gmshWorst - worst1));
  if (worst1 != worstN) std::printf("WARNING: thread count changed the result\n");
  std::printf("\n%-46s %10s %14s %8s\n", "", "seconds", "elements/s", "vs Gmsh");
  const auto line = [&](const char* what, double s) {
    std::printf("%-46s %10.4f %14.0f %7.2fx\n", what, s, elements / s, gmshSeconds / s);
  };
  line("Gmsh AnalyseMeshQuality (1 thread)", gmshSeconds);
  line("HOMesh scaled Jacobian, 1 thread", one);
  std::string label = "HOMesh scaled Jacobian, " + std::to_string(o.threads) + " threads";
  line(label.c_str(), many);
  line("HOMesh full quality (+ distortion), 1 thread", full1);
  label = "HOMesh full quality, " + std::to_string(o.threads) + " threads";
  line(label.c_str(), fullN);
  std::printf("\nratio (HOMesh 1 thread elements/s over Gmsh's): %.2f\n", gmshSeconds / one);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(parse(argc, argv));
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_quality_throughput: %s\n", e.what());
  } catch (const std::string& e) {  // Gmsh throws strings
    std::fprintf(stderr, "bench_quality_throughput: Gmsh: %s\n", e.c_str());
  }
  return 1;
}

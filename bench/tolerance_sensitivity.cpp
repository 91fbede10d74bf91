// How far the figures that the tests check against thresholds move when nothing but the last
// bits change: the results of iterative processes (optimiser sweeps, Gmsh's meshing, the sizing
// octree) depend on the CPU's floating-point paths, so their test margins are set to a
// generous multiple of what is measured here (docs/testing.md lists them).
//
//   bench_tolerance_sensitivity [GROUP...]     GROUP = optimiser | pipeline | sizing
//
// Each figure is computed for several variants of the same input: the reference run (1 thread),
// 2 threads, and the input coordinates (or the CAD's scale and the sizes with it) multiplied by
// 1 + 1e-12 u, u in [-1, 1] drawn per node (seeds 1, 2) or fixed (CAD: u = +1, -1). The spread
// (max - min over the variants) is what a different CPU can do to the figure.
#include <BRepPrimAPI_MakeSphere.hxx>
#include <BRepPrimAPI_MakeTorus.hxx>
#include <BRepTools.hxx>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <functional>
#include <map>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "curving/order_elevation.hpp"
#include "io/mesh_readers.hpp"
#include "optimise/optimiser.hpp"
#include "pipeline/case_setup.hpp"
#include "pipeline/mesh_pipeline.hpp"

namespace {

using homesh::Mesh;

const std::string kShared = std::string(HOMESH_SOURCE_DIR) + "/../shared/peer-cases/nekmesh/";
const std::string kData = std::string(HOMESH_SOURCE_DIR) + "/tests/data/";

struct Variant {
  const char* name;
  int threads;
  int seed;         // > 0: per-node relative perturbation of mesh coordinates
  double relative;  // CAD scale and sizes multiplied by 1 + relative
};
const Variant kVariants[] = {{"1 thread", 1, 0, 0.0},
                             {"2 threads", 2, 0, 0.0},
                             {"nodes*(1+1e-12u) seed 1 / CAD*(1+1e-12)", 1, 1, 1e-12},
                             {"nodes*(1+1e-12u) seed 2 / CAD*(1-1e-12)", 1, 2, -1e-12}};

// name -> value per variant
using Figures = std::map<std::string, double>;

void report(const std::string& title, const std::vector<Figures>& runs) {
  std::printf("\n%s\n", title.c_str());
  std::printf("  %-34s", "figure");
  for (const Variant& v : kVariants) std::printf(" %13.13s", v.name);
  std::printf(" %11s\n", "spread");
  for (const auto& [name, first] : runs.front()) {
    std::printf("  %-34s", name.c_str());
    double lo = first, hi = first;
    for (const Figures& f : runs) {
      const double x = f.at(name);
      lo = std::min(lo, x);
      hi = std::max(hi, x);
      std::printf(" %13.7g", x);
    }
    std::printf(" %11.3g\n", hi - lo);
  }
  std::fflush(stdout);
}

void perturb(Mesh& mesh, int seed) {
  if (seed <= 0) return;
  std::mt19937_64 rng(static_cast<unsigned>(seed));
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (double& x : mesh.xyz) x *= 1.0 + 1e-12 * u(rng);
}

void optimiserGroup() {
  const std::string dir = kShared + "optimiser/";
  std::vector<Figures> p3, naca, p4;
  for (const Variant& v : kVariants) {
    {
      // tests: OptimiserPeer.CubeSphereOrder3FiveIterations, test_cube_sphere_order_3_like_nekmesh
      Mesh m = homesh::changeOrder(homesh::readMesh(dir + "varopti_cube_sphere.msh"), 3, nullptr);
      perturb(m, v.seed);
      homesh::OptimiserOptions o;
      o.maxIterations = 5;
      o.threads = v.threads;
      const homesh::OptimiserResult r = homesh::optimiseMesh(m, o);
      p3.push_back({{"nodal worst after", r.nodalWorstAfter},
                    {"certified worst after", r.worstAfter},
                    {"iterations", double(r.iterations)}});
    }
    {
      // tests: OptimiserPeer.NacaLinearElasticFiveIterations,
      // test_optimise_command_logs_each_sweep_and_reports
      Mesh m = homesh::readMesh(dir + "varopti_naca.msh");
      perturb(m, v.seed);
      homesh::OptimiserOptions o;
      o.functional = homesh::Functional::LinearElastic;
      o.maxIterations = 5;
      o.threads = v.threads;
      const homesh::OptimiserResult r = homesh::optimiseMesh(m, o);
      naca.push_back({{"nodal worst after", r.nodalWorstAfter},
                      {"certified worst after", r.worstAfter},
                      {"after - before", r.worstAfter - r.worstBefore},
                      {"iterations", double(r.iterations)}});
    }
    {
      // test: OptimiserPeer.CubeSphereOrder4ConvergesAbove0757AndKeepsTheBoundary
      Mesh m = homesh::readMesh(dir + "varopti_cube_sphere.msh");
      perturb(m, v.seed);
      homesh::OptimiserOptions o;
      o.maxIterations = 60;
      o.threads = v.threads;
      const homesh::OptimiserResult r = homesh::optimiseMesh(m, o);
      p4.push_back({{"nodal worst after", r.nodalWorstAfter},
                    {"certified worst after", r.worstAfter},
                    {"iterations", double(r.iterations)}});
    }
  }
  // tests/python/test_optimise.py: Gmsh's tangled order-4 sphere in a box (a stored file: Gmsh
  // makes an untangled mesh from the same .geo when its input moves by 1e-12).
  std::vector<Figures> freeRuns, fixedRuns;
  const std::string tangledPath = "/tmp/homesh_sphere_in_box_p4.msh";
  if (std::system(("gzip -dc " + kData + "sphere_in_box_p4.msh.gz > " + tangledPath).c_str()) != 0)
    throw std::runtime_error("cannot unpack " + kData + "sphere_in_box_p4.msh.gz");
  for (const Variant& v : kVariants) {
    for (const bool freeInterfaces : {true, false}) {
      Mesh m = homesh::readMesh(tangledPath);
      perturb(m, v.seed);
      homesh::OptimiserOptions o;
      o.maxIterations = freeInterfaces ? 10 : 6;
      o.freeInterfaces = freeInterfaces;
      o.threads = v.threads;
      const homesh::OptimiserResult r = homesh::optimiseMesh(m, o);
      int firstValid = 0;
      for (const homesh::IterationRecord& h : r.history)
        if (firstValid == 0 && h.invalid == 0) firstValid = h.iteration;
      Figures f = {{"invalid before", double(r.invalidBefore)},
                   {"worst before", r.worstBefore},
                   {"invalid after", double(r.invalidAfter)},
                   {"worst after", r.worstAfter},
                   {"kept iteration", double(r.keptIteration)}};
      if (freeInterfaces) f["first valid sweep"] = firstValid;
      (freeInterfaces ? freeRuns : fixedRuns).push_back(f);
    }
  }
  report("tangled sphere in box P4, free interfaces, 10 sweeps", freeRuns);
  report("tangled sphere in box P4, fixed interfaces, 6 sweeps", fixedRuns);
  report("cube-sphere P3, hyperelastic, 5 sweeps", p3);
  report("NACA P3, linear elastic, 5 sweeps", naca);
  report("cube-sphere P4, hyperelastic, 60 sweeps", p4);
}

std::string shapeText(const TopoDS_Shape& shape) {
  std::ostringstream out;
  BRepTools::Write(shape, out);
  return out.str();
}

// Gmsh's linear mesh, elevated, optimised with boundary nodes sliding on the CAD.
void pipelineGroup() {
  struct Case {
    std::string title;
    std::function<TopoDS_Shape(double)> shape;  // scaled by the factor given
    double size;
  };
  const std::vector<Case> cases = {
      {"sphere r 1, P4, size 0.5, 5 sweeps (MeshPipeline.OptimiserSlides..., Python, CLI)",
       [](double s) { return BRepPrimAPI_MakeSphere(1.0 * s).Shape(); }, 0.5},
      {"torus 2 / 0.6, P4, size 0.4, 5 sweeps (MeshPipeline.OptimiserSlides...)",
       [](double s) { return BRepPrimAPI_MakeTorus(2.0 * s, 0.6 * s).Shape(); }, 0.4}};
  for (const Case& c : cases) {
    std::vector<Figures> runs;
    for (const Variant& v : kVariants) {
      const double s = 1.0 + v.relative;
      homesh::MeshingOptions options;
      options.order = 4;
      options.size = c.size * s;
      options.threads = v.threads;
      options.optimiseIterations = 5;
      const homesh::MeshResult r =
          homesh::runMeshPipeline(homesh::CadSource::brepText(shapeText(c.shape(s))), options);
      double smallestGain = 1.0;
      double previous = r.optimiser->worstBefore;
      for (const homesh::IterationRecord& h : r.optimiser->history) {
        smallestGain = std::min(smallestGain, h.worst - previous);
        previous = h.worst;
      }
      double onFaces = 0.0;
      for (const std::uint8_t d : r.mesh.nodeCadDim) onFaces += d == 2 ? 1.0 : 0.0;
      runs.push_back({{"elements", double(r.mesh.numElements())},
                      {"nodes on faces", onFaces},
                      {"worst before", r.optimiser->worstBefore},
                      {"worst after", r.optimiser->worstAfter},
                      {"after - before", r.optimiser->worstAfter - r.optimiser->worstBefore},
                      {"iterations (stall 1e-3)", double(r.optimiser->iterations)},
                      {"smallest sweep gain", smallestGain},
                      {"invalid after", double(r.optimiser->invalidAfter)}});
    }
    report(c.title, runs);
  }
}

// Boundary edges whose length / delta(midpoint) lies in [0.5, 1.5] (as the PeerCase test).
double fractionWithinSpec(const Mesh& mesh, const homesh::SizingOctree& octree) {
  for (const homesh::ElementBlock& b : mesh.blocks) {
    if (homesh::cellDimension(b.type) != mesh.dim - 1) continue;
    const int nv = homesh::cellNumVertices(b.type);
    std::size_t good = 0, total = 0;
    for (std::size_t e = 0; e < b.count(); ++e) {
      const std::int64_t* n = b.element(e);
      for (int k = 0; k < (nv == 2 ? 1 : 3); ++k) {
        const Eigen::Vector3d p(&mesh.xyz[3 * n[k]]), q(&mesh.xyz[3 * n[(k + 1) % nv]]);
        const double ratio = (p - q).norm() / octree.delta(0.5 * (p + q));
        good += (ratio >= 0.5 && ratio <= 1.5) ? 1 : 0;
        ++total;
      }
    }
    return double(good) / double(total);
  }
  return 0.0;
}

void scaleSizes(homesh::SizingParameters& p, double s) {
  p.minDelta *= s;
  p.maxDelta *= s;
}

void sizingGroup() {
  // The NekMesh meshgen cases (PeerCase.*, test_mcf_case_meshes_with_its_prediction).
  for (const char* name :
       {"3d_sphere", "3d_bl_cyl", "2d_bl_aerofoil", "2d_bl_t106", "2d_bl_naca0012"}) {
    std::vector<Figures> runs;
    for (const Variant& v : kVariants) {
      homesh::CaseSetup setup = homesh::setupCase(kShared + "meshgen/" + name + ".mcf");
      const double s = 1.0 + v.relative;
      if (setup.source.kind == homesh::CadSource::Kind::Naca)
        setup.source.naca.aoaDegrees *= s;
      else
        setup.source.scale *= s;
      scaleSizes(*setup.options.sizing, s);
      setup.options.order = 1;
      setup.options.threads = v.threads;
      const homesh::MeshResult r = homesh::runMeshPipeline(setup.source, setup.options);
      const auto actual = double(r.mesh.numElements());
      runs.push_back({{"predicted", r.sizing->prediction.elements},
                      {"actual", actual},
                      {"predicted / actual", r.sizing->prediction.elements / actual},
                      {"edges within spec", fractionWithinSpec(r.mesh, *r.sizing->octree)}});
    }
    report(std::string("meshgen ") + name, runs);
  }
  {
    // SizingPipeline.HalvingEpsRefinesTheSphereAsTheChordFormulaPredicts
    std::vector<Figures> runs;
    for (const Variant& v : kVariants) {
      const auto curvedTriangles = [&](double eps) {
        homesh::CaseSetup setup = homesh::setupCase(kShared + "meshgen/3d_sphere.mcf");
        const double s = 1.0 + v.relative;
        setup.source.scale *= s;
        scaleSizes(*setup.options.sizing, s);
        setup.options.order = 1;
        setup.options.threads = v.threads;
        setup.options.sizing->eps = eps;
        const homesh::MeshResult r = homesh::runMeshPipeline(setup.source, setup.options);
        std::size_t count = 0;
        for (const homesh::ElementBlock& b : r.mesh.blocks)
          if (homesh::cellDimension(b.type) == 2)
            for (const std::int32_t f : b.entity) count += r.cad->isPlanar(f) ? 0 : 1;
        return double(count);
      };
      const double expected =
          std::pow(homesh::chordSize(0.25, 0.02) / homesh::chordSize(0.25, 0.01), 2.0);
      runs.push_back({{"(fine / coarse) / expected",
                       curvedTriangles(0.01) / curvedTriangles(0.02) / expected}});
    }
    report("3d_sphere, EPS 0.02 -> 0.01, curved boundary triangles", runs);
  }
  // Plain CAD with automatic or explicit sizes (SizingPipeline.AutomaticSizingWithoutParameters,
  // test_plain_cad_gets_automatic_sizing, test_python_predict_matches_the_mesh, the FreeCAD
  // Sizing object's prediction test).
  struct Plain {
    std::string title, file;
    homesh::SizingParameters p;  // zeros: automatic
  };
  std::vector<Plain> plain(4);
  plain[0] = {"sphere.brep, automatic sizes", kData + "sphere.brep", {}};
  plain[1] = {"box_hole.step, automatic sizes", kData + "box_hole.step", {}};
  plain[2] = {"sphere.brep, 0.05 / 0.2 / 0.05", kData + "sphere.brep", {}};
  plain[2].p.minDelta = 0.05;
  plain[2].p.maxDelta = 0.2;
  plain[2].p.eps = 0.05;
  plain[3] = {
      "box_hole.step, 0.1 / 0.5 / 0.02, sphere source (FreeCAD)", kData + "box_hole.step", {}};
  plain[3].p.minDelta = 0.1;
  plain[3].p.maxDelta = 0.5;
  plain[3].p.eps = 0.02;
  plain[3].p.sources.push_back(homesh::RefinementSource::sphere({0, 0, 0}, 1.0, 0.15));
  for (const Plain& c : plain) {
    std::vector<Figures> runs;
    for (const Variant& v : kVariants) {
      const double s = 1.0 + v.relative;
      homesh::CadSource source = homesh::CadSource::file(c.file);
      source.scale = s;
      homesh::MeshingOptions options;
      options.order = 1;
      options.threads = v.threads;
      if (c.p.maxDelta > 0.0) {
        homesh::SizingParameters p = c.p;
        scaleSizes(p, s);
        for (homesh::RefinementSource& r : p.sources)
          r = homesh::RefinementSource::sphere({0, 0, 0}, 1.0 * s, 0.15 * s);
        options.sizing = p;
      }
      const homesh::MeshResult r = homesh::runMeshPipeline(source, options);
      const auto actual = double(r.mesh.numElements());
      runs.push_back(
          {{"predicted / actual", r.sizing->prediction.elements / actual}, {"actual", actual}});
    }
    report(c.title, runs);
  }
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::vector<std::string> groups(argv + 1, argv + argc);
    if (groups.empty()) groups = {"optimiser", "pipeline", "sizing"};
    for (const std::string& g : groups) {
      if (g == "optimiser")
        optimiserGroup();
      else if (g == "pipeline")
        pipelineGroup();
      else if (g == "sizing")
        sizingGroup();
      else
        throw std::runtime_error("unknown group " + g + " (optimiser, pipeline, sizing)");
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "bench_tolerance_sensitivity: %s\n", e.what());
    return 1;
  }
}

// The `homesh` command-line tool. See usageText() in arguments.cpp for the commands.
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_PrinterOStream.hxx>
#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include "cli/arguments.hpp"
#include "core/error.hpp"
#include "core/input_file.hpp"
#include "core/version.hpp"
#include "curving/order_elevation.hpp"
#include "io/atomic_file.hpp"
#include "io/cgns_writer.hpp"
#include "io/mesh_readers.hpp"
#include "io/mesh_writers.hpp"
#include "optimise/optimiser.hpp"
#include "pipeline/case_setup.hpp"
#include "pipeline/geometry_check.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "pipeline/mesh_summary.hpp"
#include "pipeline/nektar_read_back.hpp"
#include "pipeline/report.hpp"

namespace {

// `homesh mesh`: the mesh was made and written, but elements are still not proven valid.
constexpr int kNotProvenValid = 4;

// Prints each stage as it ends, on stderr (stdout may carry the JSON report).
class StderrProgress : public homesh::PipelineObserver {
 public:
  void stageFinished(const std::string& stage, double seconds) override {
    std::fprintf(stderr, "homesh: %-10s %8.3f s\n", stage.c_str(), seconds);
  }
};

// OCCT's readers print statistics to stdout; the command line keeps stdout for the report.
void silenceOcct() {
  const Handle(Message_Messenger)& messenger = Message::DefaultMessenger();
  messenger->RemovePrinters(STANDARD_TYPE(Message_PrinterOStream));
}

void writeReport(const std::string& path, const std::string& text) {
  if (path == "-") {
    std::cout << text << std::flush;
    return;
  }
  homesh::writeFileAtomically(path, text);
}

// Reads each written .xml back as Nektar++ builds it (pipeline/nektar_read_back.hpp); returns
// its elements not proven valid (all files).
std::size_t checkNektarOutputs(const std::vector<std::string>& outputs, int threads, bool quiet) {
  std::size_t notValid = 0;
  for (const std::string& path : outputs) {
    if (std::filesystem::path(path).extension() != ".xml") continue;
    const homesh::NektarReadBack check = homesh::checkNektarReadBack(path, threads);
    notValid += check.invalid + check.undecided;
    if (!quiet || !check.proven()) std::fprintf(stderr, "homesh: %s\n", check.line().c_str());
  }
  return notValid;
}

// Refuses bad output and report paths before any time is spent.
// Refuses, before any work, outputs that cannot be written and any output (mesh or report)
// that is the input itself: the input would be replaced by what was made from it.
// `inputs`: the files the command reads (the mesh or CAD, and curve's CAD), which no output may
// replace.
void checkOutputs(const homesh::CommonOptions& c, const std::vector<std::string>& inputs) {
  const auto readFile = [&inputs](const std::string& path) -> const std::string* {
    for (const std::string& input : inputs) {
      std::error_code error;
      if (std::filesystem::equivalent(path, input, error) && !error) return &input;
    }
    return nullptr;
  };
  for (const std::string& path : c.outputs) {
    if (const std::string* input = readFile(path))
      throw homesh::IoError("output '" + path + "' is the input file '" + *input +
                            "'; write to another file");
    homesh::checkMeshOutputPath(path);
  }
  if (c.report && *c.report != "-") {
    if (const std::string* input = readFile(*c.report))
      throw homesh::IoError("report '" + *c.report + "' is the input file '" + *input +
                            "'; write to another file");
    homesh::checkParentFolder(*c.report);
  }
}

// `read`: the groups the input mesh file named (CGNS boundary conditions), kept unless the
// command line names its own.
homesh::WriteOptions writeOptions(const homesh::CommonOptions& c,
                                  const std::vector<homesh::NamedGroup>& read = {}) {
  homesh::WriteOptions w;
  w.binary = c.binary;
  w.compressed = c.compressed;
  for (const auto& [name, entities] : c.groups) w.groups.push_back({name, entities});
  if (c.groups.empty()) w.groups = read;
  return w;
}

// What no CGNS file can hold (io/cgns_writer.hpp) is refused before the work, not after it.
void checkCgnsOrder(const homesh::CommonOptions& c, int order) {
  for (const std::string& path : c.outputs) {
    if (homesh::lowerExtension(path) != ".cgns") continue;
    try {
      homesh::checkCgnsOutput(order, writeOptions(c).groups);
    } catch (const homesh::ParameterError& e) {
      throw homesh::ParameterError("cannot write " + path + ": " + e.what());
    }
  }
}

// The case from INPUT (CAD file or .mcf) with the command line's options over it: the table's
// (`values`, checked by MeshingOptions::apply), then the refinement sources and octree output;
// the rules between options (a uniform size or octree sizing, ...) are the core's validate().
homesh::CaseSetup setupWithFlags(const std::string& input, const homesh::OptionMap& values,
                                 const homesh::SizingFlags& flags, const homesh::CommonOptions& c) {
  homesh::CaseSetup setup = homesh::setupCase(input);
  if (!c.quiet)
    for (const std::string& notice : setup.notices)
      std::fprintf(stderr, "homesh: note: %s\n", notice.c_str());
  homesh::MeshingOptions& options = setup.options;
  options.threads = c.threads;
  options.apply(values);  // over the case's: what the command line gives wins
  if (!flags.sources.empty()) {
    homesh::SizingParameters p = options.sizing.value_or(homesh::SizingParameters{});
    p.sources.insert(p.sources.end(), flags.sources.begin(), flags.sources.end());
    options.sizing = p;
  }
  if (flags.writeOctree) {
    homesh::checkMeshOutputPath(*flags.writeOctree);
    options.octreeOutput = *flags.writeOctree;
  }
  options.validate();
  return setup;
}

void printPrediction(const homesh::SizingResult& s, int dim) {
  for (const std::string& line : homesh::predictionLines(s, dim))
    std::fprintf(stderr, "homesh: %s\n", line.c_str());
}

// The end of `mesh` and `curve`: the mesh written, its summary printed (with `octree`, written
// before), the report, Nektar++'s reading of any .xml checked; the exit status.
int finishMeshJob(homesh::MeshResult& result, const homesh::CommonOptions& c,
                  const std::string& input, homesh::PipelineObserver* observer,
                  const std::optional<std::string>& octree) {
  if (!c.outputs.empty()) homesh::writeMeshOutputs(result, c.outputs, writeOptions(c), observer);
  if (!c.quiet) {
    for (const std::string& line : homesh::meshSummaryLines(result))
      std::fprintf(stderr, "homesh: %s\n", line.c_str());
    if (octree) std::fprintf(stderr, "homesh: wrote %s\n", octree->c_str());
    for (const std::string& path : c.outputs)
      std::fprintf(stderr, "homesh: wrote %s\n", path.c_str());
  }
  if (c.report) writeReport(*c.report, homesh::meshReportJson(result, input));
  const std::size_t nektarNotValid = checkNektarOutputs(c.outputs, c.threads, c.quiet);
  // The mesh is written either way; status 4 tells scripts it is not proven valid.
  if (result.quality.invalid + result.quality.undecided > 0) {
    if (!c.quiet)
      std::fprintf(stderr, "homesh: %zu %s invalid, %zu undecided (exit status 4)\n",
                   result.quality.invalid, result.quality.invalid == 1 ? "element" : "elements",
                   result.quality.undecided);
    return kNotProvenValid;
  }
  if (nektarNotValid > 0) {
    std::fprintf(stderr,
                 "homesh: the mesh is valid, but not the geometry Nektar++ builds from the .xml "
                 "(exit status 4)\n");
    return kNotProvenValid;
  }
  return 0;
}

int runMesh(const homesh::MeshCommand& cmd) {
  const homesh::CommonOptions& c = cmd.common;
  checkOutputs(c, {cmd.input});
  homesh::CaseSetup setup = setupWithFlags(cmd.input, cmd.options, cmd.sizing, c);
  homesh::MeshingOptions& options = setup.options;
  if (cmd.blFaces || cmd.blThickness || cmd.blLayers || cmd.blProgression || cmd.blSolids) {
    homesh::BoundaryLayerParameters bl =
        options.boundaryLayer.value_or(homesh::BoundaryLayerParameters{});
    if (cmd.blFaces) bl.faces = homesh::parseIndexList(*cmd.blFaces, "--bl-faces");
    if (cmd.blSolids) bl.solids = homesh::parseIndexList(*cmd.blSolids, "--bl-solids");
    if (cmd.blThickness) bl.thickness = *cmd.blThickness;
    if (cmd.blLayers) bl.layers = *cmd.blLayers;
    if (cmd.blProgression) bl.progression = *cmd.blProgression;
    options.boundaryLayer = bl;  // checked with the other options by the pipeline
  }
  checkCgnsOrder(c, options.order);
  StderrProgress progress;
  homesh::PipelineObserver* observer = c.quiet ? nullptr : &progress;
  homesh::MeshResult result = homesh::runMeshPipeline(setup.source, options, observer);
  return finishMeshJob(result, c, cmd.input, observer, cmd.sizing.writeOctree);
}

int runPredict(const homesh::PredictCommand& cmd) {
  const homesh::CommonOptions& c = cmd.common;
  checkOutputs(c, {cmd.input});
  homesh::CaseSetup setup = setupWithFlags(cmd.input, cmd.options, cmd.sizing, c);
  const homesh::SizingResult s = homesh::runSizingStage(setup.source, setup.options);
  const bool toStdout = c.report && *c.report == "-";
  if (!c.quiet) {
    for (const std::string& note : s.healing.notes())
      std::fprintf(stderr, "homesh: note: %s\n", note.c_str());
    printPrediction(s, s.prediction.dim);  // (2 for a surface mesh, whose octree is 3D)
    if (cmd.sizing.writeOctree)
      std::fprintf(stderr, "homesh: wrote %s\n", cmd.sizing.writeOctree->c_str());
  }
  if (!toStdout) std::printf("%.0f\n", s.prediction.elements);
  if (c.report) writeReport(*c.report, homesh::predictReportJson(s, cmd.input));
  return 0;
}

// A human-readable quality summary.
void printQuality(std::FILE* out, const std::string& input, const homesh::Mesh& mesh,
                  const homesh::QualitySummary& q) {
  std::fprintf(out, "%s: %zu nodes, order %d\n", input.c_str(), mesh.numNodes(), mesh.order);
  for (const auto& [type, t] : q.byType)
    std::fprintf(out,
                 "  %-5s %8zu elements  scaled Jacobian worst %8.4f mean %6.4f  distortion worst "
                 "%8.4f mean %6.4f  invalid %zu\n",
                 homesh::cellShortName(type).c_str(), t.count, t.scaledJacobian.min,
                 t.scaledJacobian.mean, t.distortion.min, t.distortion.mean, t.invalid);
  std::fprintf(out, "  scaled Jacobian (certified lower bound, Bezier): worst %.4f mean %.4f\n",
               q.scaled.min, q.scaled.mean);
  std::fprintf(out, "  invalid elements %zu, undecided %zu: %s\n", q.invalid, q.undecided,
               q.invalid > 0     ? "INVALID"
               : q.undecided > 0 ? "validity not proven"
                                 : "certified valid");
  const std::size_t flagged = q.invalid + q.undecided;
  const auto listed = homesh::flaggedElements(mesh, q, 10);
  for (const homesh::FlaggedElement& f : listed)
    std::fprintf(out, "    element %zu (%s, entity %d): %s, min J / max J in [%.4g, %.4g]\n",
                 f.index, homesh::cellShortName(f.type).c_str(), f.entity,
                 homesh::validityName(f.validity), f.lower, f.upper);
  if (flagged > listed.size())
    std::fprintf(out, "    ... and %zu more (the JSON report lists %zu)\n", flagged - listed.size(),
                 std::min(flagged, homesh::kMaxFlaggedElements));
  std::fprintf(out, "  histogram of the scaled Jacobian:\n");
  if (q.scaled.histogram.below > 0)
    std::fprintf(out, "    < 0          %8zu\n", q.scaled.histogram.below);
  for (int k = 0; k < homesh::Histogram::kBins; ++k)
    if (q.scaled.histogram.counts[k] > 0)
      std::fprintf(out, "    [%.2f, %.2f) %8zu\n", double(k) / homesh::Histogram::kBins,
                   double(k + 1) / homesh::Histogram::kBins, q.scaled.histogram.counts[k]);
}

// Reads a mesh file, printing on stderr (unless quiet) what reading changed.
homesh::Mesh readMeshFile(const std::string& path, bool quiet, std::vector<std::string>& notes,
                          std::vector<homesh::NamedGroup>* groups = nullptr) {
  homesh::Mesh mesh = homesh::readMesh(path, &notes, groups);
  if (!quiet)
    for (const std::string& note : notes) std::fprintf(stderr, "homesh: note: %s\n", note.c_str());
  return mesh;
}

// How closely the boundary follows the CAD (homesh quality --cad).
void printGeometry(std::FILE* out, const homesh::FileGeometry& g) {
  const homesh::GeometryAccuracy& a = g.accuracy;
  std::fprintf(out, "  against %s:\n", g.cad.c_str());
  std::fprintf(out,
               "    distance to the CAD: max %.3g (%.3g of the diagonal, at %s), mean %.3g of "
               "the diagonal, %zu samples\n",
               a.maxDistance, a.maxDistanceRelative(),
               a.worstEntity.empty() ? "-" : a.worstEntity.c_str(), a.meanDistanceRelative(),
               a.samples);
  std::fprintf(out, "    normal angle to the CAD: max %.3g deg (at %s), mean %.3g deg",
               a.maxAngleDeg, a.worstAngleEntity.empty() ? "-" : a.worstAngleEntity.c_str(),
               a.meanAngleDeg);
  if (a.undefinedNormals > 0)
    std::fprintf(out, ", %zu samples where the CAD has no normal", a.undefinedNormals);
  std::fprintf(out, "\n");
}

int runQuality(const homesh::QualityCommand& cmd) {
  checkOutputs(cmd.common, {cmd.input, cmd.cad});
  std::vector<std::string> notes;
  const homesh::Mesh mesh = readMeshFile(cmd.input, cmd.common.quiet, notes);
  const homesh::QualitySummary q = homesh::evaluateQuality(mesh, cmd.common.threads);
  std::optional<homesh::FileGeometry> geometry;
  if (!cmd.cad.empty()) {
    homesh::MeshingOptions options;
    options.apply(cmd.options);
    geometry = homesh::FileGeometry{
        cmd.cad, homesh::checkGeometryAgainstCad(mesh, cmd.cad, cmd.common.threads,
                                                 options.classifyTolerance)};
  }
  std::FILE* out = cmd.common.report && *cmd.common.report == "-" ? stderr : stdout;
  if (!cmd.common.quiet) {
    printQuality(out, cmd.input, mesh, q);
    if (geometry) printGeometry(out, *geometry);
  }
  if (cmd.common.report)
    writeReport(*cmd.common.report, homesh::qualityReportJson(mesh, q, cmd.input, notes,
                                                              geometry ? &*geometry : nullptr));
  return cmd.strict && (q.invalid > 0 || q.undecided > 0) ? 3 : 0;
}

int runConvert(const homesh::ConvertCommand& cmd) {
  checkOutputs(cmd.common, {cmd.input});
  std::vector<std::string> notes;
  std::vector<homesh::NamedGroup> groups;
  const homesh::Mesh mesh = readMeshFile(cmd.input, cmd.common.quiet, notes, &groups);
  checkCgnsOrder(cmd.common, mesh.order);
  const homesh::QualitySummary q = homesh::evaluateQuality(mesh, cmd.common.threads);
  for (const std::string& path : cmd.common.outputs) {
    homesh::writeMesh(mesh, path, homesh::qualityFields(q), writeOptions(cmd.common, groups));
    if (!cmd.common.quiet) std::fprintf(stderr, "homesh: wrote %s\n", path.c_str());
  }
  checkNektarOutputs(cmd.common.outputs, cmd.common.threads, cmd.common.quiet);
  return 0;
}

// Prints each sweep's state on stderr.
class SweepLog : public homesh::OptimiserObserver {
 public:
  void iterationFinished(const homesh::IterationRecord& r) override {
    std::fprintf(stderr,
                 "homesh: iteration %3d  worst scaled Jacobian %8.5f  invalid %zu  undecided %zu  "
                 "max move %.3g (%.3g of its element)  energy %.6g  %.3f s\n",
                 r.iteration, r.worst, r.invalid, r.undecided, r.maxDisplacement, r.maxRelativeMove,
                 r.energy, r.seconds);
  }
};

int runOptimise(const homesh::OptimiseCommand& cmd) {
  const homesh::CommonOptions& c = cmd.common;
  checkOutputs(c, {cmd.input});
  homesh::OptionMap values = cmd.options;
  values["threads"] = static_cast<double>(c.threads);
  homesh::OptimiserOptions options;
  options.apply(values);
  std::vector<std::string> notes;
  std::vector<homesh::NamedGroup> groups;
  homesh::Mesh mesh = readMeshFile(cmd.input, c.quiet, notes, &groups);
  checkCgnsOrder(c, cmd.order.value_or(mesh.order));
  if (cmd.order && *cmd.order != mesh.order) mesh = homesh::changeOrder(mesh, *cmd.order, nullptr);
  SweepLog log;
  const homesh::OptimiserResult r = homesh::optimiseMesh(mesh, options, c.quiet ? nullptr : &log);
  const homesh::QualitySummary q = homesh::evaluateQuality(mesh, c.threads);
  if (!c.quiet) {
    std::fprintf(
        stderr,
        "homesh: %s, %d iterations (stopped: %s), %zu free nodes in %zu colours, %.3f s (sweeps "
        "%.3f s)\n",
        homesh::functionalName(r.functional).c_str(), r.iterations, r.stopReason.c_str(),
        r.freeNodes, r.colours, r.seconds, r.sweepSeconds);
    std::fprintf(stderr,
                 "homesh: worst scaled Jacobian %.5f -> %.5f (at nodes %.5f -> %.5f), invalid %zu "
                 "-> %zu\n",
                 r.worstBefore, r.worstAfter, r.nodalWorstBefore, r.nodalWorstAfter,
                 r.invalidBefore, r.invalidAfter);
    if (r.keptIteration == 0 && r.iterations > 0)
      std::fprintf(stderr, "homesh: kept the input: no iteration was at least as good\n");
    else if (r.keptIteration != r.iterations)
      std::fprintf(stderr, "homesh: kept iteration %d (the best no worse than the input)\n",
                   r.keptIteration);
  }
  for (const std::string& path : c.outputs) {
    homesh::writeMesh(mesh, path, homesh::qualityFields(q), writeOptions(c, groups));
    if (!c.quiet) std::fprintf(stderr, "homesh: wrote %s\n", path.c_str());
  }
  if (c.report) writeReport(*c.report, homesh::optimiseReportJson(mesh, q, r, cmd.input, notes));
  checkNektarOutputs(c.outputs, c.threads, c.quiet);
  return 0;
}

// Curves another tool's linear volume mesh on its CAD (pipeline's curveMeshOnCad).
int runCurve(const homesh::CurveCommand& cmd) {
  const homesh::CommonOptions& c = cmd.common;
  checkOutputs(c, {cmd.input, cmd.cad});
  homesh::MeshingOptions options;
  options.threads = c.threads;
  options.apply(cmd.options);
  std::vector<std::string> notes;
  homesh::Mesh linear = readMeshFile(cmd.input, c.quiet, notes);
  if (linear.order > 1) {
    if (!c.quiet)
      std::fprintf(stderr,
                   "homesh: note: %s is of order %d: it is curved from its corners, the other "
                   "nodes dropped\n",
                   cmd.input.c_str(), linear.order);
    linear = homesh::changeOrder(linear, 1, nullptr);
  }
  checkCgnsOrder(c, options.order);
  // (Before the work, not after it: VTK 9.1 has no Lagrange pyramid; io/nektar_writer.hpp.)
  const bool pyramids =
      std::any_of(linear.blocks.begin(), linear.blocks.end(), [](const homesh::ElementBlock& b) {
        return b.type == homesh::CellType::Pyramid && b.count() > 0;
      });
  for (const std::string& path : c.outputs) {
    const std::string ext = homesh::lowerExtension(path);
    if (pyramids && ext == ".vtu" && options.order > 1)
      throw homesh::ParameterError(
          cmd.input + " holds pyramids, and VTU has no curved pyramid " +
          "(VTK 9.1 has no Lagrange pyramid): write " + path +
          (options.order > 2 ? " as .msh instead" : " as .msh or .xml instead"));
    if (pyramids && ext == ".xml" && options.order > 2)
      throw homesh::ParameterError(cmd.input + " holds pyramids, which Nektar++ XML takes up to " +
                                   "order 2 (above it Nektar++'s pyramid space is not ours, so " +
                                   "its geometry could not be certified): write " + path +
                                   " as .msh");
  }
  StderrProgress progress;
  homesh::PipelineObserver* observer = c.quiet ? nullptr : &progress;
  homesh::MeshResult result =
      homesh::curveMeshOnCad(homesh::CadSource::file(cmd.cad), linear, options, observer);
  return finishMeshJob(result, c, cmd.input, observer, std::nullopt);
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  try {
    silenceOcct();
    const homesh::ParsedCommand parsed = homesh::parseCommandLine(args);
    switch (parsed.kind) {
      case homesh::ParsedCommand::Kind::Help:
        std::cout << (parsed.helpTopic == "--man" ? homesh::manPage()
                                                  : homesh::usageText(parsed.helpTopic));
        return 0;
      case homesh::ParsedCommand::Kind::Version:
        std::cout << "homesh " << homesh::kVersion << "\n";
        return 0;
      case homesh::ParsedCommand::Kind::Mesh:
        return runMesh(parsed.mesh);
      case homesh::ParsedCommand::Kind::Predict:
        return runPredict(parsed.predict);
      case homesh::ParsedCommand::Kind::Quality:
        return runQuality(parsed.quality);
      case homesh::ParsedCommand::Kind::Convert:
        return runConvert(parsed.convert);
      case homesh::ParsedCommand::Kind::Optimise:
        return runOptimise(parsed.optimise);
      case homesh::ParsedCommand::Kind::Curve:
        return runCurve(parsed.curve);
    }
  } catch (const homesh::UsageError& e) {
    std::fprintf(stderr, "homesh: error: %s (see 'homesh --help')\n", e.message.c_str());
    return 2;
  } catch (const homesh::ParameterError& e) {
    std::fprintf(stderr, "homesh: error: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "homesh: error: %s\n", e.what());
    return 1;
  } catch (...) {
    std::fprintf(stderr, "homesh: error: unexpected internal failure\n");
    return 1;
  }
  return 1;
}

// The `homesh` command-line tool. See usageText() in arguments.cpp for the commands.
#include <Message.hxx>
#include <Message_Messenger.hxx>
#include <Message_PrinterOStream.hxx>
#include <cstdio>
#include <iostream>
#include <string>
#include <vector>

#include "cli/arguments.hpp"
#include "core/error.hpp"
#include "core/version.hpp"
#include "io/atomic_file.hpp"
#include "io/mesh_writers.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "pipeline/report.hpp"

namespace {

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

int runMesh(const homesh::MeshCommand& cmd) {
  homesh::MeshingOptions options;
  options.order = cmd.order;
  options.size = cmd.size;
  options.threads = cmd.threads;
  options.verbosity = cmd.verbosity;
  // Refuse bad output paths before spending time on meshing.
  for (const std::string& path : cmd.outputs) homesh::checkMeshOutputPath(path);
  if (cmd.report && *cmd.report != "-") homesh::checkParentFolder(*cmd.report);
  StderrProgress progress;
  homesh::PipelineObserver* observer = cmd.quiet ? nullptr : &progress;
  homesh::MeshResult result =
      homesh::runMeshPipeline(homesh::CadSource::file(cmd.input), options, observer);
  if (!cmd.outputs.empty()) homesh::writeMeshOutputs(result, cmd.outputs, observer);
  if (!cmd.quiet) {
    std::fprintf(stderr,
                 "homesh: %zu nodes, %zu elements of order %d; scaled Jacobian min %.4f mean "
                 "%.4f; %zu invalid\n",
                 result.mesh.numNodes(), result.mesh.numElements(), result.mesh.order,
                 result.quality.scaled.min, result.quality.scaled.mean, result.quality.invalid);
    for (const std::string& path : cmd.outputs)
      std::fprintf(stderr, "homesh: wrote %s\n", path.c_str());
  }
  if (cmd.report) writeReport(*cmd.report, homesh::meshReportJson(result, cmd.input));
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  try {
    silenceOcct();
    const homesh::ParsedCommand parsed = homesh::parseCommandLine(args);
    switch (parsed.kind) {
      case homesh::ParsedCommand::Kind::Help:
        std::cout << homesh::usageText(parsed.helpTopic);
        return 0;
      case homesh::ParsedCommand::Kind::Version:
        std::cout << "homesh " << homesh::kVersion << "\n";
        return 0;
      case homesh::ParsedCommand::Kind::Mesh:
        return runMesh(parsed.mesh);
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

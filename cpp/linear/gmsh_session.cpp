#include "linear/gmsh_session.hpp"

#include <gmsh.h>

#include <cstdio>
#include <utility>
#include <vector>

namespace homesh {
namespace {
std::mutex& gmshMutex() {
  static std::mutex mutex;
  return mutex;
}
}  // namespace

std::unique_lock<std::mutex> holdGmsh() {
  return std::unique_lock<std::mutex>(gmshMutex());
}

GmshSession::GmshSession(int verbosity, int threads)
    : GmshSession(holdGmsh(), verbosity, threads) {}

GmshSession::GmshSession(std::unique_lock<std::mutex> held, int verbosity, int threads,
                         GmshOutput output)
    : lock_(std::move(held)), verbosity_(verbosity), output_(output) {
  withGmshErrors("starting Gmsh", [&] {
    gmsh::initialize(0, nullptr, false);
    const bool terminal = output == GmshOutput::Terminal;
    gmsh::option::setNumber("General.Terminal", terminal ? 1 : 0);
    // Errors are always logged (gmshLastError explains failures); on a terminal, information
    // too (what meshes what, for the watch).
    gmsh::option::setNumber("General.Verbosity",
                            verbosity >= 2 ? 5 : (terminal ? 4 : (verbosity == 1 ? 2 : 1)));
    gmsh::option::setNumber("General.NumThreads", threads);
    gmsh::logger::start();
  });
}

GmshSession::~GmshSession() {
  try {
    if (verbosity_ > 0 && output_ == GmshOutput::Collected) {
      std::vector<std::string> log;
      gmsh::logger::get(log);
      for (const std::string& line : log) std::fprintf(stderr, "gmsh: %s\n", line.c_str());
    }
    gmsh::logger::stop();
    gmsh::finalize();
  } catch (...) {  // never throw from a destructor; Gmsh is unusable anyway if this fails
  }
}

std::string gmshLastError() {
  try {
    std::string error;
    gmsh::logger::getLastError(error);
    return error;
  } catch (...) {
    return {};
  }
}

}  // namespace homesh

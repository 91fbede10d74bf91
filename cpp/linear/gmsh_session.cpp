#include "linear/gmsh_session.hpp"

#include <gmsh.h>

namespace homesh {
namespace {
std::mutex& gmshMutex() {
  static std::mutex mutex;
  return mutex;
}
}  // namespace

GmshSession::GmshSession(int verbosity, int threads) : lock_(gmshMutex()) {
  withGmshErrors("starting Gmsh", [&] {
    gmsh::initialize(0, nullptr, false);
    gmsh::option::setNumber("General.Terminal", verbosity > 0 ? 1 : 0);
    gmsh::option::setNumber("General.Verbosity", verbosity >= 2 ? 5 : (verbosity == 1 ? 2 : 0));
    gmsh::option::setNumber("General.NumThreads", threads);
    gmsh::logger::start();
  });
}

GmshSession::~GmshSession() {
  try {
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

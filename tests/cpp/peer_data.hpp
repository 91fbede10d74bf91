// Where the C++ tests find NekMesh's peer files (../shared/peer-cases, another project's test
// data that the repository may not hold), looked up at run time, and the skip when they are not
// there: a clone without ../shared beside it reports those tests skipped with the folder named,
// never failed and never silently passed. Each such test has a sibling on data the repository
// holds or the test makes, so the area stays covered without them.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace homesh::test {

// $HOMESH_SHARED_DIR when set, else the `shared` folder beside the source tree.
inline std::filesystem::path sharedDir() {
  if (const char* env = std::getenv("HOMESH_SHARED_DIR"); env != nullptr && *env != '\0') {
    return {env};
  }
  return (std::filesystem::path(HOMESH_SOURCE_DIR) / ".." / "shared").lexically_normal();
}

// The folder of NekMesh's regression inputs: meshgen/, optimiser/, nektar-xml/.
inline std::filesystem::path peerCasesDir() {
  return sharedDir() / "peer-cases" / "nekmesh";
}

// A file under peerCasesDir(), e.g. peerFile("optimiser/varopti_naca.msh").
inline std::string peerFile(const std::string& relative) {
  return (peerCasesDir() / relative).string();
}

// Whether the peer files are there. Only the folder's absence skips: with the folder present a
// missing file is an error of the test, reported as a failure.
inline bool havePeerFiles() {
  return std::filesystem::is_directory(peerCasesDir());
}

inline std::string missingPeerFilesReason() {
  return "NekMesh's peer files are not here: " + peerCasesDir().string() +
         " not found (put the shared folder beside the clone or set HOMESH_SHARED_DIR)";
}

}  // namespace homesh::test

// Skips the calling test (GTEST_SKIP returns from the function it is written in, so call it in
// the TEST body or in a fixture's SetUp) when the peer files are absent.
#define HOMESH_REQUIRE_PEER_FILES()                             \
  do {                                                          \
    if (!::homesh::test::havePeerFiles()) {                     \
      GTEST_SKIP() << ::homesh::test::missingPeerFilesReason(); \
    }                                                           \
  } while (0)

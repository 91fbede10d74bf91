// Runs a Gmsh session in a child process of its own. Gmsh 4.8 aborts on an Eigen assertion when
// it recombines surfaces again after being finalised and initialised in the same process, so a
// test binary that makes several recombined meshes (its tests run one after another when the
// binary is run directly, not one process per test as ctest runs them) makes each in a fork.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <exception>

namespace homesh::test {

template <class Session>
void inGmshChild(const Session& session) {
  std::fflush(nullptr);  // (nothing buffered is written twice)
  const pid_t child = fork();
  ASSERT_GE(child, 0) << "fork failed";
  if (child == 0) {
    alarm(600);  // (a stuck session ends as a failure, not a hung test)
    int status = 0;
    try {
      session();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "Gmsh session failed: %s\n", e.what());
      status = 1;
    } catch (...) {
      status = 1;
    }
    std::fflush(nullptr);
    _exit(status);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  ASSERT_FALSE(WIFSIGNALED(status)) << "the Gmsh session died of signal " << WTERMSIG(status);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "the Gmsh session failed";
}

}  // namespace homesh::test

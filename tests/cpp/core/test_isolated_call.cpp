// Work run in a child process: its result comes back exactly, its errors keep their kind, and
// a crash, a hang, a runaway allocation or a cancel ends the child, never this process.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "core/error.hpp"
#include "core/isolated_call.hpp"
#include "core/mesh_bytes.hpp"

namespace homesh {
namespace {

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TEST(IsolatedCall, ReturnsTheChildsBytesAndLeavesThisProcessUnchanged) {
  int touched = 0;
  std::string big(3'000'000, '\0');  // larger than a pipe's buffer: read while written
  for (std::size_t i = 0; i < big.size(); ++i) big[i] = static_cast<char>(i * 7);
  const std::string bytes = runIsolated("a test", {}, [&] {
    touched = 1;  // in the child's copy of memory only
    return big;
  });
  EXPECT_EQ(bytes, big);
  EXPECT_EQ(touched, 0);
}

TEST(IsolatedCall, ErrorsKeepTheirKindAndMessage) {
  EXPECT_THROW(runIsolated("a test", {}, []() -> std::string { throw CadError("Face3 is bad"); }),
               CadError);
  try {
    runIsolated("a test", {}, []() -> std::string { throw ParameterError("order is 0"); });
    FAIL();
  } catch (const ParameterError& e) {
    EXPECT_STREQ(e.what(), "order is 0");
  }
  EXPECT_THROW(runIsolated("a test", {}, []() -> std::string { throw MeshingError("m"); }),
               MeshingError);
  EXPECT_THROW(runIsolated("a test", {}, []() -> std::string { throw IoError("i"); }), IoError);
  EXPECT_THROW(runIsolated("a test", {}, []() -> std::string { throw CancelledError("c"); }),
               CancelledError);
  EXPECT_THROW(runIsolated("a test", {}, []() -> std::string { throw 42; }), Error);
}

TEST(IsolatedCall, ACrashInTheChildIsAnErrorHere) {
  try {
    runIsolated("the crashing work", {}, []() -> std::string {
      std::raise(SIGSEGV);
      return "unreachable";
    });
    FAIL();
  } catch (const ChildCrashed& e) {
    EXPECT_NE(std::string(e.what()).find("the crashing work crashed (Segmentation fault)"),
              std::string::npos)
        << e.what();
  }
  EXPECT_THROW(runIsolated("an aborting work", {}, []() -> std::string { std::abort(); }),
               ChildCrashed);
  EXPECT_THROW(runIsolated("an exiting work", {}, []() -> std::string { std::_Exit(0); }),
               ChildCrashed);
}

TEST(IsolatedCall, TheTimeBudgetEndsAHangingChild) {
  IsolationLimits limits;
  limits.seconds = 0.3;
  limits.budgetName = "the test's limit";
  const auto start = std::chrono::steady_clock::now();
  std::string message;
  try {
    runIsolated("the hanging work", limits, []() -> std::string {
      std::this_thread::sleep_for(std::chrono::seconds(60));
      return "";
    });
  } catch (const MeshingError& e) {
    message = e.what();
  }
  // The message is the proof that the budget ended the child: left alone it would have slept
  // its minute and returned normally, with no error. The time is printed, not asserted (a
  // loaded machine decides it).
  EXPECT_NE(message.find("stopped at its time budget of 0.3 s (the test's limit)"),
            std::string::npos)
      << message;
  std::printf("the hanging child was ended after %.3f s\n", secondsSince(start));
}

// A retry runs under what is left of its stage's budget (2.99997 s of 3, say); its message
// names the budget the user set, not that share.
TEST(IsolatedCall, AShareOfABudgetIsReportedAsTheBudget) {
  IsolationLimits limits;
  limits.seconds = 0.2;
  limits.statedSeconds = 3.0;
  std::string message;
  try {
    runIsolated("the retried work", limits, []() -> std::string {
      std::this_thread::sleep_for(std::chrono::seconds(60));
      return "";
    });
  } catch (const MeshingError& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("stopped at its time budget of 3 s"), std::string::npos) << message;
}

// A watched child's stdout and stderr come here line by line, in order, the last line even
// without its newline; the child's result is unchanged.
TEST(IsolatedCall, AWatchSeesTheChildsOutputLineByLine) {
  std::vector<std::string> lines;
  IsolationLimits limits;
  limits.watch = [&lines](const std::string& line) {
    lines.push_back(line);
    return std::string();
  };
  const std::string bytes = runIsolated("the talking work", limits, [] {
    std::printf("one\ntwo ");
    std::fflush(stdout);
    std::fprintf(stderr, "three\n");
    std::printf("four");
    std::fflush(stdout);
    return std::string("done");
  });
  EXPECT_EQ(bytes, "done");
  EXPECT_EQ(lines, (std::vector<std::string>{"one", "two three", "four"}));
}

// A watch that says the work stalls ends the child at once (left alone it would sleep its
// minute and return normally), with Stalled and the watch's words.
TEST(IsolatedCall, AWatchThatSeesAStallEndsTheChild) {
  IsolationLimits limits;
  limits.watch = [](const std::string& line) {
    return line == "again 3" ? std::string("it said again three times") : std::string();
  };
  std::string message;
  try {
    runIsolated("the looping work", limits, []() -> std::string {
      for (int i = 1; i <= 5; ++i) {
        std::printf("again %d\n", i);
        std::fflush(stdout);
      }
      std::this_thread::sleep_for(std::chrono::seconds(60));
      return "";
    });
  } catch (const Stalled& e) {
    message = e.what();
  }
  EXPECT_NE(message.find("the looping work made no progress after "), std::string::npos) << message;
  EXPECT_NE(message.find(" s: it said again three times"), std::string::npos) << message;
}

TEST(IsolatedCall, CancellingEndsTheChild) {
  IsolationLimits limits;
  const auto start = std::chrono::steady_clock::now();
  limits.cancelled = [start] { return secondsSince(start) > 0.2; };
  // CancelledError is the proof: the child, left alone, sleeps its minute and returns normally.
  EXPECT_THROW(runIsolated("the long work", limits,
                           []() -> std::string {
                             std::this_thread::sleep_for(std::chrono::seconds(60));
                             return "";
                           }),
               CancelledError);
}

// A child whose start hangs on a lock that another thread of this process held at the fork
// (OpenCASCADE's error-handler mutex did, under concurrent jobs) is killed and started again.
// The "lock" here is a flag the probe waits on: set when the first child is made, cleared by
// the parent while it waits for that child, so the first child's copy stays set forever and a
// later child's copy is clear. However slow the machine, the first child never starts; a later
// one does (the last one has the whole budget).
std::atomic<bool> gLockHeld{false};

TEST(IsolatedCall, AChildStuckOnALockCopiedAtTheForkIsStartedAgain) {
  gLockHeld = true;
  IsolationLimits limits;
  limits.startProbe = [] {
    while (gLockHeld.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  };
  limits.startSeconds = 0.2;
  limits.startAttempts = 3;
  limits.seconds = 600;  // a hang guard: without the restart the first child never answers
  limits.cancelled = [] {
    gLockHeld = false;
    return false;
  };
  std::vector<int> restarts;
  limits.restarted = [&](int child) { restarts.push_back(child); };
  EXPECT_EQ(runIsolated("the locked work", limits, [] { return std::string("done"); }), "done");
  ASSERT_FALSE(restarts.empty());
  EXPECT_EQ(restarts.front(), 1);
  EXPECT_LE(restarts.size(), 2U);  // the third child, the last, is not given up
  // Without a probe nothing is restarted, and the answer is the same.
  limits.startProbe = nullptr;
  restarts.clear();
  EXPECT_EQ(runIsolated("the plain work", limits, [] { return std::string("done"); }), "done");
  EXPECT_TRUE(restarts.empty());
  // A probe that never returns in any child: the last child waits on, until the budget ends it.
  gLockHeld = true;
  limits.cancelled = nullptr;
  limits.startProbe = [] {
    while (gLockHeld.load()) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  };
  limits.seconds = 2.0;
  std::string message;
  try {
    runIsolated("the stuck work", limits, [] { return std::string("done"); });
  } catch (const MeshingError& e) {
    message = e.what();
  }
  gLockHeld = false;
  EXPECT_NE(message.find("the stuck work stopped at its time budget of 2 s"), std::string::npos)
      << message;
  // At most the first two given up (how many the budget left time for is the machine's).
  EXPECT_LE(restarts.size(), 2U);
}

TEST(IsolatedCall, ARunawayAllocationFailsInTheChildOnly) {
  IsolationLimits limits;
  limits.extraBytes = std::size_t{256} << 20;  // 256 MiB more than this process
  try {
    runIsolated("the greedy work", limits, []() -> std::string {
      std::vector<std::vector<char>> hoard;
      for (;;) hoard.emplace_back(std::size_t{64} << 20, 'x');  // until bad_alloc
    });
    FAIL();
  } catch (const MeshingError& e) {
    EXPECT_NE(std::string(e.what()).find("the greedy work ran out of memory"), std::string::npos)
        << e.what();
  }
}

TEST(MeshBytes, AMeshAndABlockRoundTripExactly) {
  Mesh mesh;
  mesh.dim = 3;
  mesh.order = 1;
  mesh.planeNormal = {0.0, 0.6, 0.8};
  const double nodes[4][3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0.1, 0.2, 1.0 / 3.0}};
  for (int i = 0; i < 4; ++i) mesh.addNode(nodes[i], i == 3 ? 3 : 2, i, 0.25 * i, -1e-300);
  ElementBlock tets;
  tets.type = CellType::Tetrahedron;
  tets.nodes = {0, 1, 2, 3};
  tets.entity = {7};
  mesh.blocks.push_back(tets);
  ElementBlock layer{CellType::Hexahedron, 1, {0, 1, 2, 3, 0, 1, 2, 3}, {1}};
  layer.layerCells = true;  // (a macro layer's hexahedra: the flag travels too)
  std::string bytes;
  appendMeshBytes(bytes, mesh);
  appendBlockBytes(bytes, tets);
  appendBlockBytes(bytes, layer);
  std::size_t offset = 0;
  const Mesh back = readMeshBytes(bytes, offset);
  const ElementBlock block = readBlockBytes(bytes, offset);
  const ElementBlock layerBack = readBlockBytes(bytes, offset);
  EXPECT_FALSE(block.layerCells);
  EXPECT_TRUE(layerBack.layerCells);
  EXPECT_EQ(layerBack.nodes, layer.nodes);
  EXPECT_EQ(offset, bytes.size());
  EXPECT_EQ(back.xyz, mesh.xyz);
  EXPECT_EQ(back.nodeCadDim, mesh.nodeCadDim);
  EXPECT_EQ(back.nodeCadIndex, mesh.nodeCadIndex);
  EXPECT_EQ(back.nodeCadParam, mesh.nodeCadParam);
  EXPECT_EQ(back.planeNormal, mesh.planeNormal);
  ASSERT_EQ(back.blocks.size(), 1U);
  EXPECT_EQ(back.blocks[0].nodes, tets.nodes);
  EXPECT_EQ(block.entity, tets.entity);
  // Short bytes are refused, not read past their end.
  for (const std::size_t cut : {std::size_t{0}, std::size_t{5}, bytes.size() / 2}) {
    std::size_t at = 0;
    EXPECT_THROW(readMeshBytes(bytes.substr(0, cut), at), Error) << cut;
  }
}

}  // namespace
}  // namespace homesh

// MeshingOptions from an options mapping: every value checked once against the parameter table,
// defaults from it, and names a caller has no use for refused.
#include <gtest/gtest.h>

#include <string>

#include "core/error.hpp"
#include "core/parameters.hpp"
#include "pipeline/meshing_options.hpp"

namespace homesh {
namespace {

std::string messageOf(const OptionMap& values, const std::vector<std::string>& allowed = {}) {
  try {
    MeshingOptions::fromMap(values, allowed);
  } catch (const ParameterError& e) {
    return e.what();
  }
  return "";
}

TEST(MeshingOptions, DefaultsAreTheTables) {
  const MeshingOptions o;
  EXPECT_EQ(o.order, parameterDefault("order"));
  EXPECT_EQ(o.repairRounds, parameterDefault("repair_rounds"));
  EXPECT_EQ(o.linearSeconds, parameterDefault("linear_seconds"));
  EXPECT_EQ(o.heal, parameterDefault("heal") != 0.0);
  EXPECT_EQ(o.optimiseIterations, 0);  // the optimiser is asked for, not on by default
  const MeshingOptions empty = MeshingOptions::fromMap({});
  EXPECT_EQ(empty.order, o.order);
  EXPECT_FALSE(empty.size || empty.sizing);
}

TEST(MeshingOptions, ValuesGoWhereTheyBelong) {
  const MeshingOptions o = MeshingOptions::fromMap(
      {{"order", 6.0}, {"heal", false}, {"optimise", true}, {"eps", 0.01}, {"surface", true}});
  EXPECT_EQ(o.order, 6);
  EXPECT_FALSE(o.heal);
  EXPECT_TRUE(o.surface);
  // On/off for the sweep count: on is the table's default.
  EXPECT_EQ(o.optimiseIterations, parameterDefault("optimise"));
  ASSERT_TRUE(o.sizing);
  EXPECT_EQ(o.sizing->eps, 0.01);
  EXPECT_EQ(o.sizing->maxDelta, 0.0);  // automatic until the CAD is known
  // 0 where 0 is automatic: no uniform size.
  EXPECT_FALSE(MeshingOptions::fromMap({{"size", 0.0}}).size);
  EXPECT_EQ(*MeshingOptions::fromMap({{"size", 0.5}}).size, 0.5);
}

TEST(MeshingOptions, EachBadValueIsNamedOnce) {
  EXPECT_EQ(messageOf({{"order", 11.0}}), "order must be an integer from 1 to 10, got 11");
  EXPECT_EQ(messageOf({{"order", std::string("4")}}),
            "order must be an integer from 1 to 10, got '4'");
  EXPECT_EQ(messageOf({{"order", true}}), "order must be an integer from 1 to 10, got true");
  EXPECT_EQ(messageOf({{"heal", 1.0}}), "heal must be true or false, got 1");
  EXPECT_EQ(messageOf({{"eps", 0.0}}), "EPS must be a number in (0, 1], got 0");
  EXPECT_EQ(messageOf({{"size", -1.0}}), "size must be a length > 0, got -1");
  EXPECT_EQ(messageOf({{"job_seconds", -2.0}}), "job time limit must be a number >= 0, got -2");
  EXPECT_NE(messageOf({{"ordr", 2.0}}).find("unknown option 'ordr' (options: order, size"),
            std::string::npos);
  // The layer's own parameters are not the job's.
  EXPECT_NE(messageOf({{"layers", 3.0}}).find("option 'layers' does not apply here"),
            std::string::npos);
  EXPECT_EQ(messageOf({{"size", 1.0}}, {"order", "threads"}),
            "option 'size' does not apply here (options: order, threads)");
  // Rules between options stay validate()'s.
  EXPECT_NE(messageOf({{"size", 1.0}, {"eps", 0.1}}).find("not both"), std::string::npos);
  EXPECT_NE(messageOf({{"solids_only", true}, {"surface", true}}), "");
}

}  // namespace
}  // namespace homesh

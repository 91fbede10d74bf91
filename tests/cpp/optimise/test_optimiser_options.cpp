// OptimiserOptions::apply: the one place a front end's optimiser options enter, checked against
// the parameter table.
#include <gtest/gtest.h>

#include <string>

#include "core/error.hpp"
#include "core/parameters.hpp"
#include "optimise/optimiser_options.hpp"

namespace homesh {
namespace {

std::string refusal(const OptionMap& values) {
  try {
    OptimiserOptions().apply(values);
  } catch (const ParameterError& e) {
    return e.what();
  }
  return "";
}

TEST(OptimiserOptions, ApplySetsEachFieldFromItsTableKey) {
  OptimiserOptions o;
  o.apply({{"functional", std::string("Linear-Elastic")},
           {"optimise", 7.0},
           {"tolerance", 1e-3},
           {"region", 0.4},
           {"region_layers", 1.0},
           {"focus", 0.0},
           {"free_interfaces", true},
           {"optimise_seconds", 2.5},
           {"facet_weight", 1.0},
           {"threads", 3.0}});
  EXPECT_EQ(o.functional, Functional::LinearElastic);
  EXPECT_EQ(o.maxIterations, 7);
  EXPECT_EQ(o.tolerance, 1e-3);
  ASSERT_TRUE(o.regionThreshold.has_value());
  EXPECT_EQ(*o.regionThreshold, 0.4);
  EXPECT_EQ(o.regionLayers, 1);
  EXPECT_EQ(o.focusPasses, 0);
  EXPECT_TRUE(o.freeInterfaces);
  EXPECT_EQ(o.timeLimit, 2.5);
  EXPECT_EQ(o.facetWeight, 1.0);
  EXPECT_EQ(o.threads, 3);
}

TEST(OptimiserOptions, RegionZeroIsNoRegionAndSweepsOnAreTheTablesDefault) {
  OptimiserOptions o;
  o.apply({{"region", 0.0}, {"optimise", true}});
  EXPECT_FALSE(o.regionThreshold.has_value());
  EXPECT_EQ(o.maxIterations, static_cast<int>(parameterDefault("optimise")));
}

TEST(OptimiserOptions, BadValuesAreRefusedNamingTheOption) {
  EXPECT_NE(refusal({{"functional", std::string("spring")}}).find("functional must be one of"),
            std::string::npos);
  EXPECT_NE(refusal({{"functional", 1.0}}).find("functional"), std::string::npos);
  EXPECT_NE(refusal({{"region", 1.5}}).find("region must be"), std::string::npos);
  EXPECT_NE(refusal({{"focus", -1.0}}).find("focus passes must be"), std::string::npos);
  EXPECT_NE(refusal({{"region_layers", 3.0}}).find("region layers need a region"),
            std::string::npos);
  // A table key the optimiser has no use for, and one the table does not have.
  EXPECT_NE(refusal({{"order", 3.0}}).find("'order' does not apply to the optimiser"),
            std::string::npos);
  EXPECT_NE(refusal({{"sweeps", 3.0}}).find("unknown option 'sweeps'"), std::string::npos);
}

TEST(OptimiserOptions, KeysAreTheTablesInItsOrder) {
  const std::vector<std::string> keys = OptimiserOptions::keys();
  ASSERT_FALSE(keys.empty());
  std::size_t last = 0;
  for (const std::string& key : keys) {
    std::size_t at = 0;
    while (parameterDefinitions()[at].key != key) ++at;
    EXPECT_GE(at, last) << key;
    last = at;
    EXPECT_EQ(refusal({{key, OptionValue(parameterDefault(key))}}).find("does not apply"),
              std::string::npos)
        << key;
  }
}

}  // namespace
}  // namespace homesh

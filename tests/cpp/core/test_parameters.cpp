// The one parameter table: every entry checks its own range, in words the user reads.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <set>
#include <string>

#include "core/error.hpp"
#include "core/parameters.hpp"

namespace homesh {
namespace {

TEST(Parameters, KeysPropertiesAndOptionsAreUnique) {
  std::set<std::string> keys, properties, options;
  for (const ParameterDefinition& p : parameterDefinitions()) {
    EXPECT_TRUE(keys.insert(p.key).second) << p.key;
    if (*p.property != '\0') {
      EXPECT_TRUE(properties.insert(p.property).second) << p.property;
    }
    if (*p.option != '\0') {
      EXPECT_TRUE(options.insert(p.option).second) << p.option;
    }
    EXPECT_LT(p.min, p.max) << p.key;
    EXPECT_NE(std::string(p.doc), "") << p.key;
  }
  EXPECT_THROW(parameterDefinition("no such parameter"), std::out_of_range);
}

TEST(Parameters, EveryRangeRefusesWhatLiesJustOutsideIt) {
  for (const ParameterDefinition& p : parameterDefinitions()) {
    const bool integer = p.kind == ParameterKind::Integer;
    // Just outside: one below an integer minimum, the minimum itself when it is excluded.
    const double below = integer ? p.min - 1 : (p.minExclusive ? p.min : p.min - 1e-9);
    EXPECT_THROW(checkParameter(p.key, below), ParameterError) << p.key;
    if (std::isfinite(p.max)) {
      EXPECT_NO_THROW(checkParameter(p.key, p.max)) << p.key;
      EXPECT_THROW(checkParameter(p.key, integer ? p.max + 1 : std::nextafter(p.max, 1e300)),
                   ParameterError)
          << p.key;
    }
    EXPECT_THROW(checkParameter(p.key, std::numeric_limits<double>::quiet_NaN()), ParameterError);
    if (integer) {
      EXPECT_THROW(checkParameter(p.key, p.min + 0.5), ParameterError) << p.key;
    }
    // The default is a valid value, or 0 standing for "automatic".
    if (!(p.zeroIsAutomatic && p.defaultValue == 0.0)) {
      EXPECT_TRUE(inRange(p, p.defaultValue)) << p.key;
    }
  }
}

TEST(Parameters, MessagesNameTheParameterTheRangeAndTheValue) {
  try {
    checkParameter("order", 20);
    FAIL() << "order 20 accepted";
  } catch (const ParameterError& e) {
    EXPECT_EQ(std::string(e.what()), "order must be an integer from 1 to 10, got 20");
  }
  EXPECT_EQ(rangeText(parameterDefinition("eps")), "a number in (0, 1]");
  EXPECT_EQ(rangeText(parameterDefinition("size")), "a length > 0");
  EXPECT_EQ(rangeText(parameterDefinition("repair_rounds")), "an integer from 0 to 20");
}

}  // namespace
}  // namespace homesh

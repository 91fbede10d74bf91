// Command-line parsing: accepted forms and the error for each bad one.
#include <gtest/gtest.h>

#include <cmath>

#include "cli/arguments.hpp"
#include "core/parameters.hpp"
#include "pipeline/mesh_pipeline.hpp"

namespace homesh {
namespace {

ParsedCommand parse(const std::vector<std::string>& args) {
  return parseCommandLine(args);
}

// The number a parsed command line gives for table key `key` (NaN when it gives none).
double given(const OptionMap& options, const std::string& key) {
  const auto it = options.find(key);
  return it == options.end() ? std::nan("") : checkedOption(key, it->second);
}

std::string usageError(const std::vector<std::string>& args) {
  try {
    parseCommandLine(args);
  } catch (const UsageError& e) {
    return e.message;
  }
  return "";
}

TEST(Arguments, MeshWithEveryOption) {
  const ParsedCommand p = parse({"mesh", "part.step", "--order", "5", "--size", "0.25", "-o",
                                 "a.msh", "-o", "b.vtu", "--report", "r.json", "-j", "2", "-v"});
  ASSERT_EQ(p.kind, ParsedCommand::Kind::Mesh);
  EXPECT_EQ(p.mesh.input, "part.step");
  EXPECT_EQ(given(p.mesh.options, "order"), 5);
  EXPECT_DOUBLE_EQ(given(p.mesh.options, "size"), 0.25);
  EXPECT_EQ(p.mesh.common.outputs, (std::vector<std::string>{"a.msh", "b.vtu"}));
  EXPECT_EQ(p.mesh.common.report.value_or(""), "r.json");
  EXPECT_EQ(p.mesh.common.threads, 2);
  EXPECT_EQ(given(p.mesh.options, "verbosity"), 1);
  EXPECT_EQ(given(parse({"mesh", "a.step", "-vv"}).mesh.options, "verbosity"), 2);
  // Boolean flags turn the table's default around.
  const OptionMap modes =
      parse({"mesh", "a.step", "--no-heal", "--solids-only", "--surface", "--auto"}).mesh.options;
  EXPECT_EQ(given(modes, "heal"), 0.0);
  for (const char* key : {"solids_only", "surface", "auto"}) EXPECT_EQ(given(modes, key), 1.0);
  EXPECT_EQ(given(parse({"predict", "a.step", "--no-heal"}).predict.options, "heal"), 0.0);
}

TEST(Arguments, Defaults) {
  const ParsedCommand p = parse({"mesh", "part.brep"});
  EXPECT_TRUE(p.mesh.options.empty());  // the table's defaults, or a .mcf's values
  EXPECT_TRUE(p.mesh.sizing.sources.empty());
  EXPECT_TRUE(p.mesh.common.outputs.empty());
}

TEST(Arguments, RepairRounds) {
  EXPECT_EQ(
      given(parse({"mesh", "part.brep", "--repair-rounds", "0"}).mesh.options, "repair_rounds"), 0);
  EXPECT_EQ(
      given(parse({"mesh", "part.brep", "--repair-rounds", "20"}).mesh.options, "repair_rounds"),
      20);
  for (const char* bad : {"-1", "21", "2.5", "x"})
    EXPECT_NE(usageError({"mesh", "part.brep", "--repair-rounds", bad}).find("--repair-rounds"),
              std::string::npos)
        << bad;
}

TEST(Arguments, OptimiserOptionsNeedTheOptimiser) {
  // --optimise alone: the table's number of sweeps; --maxiter N: N.
  const OptionMap on = parse({"mesh", "part.brep", "--optimise"}).mesh.options;
  EXPECT_EQ(given(on, "optimise"), parameterDefault("optimise"));
  EXPECT_EQ(given(parse({"mesh", "part.brep", "--optimise", "-n", "7"}).mesh.options, "optimise"),
            7);
  EXPECT_EQ(given(parse({"mesh", "part.brep", "--optimise", "--facet-weight", "1.5"}).mesh.options,
                  "facet_weight"),
            1.5);
  // The optimiser's options do nothing without it: refused by name.
  EXPECT_EQ(usageError({"mesh", "part.brep", "--facet-weight", "1.5"}),
            "--facet-weight needs --optimise");
  EXPECT_EQ(usageError({"mesh", "part.brep", "--time-limit", "40"}),
            "--time-limit needs --optimise");
  EXPECT_EQ(usageError({"mesh", "part.brep", "-n", "5"}), "--maxiter needs --optimise");
  EXPECT_EQ(given(parse({"mesh", "part.brep", "--time-limit", "40", "--optimise"}).mesh.options,
                  "optimise_seconds"),
            40.0);
  for (const char* bad : {"-0.5", "101", "x"})
    EXPECT_NE(usageError({"mesh", "part.brep", "--facet-weight", bad}).find("--facet-weight"),
              std::string::npos)
        << bad;
}

TEST(Arguments, HelpListsTheTablesOptionsWithTheirRangesAndDefaults) {
  // The help's words in one line: a range may be wrapped over two. The optimiser's own options
  // are `homesh optimise`'s, the classification tolerance `homesh curve`'s.
  std::string help;
  for (const char c : usageText("mesh") + usageText("optimise") + usageText("curve"))
    if (c != '\n' && !(c == ' ' && !help.empty() && help.back() == ' ')) help += c;
  for (const ParameterDefinition& p : parameterDefinitions()) {
    if (*p.option == '\0' || std::string(p.key) == "verbosity") continue;
    EXPECT_NE(help.find(p.option), std::string::npos) << p.key;
    if (p.kind != ParameterKind::Boolean) {
      EXPECT_NE(help.find(rangeText(p)), std::string::npos) << p.key;
    }
  }
  EXPECT_NE(usageText("mesh").find("  -p, --order N"), std::string::npos);
}

TEST(Arguments, OptimiseTakesTheTablesOptimiserOptions) {
  const ParsedCommand p = parse({"optimise",
                                 "m.msh",
                                 "-f",
                                 "winslow",
                                 "-n",
                                 "5",
                                 "--tolerance",
                                 "1e-4",
                                 "--region",
                                 "0.3",
                                 "--layers",
                                 "1",
                                 "--focus",
                                 "0",
                                 "--free-interfaces",
                                 "--time-limit",
                                 "9",
                                 "-p",
                                 "3",
                                 "-j",
                                 "2"});
  ASSERT_EQ(p.kind, ParsedCommand::Kind::Optimise);
  const OptionMap& o = p.optimise.options;
  EXPECT_EQ(given(o, "functional"), 2);  // the table's third choice
  EXPECT_EQ(given(o, "optimise"), 5);
  EXPECT_EQ(given(o, "tolerance"), 1e-4);
  EXPECT_EQ(given(o, "region"), 0.3);
  EXPECT_EQ(given(o, "region_layers"), 1);
  EXPECT_EQ(given(o, "focus"), 0);
  EXPECT_EQ(given(o, "free_interfaces"), 1);
  EXPECT_EQ(given(o, "optimise_seconds"), 9);
  EXPECT_EQ(p.optimise.order.value_or(0), 3);
  EXPECT_EQ(p.optimise.common.threads, 2);
  // Each value is judged as it is read, naming the long option.
  EXPECT_NE(usageError({"optimise", "m.msh", "-f", "spring"}).find("--functional: functional"),
            std::string::npos);
  EXPECT_NE(usageError({"optimise", "m.msh", "--focus", "-1"}).find("--focus must be"),
            std::string::npos);
  EXPECT_NE(usageError({"optimise", "m.msh", "--region", "2"}).find("--region must be"),
            std::string::npos);
}

TEST(Arguments, SizingAndPredict) {
  const ParsedCommand p =
      parse({"predict", "case.mcf", "--max-delta", "0.5", "--eps", "0.1", "--refine-sphere",
             "0,0,1,0.5,0.01", "--refine-line", "0,0,0,1,0,0,0.1,0.02", "--refine-box",
             "0,0,0,1,1,1,0.2", "--refine-curve", "3,0.1,0.05", "--write-octree", "o.vtu"});
  ASSERT_EQ(p.kind, ParsedCommand::Kind::Predict);
  EXPECT_EQ(p.predict.input, "case.mcf");
  EXPECT_DOUBLE_EQ(given(p.predict.options, "max_delta"), 0.5);
  EXPECT_EQ(p.predict.options.count("min_delta"), 0u);
  EXPECT_DOUBLE_EQ(given(p.predict.options, "eps"), 0.1);
  ASSERT_EQ(p.predict.sizing.sources.size(), 4u);
  EXPECT_EQ(p.predict.sizing.sources[0].kind, RefinementSource::Kind::Sphere);
  EXPECT_DOUBLE_EQ(p.predict.sizing.sources[0].delta, 0.01);
  EXPECT_EQ(p.predict.sizing.sources[1].kind, RefinementSource::Kind::Segment);
  EXPECT_EQ(p.predict.sizing.sources[2].kind, RefinementSource::Kind::Box);
  EXPECT_EQ(p.predict.sizing.sources[3].edge, 3);
  EXPECT_EQ(p.predict.sizing.writeOctree.value_or(""), "o.vtu");
  const ParsedCommand m = parse({"mesh", "a.step", "--min-delta", "0.01", "-p", "2"});
  EXPECT_EQ(given(m.mesh.options, "order"), 2);
  EXPECT_DOUBLE_EQ(given(m.mesh.options, "min_delta"), 0.01);
}

TEST(Arguments, BadSizingFlagsNameTheProblem) {
  const auto message = [](const std::vector<std::string>& args) {
    try {
      parse(args);
    } catch (const UsageError& e) {
      return e.message;
    }
    return std::string("no error");
  };
  EXPECT_NE(message({"predict", "a.step", "--eps", "2"}).find("--eps"), std::string::npos);
  EXPECT_NE(message({"predict", "a.step", "--max-delta", "-1"}).find("--max-delta"),
            std::string::npos);
  EXPECT_NE(message({"predict", "a.step", "--refine-sphere", "0,0,1"}).find("X,Y,Z,R,D"),
            std::string::npos);
  EXPECT_NE(message({"predict", "a.step", "--refine-sphere", "0,0,1,-1,0.1"}).find("radius"),
            std::string::npos);
  EXPECT_NE(message({"predict", "a.step", "--refine-box", "1,1,1,0,0,0,0.1"}).find("corner"),
            std::string::npos);
  EXPECT_NE(message({"predict", "a.step", "--refine-curve", "2.5,0.1,0.1"}).find("edge"),
            std::string::npos);
  // Given together they parse; MeshingOptions::validate refuses them (test_meshing_options).
  EXPECT_EQ(message({"mesh", "a.step", "--size", "1", "--max-delta", "1"}), "no error");
}

TEST(Arguments, QualityAndConvert) {
  const ParsedCommand q = parse({"quality", "m.msh", "--report", "-", "--strict", "-j", "2"});
  ASSERT_EQ(q.kind, ParsedCommand::Kind::Quality);
  EXPECT_EQ(q.quality.input, "m.msh");
  EXPECT_TRUE(q.quality.strict);
  EXPECT_EQ(q.quality.common.report.value_or(""), "-");
  EXPECT_EQ(q.quality.common.threads, 2);
  const ParsedCommand c =
      parse({"convert", "m.msh", "-o", "m.xml", "--compressed", "-o", "m.msh", "--binary"});
  ASSERT_EQ(c.kind, ParsedCommand::Kind::Convert);
  EXPECT_EQ(c.convert.common.outputs, (std::vector<std::string>{"m.xml", "m.msh"}));
  EXPECT_TRUE(c.convert.common.compressed);
  EXPECT_TRUE(c.convert.common.binary);
  EXPECT_NE(usageError({"convert", "m.msh"}).find("-o"), std::string::npos);
  EXPECT_NE(usageError({"quality"}).find("INPUT"), std::string::npos);
  EXPECT_NE(usageError({"quality", "m.msh", "--order", "3"}).find("--order"), std::string::npos);
}

TEST(Arguments, HelpAndVersion) {
  EXPECT_EQ(parse({"--help"}).kind, ParsedCommand::Kind::Help);
  EXPECT_EQ(parse({"mesh", "--help"}).helpTopic, "mesh");
  EXPECT_EQ(parse({"--version"}).kind, ParsedCommand::Kind::Version);
  EXPECT_EQ(parse({"quality", "-h"}).helpTopic, "quality");
  EXPECT_NE(usageText("convert").find("--compressed"), std::string::npos);
  EXPECT_NE(usageText("mesh").find("--order"), std::string::npos);
}

TEST(Arguments, BadCommandLinesNameTheProblem) {
  EXPECT_NE(usageError({}).find("no command"), std::string::npos);
  EXPECT_NE(usageError({"frobnicate"}).find("frobnicate"), std::string::npos);
  EXPECT_NE(usageError({"mesh"}).find("INPUT"), std::string::npos);
  EXPECT_NE(usageError({"mesh", "a.step", "--order", "0"}).find("--order"), std::string::npos);
  EXPECT_NE(usageError({"mesh", "a.step", "--order", "11"}).find("--order"), std::string::npos);
  EXPECT_NE(usageError({"mesh", "a.step", "--order", "two"}).find("integer"), std::string::npos);
  EXPECT_NE(usageError({"mesh", "a.step", "--size", "-1"}).find("a length > 0"), std::string::npos);
  EXPECT_NE(usageError({"mesh", "a.step", "--size", "1x"}).find("number"), std::string::npos);
  EXPECT_NE(usageError({"mesh", "a.step", "--size"}).find("needs a value"), std::string::npos);
  EXPECT_NE(usageError({"mesh", "a.step", "--bogus"}).find("--bogus"), std::string::npos);
  EXPECT_NE(usageError({"mesh", "a.step", "b.step"}).find("b.step"), std::string::npos);
  EXPECT_NE(usageError({"mesh", "a.step", "-j", "-1"}).find("--threads"), std::string::npos);
  // 0 where the table says 0 is automatic: every core, the sizing octree.
  const ParsedCommand automatic = parse({"mesh", "a.step", "-j", "0", "--size", "0"});
  EXPECT_EQ(automatic.mesh.common.threads, 0);
  EXPECT_EQ(given(automatic.mesh.options, "size"), 0.0);
}

}  // namespace
}  // namespace homesh

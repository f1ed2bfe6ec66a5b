// The scenario schema is complete and self-consistent; validation names the JSON pointer.
// SPDX-License-Identifier: MIT
#include <gtest/gtest.h>

#include <fstream>

#include "core/error.hpp"
#include "pipeline/scenario.hpp"
#include "support/temp_dir.hpp"

using namespace terrapolis;
using namespace terrapolis::pipeline;
using json = nlohmann::ordered_json;

namespace {

/// Walks every leaf property of the schema.
template <class F>
void each_field(const nlohmann::json& schema, const std::string& pointer, F&& f) {
  for (const auto& [key, sub] : schema["properties"].items()) {
    if (sub.value("type", "") == "object" && sub.contains("properties")) each_field(sub, pointer + "/" + key, f);
    else f(pointer + "/" + key, sub);
  }
}

std::string error_of(const std::string& file, const std::vector<std::string>& sets) {
  try {
    load_scenario(file, sets);
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Scenario, EveryFieldHasDescriptionUnitDefaultAndRange) {
  const auto schema = nlohmann::json::parse(scenario_schema_text());
  int fields = 0;
  each_field(schema, "", [&](const std::string& p, const nlohmann::json& f) {
    ++fields;
    EXPECT_TRUE(f.contains("description")) << p;
    EXPECT_TRUE(f.contains("x-unit")) << p;
    ASSERT_TRUE(f.contains("default")) << p;
    const std::string type = f.value("type", "");
    if (type == "number" || type == "integer") {
      EXPECT_TRUE(f.contains("minimum") || f.contains("exclusiveMinimum")) << p;
      EXPECT_TRUE(f.contains("maximum") || f.contains("exclusiveMaximum")) << p;
    }
  });
  EXPECT_GT(fields, 5);
  // The defaults form a valid scenario, and objects reject unknown keys at every level.
  EXPECT_EQ(validate_scenario(schema_defaults()), "");
  std::function<void(const nlohmann::json&, const std::string&)> closed = [&](const nlohmann::json& s, const std::string& p) {
    if (s.value("type", "") != "object") return;
    EXPECT_EQ(s.value("additionalProperties", true), false) << p;
    if (s.contains("properties"))
      for (const auto& [k, sub] : s["properties"].items()) closed(sub, p + "/" + k);
  };
  closed(schema, "");
  // An unknown key is named by its own pointer.
  nlohmann::json typo = schema_defaults();
  typo["density"]["weigths"] = 1;
  EXPECT_EQ(validate_scenario(typo), "/density/weigths: unknown key");
  // A list of the wrong length is said in a user's words.
  nlohmann::json triple = schema_defaults();
  triple["water"]["reservoirs"] = nlohmann::json::parse(R"([{"at": [1, 2, 3], "level_m": 5}])");
  EXPECT_EQ(validate_scenario(triple), "/water/reservoirs/0/at: must have at most 2 items");
}

TEST(Scenario, DefaultScenarioIsTheSchemaDefaults) {
  const Scenario s = load_scenario("");
  EXPECT_EQ(s.resolved, schema_defaults());
  EXPECT_EQ(s.resolved["seed"], 1);
  EXPECT_EQ(s.resolved["outputs"]["cog"], true);
}

TEST(Scenario, SetChangesExactlyWhatItNames) {
  const Scenario base = load_scenario("");
  const Scenario changed = load_scenario("", {"outputs.preview_width=640", "seed=7"});
  json expected = base.resolved;
  expected["outputs"]["preview_width"] = 640;
  expected["seed"] = 7;
  EXPECT_EQ(changed.resolved, expected);
  EXPECT_EQ(load_scenario("", {}, 42).resolved["seed"], 42);
  EXPECT_EQ(load_scenario("", {"output=runs/a b"}).resolved["output"], "runs/a b");  // bare words are strings
}

TEST(Scenario, InvalidScenariosNameThePointer) {
  EXPECT_NE(error_of("", {"outputs.cog=3"}).find("/outputs/cog"), std::string::npos);
  EXPECT_NE(error_of("", {"outputs.preview_width=10"}).find("/outputs/preview_width"), std::string::npos);
  EXPECT_NE(error_of("", {"seed=-1"}).find("/seed"), std::string::npos);
  EXPECT_NE(error_of("", {"colour=1"}).find("colour"), std::string::npos);
  EXPECT_NE(error_of("", {"outputs.bogus=1"}).find("/outputs"), std::string::npos);
  EXPECT_NE(error_of("", {"novalue"}).find("stage.field=value"), std::string::npos);
  test::TempDir dir;
  std::ofstream(dir.file("bad.json")) << "{ \"seed\": ";
  EXPECT_NE(error_of(dir.file("bad.json"), {}).find("not valid JSON"), std::string::npos);
  std::ofstream(dir.file("list.json")) << "[1, 2]";
  EXPECT_NE(error_of(dir.file("list.json"), {}).find("a scenario is a JSON object"), std::string::npos);
  EXPECT_NE(error_of(dir.file("missing.json"), {}).find("missing.json: no such scenario file"), std::string::npos);
}

TEST(Scenario, RelativePathsFollowTheScenarioFile) {
  test::TempDir dir;
  std::ofstream(dir.file("s.json")) << R"({"dem": "dems/x.tif", "output": "out"})";
  const Scenario s = load_scenario(dir.file("s.json"));
  EXPECT_EQ(s.path("dem"), dir.file("dems/x.tif"));
  EXPECT_EQ(s.path("output"), dir.file("out"));
}

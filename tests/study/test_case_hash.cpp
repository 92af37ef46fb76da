// Case identity: SHA-256 against the FIPS 180-4 examples, stable hashes, key order and
// spelled-out defaults irrelevant, every result-changing input relevant.
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "study/case_hash.hpp"
#include "study_test_support.hpp"

namespace crevasse {
namespace {

using nlohmann::json;

std::set<std::string> ids(const Study& s) {
  std::set<std::string> out;
  for (const auto& c : s.cases) out.insert(c.case_id);
  return out;
}

TEST(CaseHash, Sha256MatchesTheStandardExamples) {
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha256_hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(CaseHash, SameStudySameHashes) {
  const Study a = test::parse(test::tiny_study(4));
  const Study b = test::parse(test::tiny_study(4));
  ASSERT_EQ(a.cases.size(), 4u);
  for (std::size_t i = 0; i < a.cases.size(); ++i)
    EXPECT_EQ(a.cases[i].case_id, b.cases[i].case_id);
  EXPECT_EQ(a.study_hash, b.study_hash);
}

TEST(CaseHash, KeyOrderDoesNotMatter) {
  const std::string scene_a = test::tiny_scene().dump();
  // The same scene with its keys written in reverse order, at every level.
  std::function<std::string(const json&)> reversed = [&](const json& j) -> std::string {
    if (!j.is_object()) return j.dump();
    std::vector<std::string> parts;
    for (auto it = j.begin(); it != j.end(); ++it) {
      std::string part = json(it.key()).dump();
      part += ": ";
      part += reversed(it.value());
      parts.push_back(std::move(part));
    }
    std::reverse(parts.begin(), parts.end());
    std::string s = "{";
    for (std::size_t i = 0; i < parts.size(); ++i) {
      if (i) s += ", ";
      s += parts[i];
    }
    s += "}";
    return s;
  };
  const std::string scene_b = reversed(test::tiny_scene());
  ASSERT_NE(scene_a, scene_b);
  const std::string a = R"({"name": "k", "base_scene": )" + scene_a +
                        R"(, "fixed": {"slope": 1, "step_length_ratio": 1},
                             "sweep": {"cohesion_ratio": [0.1, 0.2], "thickness": [40, 50]}})";
  const std::string b = R"({"sweep": {"thickness": [40, 50], "cohesion_ratio": [0.1, 0.2]},
                             "fixed": {"step_length_ratio": 1, "slope": 1}, "base_scene": )" +
                        scene_b + R"(, "name": "k"})";
  const Study sa = parse_study(a, ".", "a"), sb = parse_study(b, ".", "b");
  EXPECT_EQ(ids(sa), ids(sb));
  EXPECT_EQ(sa.study_hash, sb.study_hash);
  EXPECT_NE(sa.cases[1].case_id, sb.cases[1].case_id) << "enumeration order follows the file";
}

TEST(CaseHash, DefaultsSpelledOutOrGroupsInDimensionalFormGiveTheSameCase) {
  json plain = test::tiny_study(2);
  plain["sweep"] = {{"cohesion_ratio", {0.5}}};
  json spelled = plain;
  spelled["base_scene"]["ice"]["density"] = 917.0;
  spelled["base_scene"]["bed"]["friction"] = 0.1;
  spelled["base_scene"]["numerics"]["cfl"] = 0.5;
  spelled["name"] = "another_name";  // the study name is not part of a case
  EXPECT_EQ(ids(test::parse(plain)), ids(test::parse(spelled)));

  json dimensional = plain;
  dimensional.erase("sweep");
  dimensional["fixed"]["/ice/tensile_strength"] = 0.5 * 917.0 * 9.81 * 40.0;
  EXPECT_EQ(ids(test::parse(plain)), ids(test::parse(dimensional)));
}

TEST(CaseHash, OutputResourcesAndTimeLimitDoNotChangeTheCase) {
  json a = test::tiny_study(2);
  json b = a;
  b["base_scene"]["output"] = {{"vtu_interval", 5.0}, {"png", true}};
  b["base_scene"]["run"]["wall_time_limit"] = 100.0;
  b["base_scene"]["name"] = "renamed";
  b["resources"] = {{"jobs", 7}, {"threads_per_case", 3}, {"case_time_limit_s", 10}};
  EXPECT_EQ(ids(test::parse(a)), ids(test::parse(b)));
}

TEST(CaseHash, AnythingThatCanChangeAResultChangesTheHash) {
  const Study base = test::parse(test::tiny_study(2));
  const std::string id = base.cases[0].case_id;
  auto with = [&](const std::function<void(json&)>& edit) {
    json j = test::tiny_study(2);
    edit(j);
    return test::parse(j).cases[0].case_id;
  };
  EXPECT_NE(id, with([](json& j) { j["base_scene"]["numerics"]["seed"] = 2; }));
  EXPECT_NE(id, with([](json& j) { j["base_scene"]["numerics"]["cfl"] = 0.4; }));
  EXPECT_NE(id, with([](json& j) { j["base_scene"]["run"]["max_steps"] = 201; }));
  EXPECT_NE(id, with([](json& j) { j["fixed"]["slope"] = 0.9; }));
  EXPECT_NE(id, with([](json& j) { j["measurement"] = {{"damage_threshold", 0.9}}; }));
  EXPECT_NE(id, case_hash(base.cases[0].scene, base.measurement_json, "another-engine-version"));
  EXPECT_EQ(id, case_hash(base.cases[0].scene, base.measurement_json, CREVASSE_ENGINE_VERSION));
}

}  // namespace
}  // namespace crevasse

// Study files: enumeration, axis ranges, derived dimensional parameters, and one specific
// refusal per kind of mistake.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>

#include <nlohmann/json.hpp>

#include "analysis/crevasse_measure.hpp"
#include "engine/error.hpp"
#include "engine/scene.hpp"
#include "study/shard.hpp"
#include "study/study_file.hpp"
#include "study_test_support.hpp"

namespace crevasse {
namespace {

using nlohmann::json;
using test::parse;
using test::tiny_scene;

json base_study() { return {{"name", "t"}, {"base_scene", tiny_scene()}}; }

TEST(StudyFile, LinearAndLogAxesIncludeBothEndsAndRoundCleanly) {
  const auto lin = expand_axis(json{{"linear", {0.0, 1.0, 5}}}, "x");
  ASSERT_EQ(lin.size(), 5u);
  EXPECT_EQ(lin[1].get<double>(), 0.25);
  EXPECT_EQ(lin[4].get<double>(), 1.0);
  const auto log = expand_axis(json{{"log", {0.01, 1.0, 3}}}, "x");
  ASSERT_EQ(log.size(), 3u);
  EXPECT_EQ(log[0].get<double>(), 0.01);
  EXPECT_EQ(log[1].get<double>(), 0.1);  // not 0.09999999999999999
  EXPECT_EQ(log[2].get<double>(), 1.0);
  const auto list = expand_axis(json::array({3, "a", 2.5}), "x");
  ASSERT_EQ(list.size(), 3u);
  EXPECT_EQ(list[1], "a");
  EXPECT_EQ(expand_axis(json{{"linear", {2.0, 2.0, 1}}}, "x").size(), 1u);
}

TEST(StudyFile, CartesianProductLastAxisFastestReplicasInnermost) {
  json j = base_study();
  j["base_scene"]["numerics"]["jitter"] = 0.2;
  j["sweep"] = json::object();
  j["sweep"]["thickness"] = {40, 60};
  j["sweep"]["cohesion_ratio"] = {{"log", {0.1, 1.0, 3}}};
  j["replicas"] = {{"count", 2}, {"first_seed", 7}};
  // nlohmann::json sorts keys; the study keeps the file's order, so build the text by hand.
  const std::string text =
      R"({"name": "t", "base_scene": )" + j["base_scene"].dump() +
      R"(, "sweep": {"thickness": [40, 60], "cohesion_ratio": {"log": [0.1, 1, 3]}},
                              "replicas": {"count": 2, "first_seed": 7}})";
  const Study s = parse_study(text, ".", "test");
  ASSERT_EQ(s.cases.size(), 12u);
  EXPECT_EQ(s.cases[0].label, "thickness=40 cohesion_ratio=0.1 replica=0");
  EXPECT_EQ(s.cases[1].label, "thickness=40 cohesion_ratio=0.1 replica=1");
  EXPECT_EQ(s.cases[2].label, "thickness=40 cohesion_ratio=0.316228 replica=0");
  EXPECT_EQ(s.cases[6].label, "thickness=60 cohesion_ratio=0.1 replica=0");
  EXPECT_EQ(s.cases[0].scene.seed, 7u);
  EXPECT_EQ(s.cases[1].scene.seed, 8u);
  EXPECT_EQ(s.cases[11].axes["replica"], 1);
  EXPECT_EQ(s.cases[11].axes["thickness"], 60);
  std::set<std::string> ids;
  for (const auto& c : s.cases) {
    EXPECT_EQ(c.case_id.size(), 64u);
    ids.insert(c.case_id);
  }
  EXPECT_EQ(ids.size(), 12u);
  for (std::size_t i = 0; i < s.cases.size(); ++i) EXPECT_EQ(s.cases[i].index, i);
}

// The creep section is optional (a scene without creep writes none), yet a study may set and
// sweep its fields by pointer, on a base scene without creep too.
TEST(StudyFile, CreepFieldsAreSceneParameters) {
  json j = base_study();
  j["fixed"] = {{"/ice/creep/rate_factor", 2.4e-24}};
  j["sweep"] = {{"/ice/creep/field_speed", {3.17e-6, 3.17e-5}}};
  const Study s = parse_study(j.dump(), ".", "test");
  ASSERT_EQ(s.cases.size(), 2u);
  EXPECT_TRUE(s.cases[0].scene.creeps());
  EXPECT_DOUBLE_EQ(s.cases[1].scene.creep_field_speed, 3.17e-5);
  EXPECT_NE(s.cases[0].case_id, s.cases[1].case_id);
}

TEST(StudyFile, DerivesTensileStrengthStepAndWidthFromTheGroups) {
  json j = base_study();
  j["fixed"] = {{"/ice/density", 900.0},
                {"/gravity/g", 9.8},
                {"thickness", 60.0},
                {"step_length_ratio", 2.0},
                {"slope", 0.5},
                {"front_past_step_ratio", 3.0},
                {"upstream_length_ratio", 6.0},
                {"downstream_length_ratio", 8.0},
                {"cells_per_thickness", 12.0}};
  j["sweep"] = {{"cohesion_ratio", {0.05, 0.5}}};
  const Study s = parse(j);
  ASSERT_EQ(s.cases.size(), 2u);
  const SceneConfig& sc = s.cases[1].scene;
  EXPECT_DOUBLE_EQ(sc.ice_thickness, 60.0);
  EXPECT_DOUBLE_EQ(sc.tensile_strength, 0.5 * 900.0 * 9.8 * 60.0);  // c = Π ρ g H_i
  EXPECT_DOUBLE_EQ(sc.step_length, 120.0);                          // L_s = r H_i
  EXPECT_DOUBLE_EQ(sc.step_height, 60.0);                           // H_s = S L_s
  EXPECT_DOUBLE_EQ(sc.front_past_step, 180.0);
  EXPECT_DOUBLE_EQ(sc.upstream_length, 360.0);
  EXPECT_DOUBLE_EQ(sc.downstream_length, 480.0);
  EXPECT_DOUBLE_EQ(sc.dx, 5.0);
  // The groups read back from the resolved scene are the ones asked for.
  EXPECT_NEAR(s.cases[0].groups.cohesion_ratio, 0.05, 1e-12);
  EXPECT_NEAR(s.cases[1].groups.cohesion_ratio, 0.5, 1e-12);
  EXPECT_DOUBLE_EQ(s.cases[1].groups.step_length_ratio, 2.0);
  ASSERT_TRUE(s.cases[1].groups.slope.has_value());
  EXPECT_DOUBLE_EQ(*s.cases[1].groups.slope, 0.5);
  EXPECT_FALSE(s.cases[1].groups.width_ratio.has_value());
  // The canonical scene has every default spelled out.
  EXPECT_TRUE(s.cases[0].scene_json.contains("ice"));
  EXPECT_EQ(s.cases[0].scene_json["ice"]["poisson_ratio"], 0.3);
}

TEST(StudyFile, VerticalStepTakesItsHeightFromStepHeightRatio) {
  json j = base_study();
  j["fixed"] = {{"step_length_ratio", 0.0}, {"step_height_ratio", 1.5}};
  const Study s = parse(j);
  ASSERT_EQ(s.cases.size(), 1u);
  EXPECT_EQ(s.cases[0].scene.step_length, 0.0);
  EXPECT_DOUBLE_EQ(s.cases[0].scene.step_height, 60.0);
  EXPECT_FALSE(s.cases[0].groups.slope.has_value());
  EXPECT_DOUBLE_EQ(s.cases[0].groups.step_height_ratio, 1.5);
}

TEST(StudyFile, ThreeDWidthFromWidthRatio) {
  json j = base_study();
  j["fixed"] = {{"/dim", 3}, {"width_ratio", 0.5}, {"thickness", 40.0}};
  j["base_scene"]["effects"].push_back("lateral_walls");
  const Study s = parse(j);
  EXPECT_EQ(s.cases[0].scene.dim, 3);
  EXPECT_DOUBLE_EQ(s.cases[0].scene.width, 20.0);
  ASSERT_TRUE(s.cases[0].groups.width_ratio.has_value());
  EXPECT_DOUBLE_EQ(*s.cases[0].groups.width_ratio, 0.5);
}

TEST(StudyFile, AnySceneParameterByJsonPointer) {
  json j = base_study();
  j["sweep"] = {{"/bed/friction", {0.0, 0.1, 0.3}}, {"/bed/shape", {"step", "concave"}}};
  const Study s = parse(j);
  ASSERT_EQ(s.cases.size(), 6u);
  std::set<std::pair<double, std::string>> seen;
  for (const auto& c : s.cases) seen.emplace(c.scene.bed_friction, kind_name(c.scene.bed_shape));
  EXPECT_EQ(seen.size(), 6u);
}

TEST(StudyFile, BaseSceneFromAFileRelativeToTheStudy) {
  test::ScratchDir dir("studyfile");
  std::filesystem::create_directories(dir / "scenes");
  test::write_text(dir / "scenes" / "s.json", tiny_scene().dump());
  test::write_text(dir / "study.json", R"({"name": "f", "base_scene": "scenes/s.json",
                                          "sweep": {"cohesion_ratio": [0.1, 0.2]}})");
  const Study s = load_study_file(dir / "study.json");
  EXPECT_EQ(s.cases.size(), 2u);
  EXPECT_NE(s.source_text.find("scenes/s.json"), std::string::npos);
  EXPECT_EQ(s.base_scene["ice"]["thickness"], 40.0);
}

TEST(StudyFile, ResourcesAndMeasurementSettings) {
  json j = base_study();
  j["resources"] = {{"jobs", 3}, {"threads_per_case", 2}, {"case_time_limit_s", 60}};
  j["measurement"] = {
      {"damage_threshold", 0.9}, {"window_min_x_m", 100.0}, {"surface_smoothing_bins", 5}};
  const Study s = parse(j);
  EXPECT_EQ(s.resources.jobs, 3);
  EXPECT_EQ(s.resources.threads_per_case, 2);
  EXPECT_EQ(s.resources.case_time_limit_s, 60.0);
  EXPECT_EQ(s.measurement.damage_threshold, 0.9);
  ASSERT_TRUE(s.measurement.window_min_x_m.has_value());
  EXPECT_EQ(*s.measurement.window_min_x_m, 100.0);
  EXPECT_EQ(s.measurement_json["surface_smoothing_bins"], 5);
  // count_gaps is written only when on, so that studies without it keep their hashes.
  EXPECT_FALSE(s.measurement.count_gaps);
  EXPECT_FALSE(s.measurement_json.contains("count_gaps"));
  j["measurement"]["count_gaps"] = true;
  const Study g = parse(j);
  EXPECT_TRUE(g.measurement.count_gaps);
  EXPECT_EQ(g.measurement_json["count_gaps"], true);
  EXPECT_NE(g.study_hash, s.study_hash);
}

// A protocol names the frame its field is measured in; the frame it implies is the one written, so
// a study that names it keeps the case ids of one that sets the frame by hand.
TEST(StudyFile, ProtocolSetsItsFrameAndKeepsTheCaseIds) {
  json j = base_study();
  j["protocol"] = "initiation";
  const Study initiation = parse(j);
  EXPECT_EQ(initiation.protocol, "initiation");
  EXPECT_EQ(initiation.measurement.frame, "draped");
  j["protocol"] = "steady";
  const Study steady = parse(j);
  EXPECT_EQ(steady.measurement.frame, "passed");
  json by_hand = base_study();
  by_hand["measurement"] = {{"frame", "passed"}};
  EXPECT_EQ(parse(by_hand).study_hash, steady.study_hash);
  EXPECT_NE(initiation.study_hash, steady.study_hash);
  // The series over time is a record of the run, not part of the case.
  j["measure_interval_s"] = 10;
  const Study with_series = parse(j);
  EXPECT_EQ(with_series.measure_interval_s, 10.0);
  EXPECT_EQ(with_series.study_hash, steady.study_hash);
}

// Each mistake gets its own message naming the field (and the value and range where there is one).
struct BadStudy {
  const char* what;
  std::function<void(json&)> edit;
  std::vector<std::string> expect;  // substrings of the message
};

class InvalidStudy : public ::testing::TestWithParam<BadStudy> {};

TEST_P(InvalidStudy, IsRefusedWithItsOwnMessage) {
  json j = base_study();
  GetParam().edit(j);
  try {
    parse(j);
    FAIL() << GetParam().what << ": accepted";
  } catch (const InputError& e) {
    const std::string msg = e.what();
    for (const auto& s : GetParam().expect)
      EXPECT_NE(msg.find(s), std::string::npos) << msg << "\nmissing: " << s;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
  }
}

const BadStudy kBadStudies[] = {
    {"log range with a non-positive bound",
     [](json& j) {
       j["sweep"] = {{"cohesion_ratio", {{"log", {-0.1, 1.0, 4}}}}};
     },
     {"sweep.cohesion_ratio.log", "-0.1", "(0, inf)"}},
    {"unknown measurement frame", [](json& j) { j["measurement"] = {{"frame", "sideways"}}; },
     {"measurement.frame", "\"sideways\"", "'passed' or 'draped'"}},
    {"unknown protocol", [](json& j) { j["protocol"] = "start"; },
     {"protocol", "\"start\"", "\"initiation\" or \"steady\""}},
    {"a frame the protocol does not measure",
     [](json& j) {
       j["protocol"] = "initiation";
       j["measurement"] = {{"frame", "passed"}};
     },
     {"measurement.frame", "\"passed\"", "initiation protocol's frame \"draped\""}},
    {"negative measure interval", [](json& j) { j["measure_interval_s"] = -1; },
     {"measure_interval_s", "-1", "[0, 1000000]"}},
    {"count_gaps not a boolean", [](json& j) { j["measurement"] = {{"count_gaps", "yes"}}; },
     {"measurement.count_gaps", "\"yes\"", "true or false"}},
    {"log range with zero",
     [](json& j) {
       j["sweep"] = {{"cohesion_ratio", {{"log", {0.0, 1.0, 4}}}}};
     },
     {"sweep.cohesion_ratio.log", "bound 0"}},
    {"count not an integer",
     [](json& j) {
       j["sweep"] = {{"cohesion_ratio", {{"linear", {0.1, 1.0, 2.5}}}}};
     },
     {"sweep.cohesion_ratio.linear", "count must be an integer"}},
    {"count zero",
     [](json& j) {
       j["sweep"] = {{"cohesion_ratio", {{"linear", {0.1, 1.0, 0}}}}};
     },
     {"sweep.cohesion_ratio.linear", "count 0", "[1, 10000]"}},
    {"range of two numbers",
     [](json& j) {
       j["sweep"] = {{"cohesion_ratio", {{"linear", {0.1, 1.0}}}}};
     },
     {"sweep.cohesion_ratio.linear", "[first, last, count]"}},
    {"unknown range kind",
     [](json& j) {
       j["sweep"] = {{"cohesion_ratio", {{"geometric", {0.1, 1.0, 3}}}}};
     },
     {"sweep.cohesion_ratio", "must be a list of values"}},
    {"empty list",
     [](json& j) {
       j["sweep"] = {{"cohesion_ratio", json::array()}};
     },
     {"sweep.cohesion_ratio", "empty list"}},
    {"cohesion ratio out of range",
     [](json& j) {
       j["fixed"] = {{"cohesion_ratio", -1.0}};
     },
     {"fixed.cohesion_ratio", "value -1", "(0, 10000]"}},
    {"group value not a number",
     [](json& j) {
       j["sweep"] = {{"slope", {"steep"}}};
     },
     {"sweep.slope", "must be a number"}},
    {"unknown parameter",
     [](json& j) {
       j["sweep"] = {{"cohesion", {0.1}}};
     },
     {"sweep.cohesion", "unknown parameter 'cohesion'", "cohesion_ratio"}},
    {"pointer to no scene field",
     [](json& j) {
       j["fixed"] = {{"/ice/thicknes", 50.0}};
     },
     {"fixed./ice/thicknes", "not a scene parameter", "'thicknes'"}},
    {"group and its scene field",
     [](json& j) {
       j["fixed"] = {{"cohesion_ratio", 0.1}, {"/ice/tensile_strength", 1e5}};
     },
     {"cohesion_ratio", "/ice/tensile_strength", "give only one"}},
    {"slope and step height ratio",
     [](json& j) {
       j["fixed"] = {{"slope", 1.0}, {"step_height_ratio", 1.0}};
     },
     {"slope", "step_height_ratio", "give only one"}},
    {"slope of a vertical step",
     [](json& j) {
       j["fixed"] = {{"step_length_ratio", 0.0}, {"slope", 1.0}};
     },
     {"case 0", "vertical", "step_height_ratio"}},
    {"width ratio in 2D",
     [](json& j) {
       j["fixed"] = {{"width_ratio", 1.0}};
     },
     {"width_ratio", "3D", "dim 2"}},
    {"same parameter fixed and swept",
     [](json& j) {
       j["fixed"] = {{"thickness", 40.0}};
       j["sweep"] = {{"thickness", {40.0, 60.0}}};
     },
     {"sweep.thickness", "also set in fixed"}},
    {"repeated value",
     [](json& j) {
       j["sweep"] = {{"cohesion_ratio", {0.1, 0.2, 0.1}}};
     },
     {"cases 0", "and 2", "same parameters"}},
    {"replicas without jitter",
     [](json& j) { j["replicas"] = 3; },
     {"replicas", "/numerics/jitter"}},
    {"replicas out of range",
     [](json& j) { j["replicas"] = 0; },
     {"replicas", "value 0", "[1, 1000]"}},
    {"missing name", [](json& j) { j.erase("name"); }, {"name", "required"}},
    {"name with a slash", [](json& j) { j["name"] = "a/b"; }, {"name", "'a/b'"}},
    {"missing base scene", [](json& j) { j.erase("base_scene"); }, {"base_scene", "required"}},
    {"base scene file missing",
     [](json& j) { j["base_scene"] = "no/such/scene.json"; },
     {"base_scene", "cannot open"}},
    {"unknown top-level key",
     [](json& j) { j["sweeps"] = json::object(); },
     {"sweeps", "unknown key"}},
    {"scene invalid for a case",
     [](json& j) {
       j["sweep"] = {{"thickness", {40.0, 20.0}}};
     },
     {"case 1 (thickness=20)", "numerics.dx", "too coarse"}},
    {"unknown scene key",
     [](json& j) { j["base_scene"]["ice"]["colour"] = "blue"; },
     {"case 0", "ice.colour", "unknown key"}},
    {"jobs negative",
     [](json& j) {
       j["resources"] = {{"jobs", -1}};
     },
     {"resources.jobs", "value -1", "[0, 1024]"}},
    {"unknown resource",
     [](json& j) {
       j["resources"] = {{"cores", 2}};
     },
     {"resources.cores", "unknown key"}},
    {"unknown measurement setting",
     [](json& j) {
       j["measurement"] = {{"threshold", 0.9}};
     },
     {"measurement.threshold", "unknown key"}},
    {"damage threshold out of range",
     [](json& j) {
       j["measurement"] = {{"damage_threshold", 1.5}};
     },
     {"measurement.damage_threshold", "1.5", "(0, 1)"}},
    {"cells per thickness too few",
     [](json& j) {
       j["fixed"] = {{"cells_per_thickness", 2.0}};
     },
     {"fixed.cells_per_thickness", "value 2", "[4, 10000]"}},
};

INSTANTIATE_TEST_SUITE_P(Refusals, InvalidStudy, ::testing::ValuesIn(kBadStudies),
                         [](const auto& info) { return "case_" + std::to_string(info.index); });

TEST(StudyFile, NotJsonIsRefused) {
  try {
    parse_study("{\"name\": \"x\", ", ".", "broken.json");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("broken.json: not valid JSON"), std::string::npos)
        << e.what();
  }
}

TEST(Shard, ParsesAndRefuses) {
  EXPECT_EQ(parse_shard("0/4").index, 0);
  EXPECT_EQ(parse_shard("3/4").count, 4);
  for (const char* bad : {"4/4", "-1/4", "1/0", "a/b", "1", "1/2/3", ""}) {
    try {
      parse_shard(bad);
      ADD_FAILURE() << bad << " accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("--shard"), std::string::npos);
    }
  }
}

}  // namespace
}  // namespace crevasse

namespace crevasse {
namespace {

// Every study shipped in studies/ and studies/numerics/ loads (named after its file) and runs a
// glacier in contact with its bed across the whole step (draped to the outflow, no ice cliff); the
// calving-front studies of studies/cliff/, and studies that set draped_length_ratio 0
// themselves, start from the cliff. quick.json runs the pushed glacier (fed by an
// inflow, free downstream, q_y = 10 c) in the initiation protocol from weak to strong ice in 2D,
// every case resolved (c/(ρ_i g) ≥ 3 dx), at most 6 cases of H_i ≤ 400 m (the main job's budget).
TEST(ShippedStudies, AllLoadAndQuickSpansWeakToStrongIce) {
  const std::filesystem::path dir = std::filesystem::path(CREVASSE_SOURCE_DIR) / "studies";
  int loaded = 0;
  for (const std::string sub : {"", "numerics", "cliff"}) {
    const bool cliff = sub == "cliff";
    for (const auto& entry : std::filesystem::directory_iterator(dir / sub)) {
      if (entry.path().extension() != ".json") continue;
      SCOPED_TRACE(entry.path().string());
      const Study s = load_study_file(entry.path());
      const nlohmann::json file = nlohmann::json::parse(std::ifstream(entry.path()));
      const bool sets_no_drape = file.contains("fixed") && file["fixed"].contains("draped_length_ratio") &&
                                 file["fixed"]["draped_length_ratio"] == 0;
      EXPECT_EQ(s.name, entry.path().stem().string());
      EXPECT_FALSE(s.cases.empty());
      for (const auto& c : s.cases) {
        // A study may start from a cliff only where its file says so: the cliff studies, or a
        // study that sets draped_length_ratio to 0 itself (an experiment on the start).
        if (cliff || sets_no_drape) {
          EXPECT_EQ(c.scene.draped_length, 0.0) << c.label;
        } else {
          EXPECT_GT(c.scene.draped_length, c.scene.step_length) << c.label;
          EXPECT_TRUE(c.scene.has(Effect::outflow)) << c.label;
        }
      }
      ++loaded;
    }
  }
  EXPECT_GE(loaded, 20);  // the studies of results/README.md
  const Study quick = load_study_file(dir / "quick.json");
  double lo = 1e9, hi = 0;
  std::size_t resolved = 0;
  for (const auto& c : quick.cases) {
    EXPECT_EQ(c.scene.dim, 2);
    EXPECT_EQ(c.scene.drive_boundary, DriveBoundary::inflow);
    EXPECT_GT(c.scene.draped_length, c.scene.upstream_length + c.scene.step_length);
    EXPECT_LE(c.scene.ice_thickness, 400.0);
    // The pushed scene: nothing held downstream, not carried by a tilted gravity, q_y = k c.
    EXPECT_FALSE(c.scene.has(Effect::downstream_drive));
    EXPECT_EQ(c.scene.gravity_tilt_deg, 0.0);
    EXPECT_NEAR(c.scene.shear_strength, 10.0 * c.scene.tensile_strength, 1e-6 * c.scene.shear_strength);
    lo = std::min(lo, c.groups.cohesion_ratio);
    hi = std::max(hi, c.groups.cohesion_ratio);
    const SceneConfig& sc = c.scene;
    resolved += !analysis::strength_under_resolved(sc.tensile_strength, sc.density, sc.gravity, sc.dx);
  }
  EXPECT_EQ(quick.protocol, "initiation");
  EXPECT_LE(lo, 0.1 * (1.0 + 1e-9));  // Π as computed back from the resolved scene
  EXPECT_GE(hi, 0.4);
  EXPECT_EQ(resolved, quick.cases.size());
  EXPECT_LE(quick.cases.size(), 6u);
  // accuracy_drive's rows are accuracy_cost's cases at other drive speeds: the same scene
  // apart from drive.speed, so the table compares like with like.
  const Study acc = load_study_file(dir / "cliff" / "accuracy_cost.json");
  const Study drive = load_study_file(dir / "cliff" / "accuracy_drive.json");
  for (const auto& c : drive.cases) {
    SCOPED_TRACE(c.label);
    EXPECT_NE(c.scene.drive_speed, 4.0);
    nlohmann::json faster = scene_to_json(c.scene);
    int matched = 0;
    for (const auto& a : acc.cases) {
      nlohmann::json base = scene_to_json(a.scene);
      base["drive"]["speed"] = faster["drive"]["speed"];
      matched += base == faster;
    }
    EXPECT_EQ(matched, 1);
  }
  // three_d runs at cohesion ratios of cliff_quick's cases (its 2D counterpart on the diagram).
  const Study cliff_quick = load_study_file(dir / "cliff" / "cliff_quick.json");
  const Study three = load_study_file(dir / "cliff" / "three_d.json");
  for (const auto& c : three.cases) {
    EXPECT_EQ(c.scene.dim, 3);
    bool matched = false;
    for (const auto& q : cliff_quick.cases)
      matched = matched || q.scene.tensile_strength == c.scene.tensile_strength;
    EXPECT_TRUE(matched) << c.label;
  }
}

}  // namespace
}  // namespace crevasse

namespace crevasse {
namespace {

// Strengths relative to the overburden, and the gate's place past the lip in H_i.
TEST(StudyFile, ShearStrengthRatioAndGateOffsetRatioScaleWithThickness) {
  nlohmann::json j = {{"name", "t"}, {"base_scene", test::tiny_scene()}};
  j["fixed"] = {{"thickness", 40.0}, {"shear_strength_ratio", 1.5}, {"gate_offset_ratio", 0.25}};
  const Study s = test::parse(j);
  ASSERT_EQ(s.cases.size(), 1u);
  const SceneConfig& c = s.cases[0].scene;
  EXPECT_DOUBLE_EQ(c.shear_strength, 1.5 * c.density * c.gravity * 40.0);
  EXPECT_DOUBLE_EQ(c.gate_offset, 10.0);
  EXPECT_DOUBLE_EQ(c.gate_x(), c.step_top_x() + 10.0);
}

// q_y = k c follows the tensile strength however it is given (Π or the pointer), not H_i; the
// draped length is in H_i; giving q_y both ways is refused naming both.
TEST(StudyFile, ShearToTensileRatioFollowsTheTensileStrength) {
  nlohmann::json j = {{"name", "t"}, {"base_scene", test::tiny_scene()}};
  j["fixed"] = {{"shear_to_tensile_ratio", 10.0}, {"draped_length_ratio", 0.5}};
  j["sweep"] = {{"thickness", {40.0, 80.0}}, {"/ice/tensile_strength", {1.0e5, 2.0e5}}};
  const Study s = test::parse(j);
  ASSERT_EQ(s.cases.size(), 4u);
  for (const auto& sc : s.cases) {
    EXPECT_DOUBLE_EQ(sc.scene.shear_strength, 10.0 * sc.scene.tensile_strength) << sc.label;
    EXPECT_DOUBLE_EQ(sc.scene.draped_length, 0.5 * sc.scene.ice_thickness) << sc.label;
  }
  j["sweep"] = {{"cohesion_ratio", {0.1}}};
  j["fixed"]["thickness"] = 40.0;
  const Study pi = test::parse(j);
  const SceneConfig& c = pi.cases[0].scene;
  EXPECT_DOUBLE_EQ(c.shear_strength, 10.0 * 0.1 * c.density * c.gravity * 40.0);
  j["fixed"]["shear_strength_ratio"] = 1.0;
  try {
    test::parse(j);
    FAIL() << "both shear strengths accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("shear_to_tensile_ratio"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("shear_strength_ratio"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace crevasse

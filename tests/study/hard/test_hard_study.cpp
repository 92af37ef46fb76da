// Hard cases in a study, label `hard`: a study holding a case pushed past
// the stability limit records it as failed, with the engine's diagnosis as the reason, and
// still completes the stable case next to it. The unstable case is CFL 2, the largest the scene
// validation accepts (numerics.cfl in (0, 2]); the engine blows up there within a few steps
// (tests/engine/hard/test_hard_cases.cpp, DISABLED_CflMax2).
#include <gtest/gtest.h>

#include "../study_test_support.hpp"

namespace crevasse {
namespace {

// The base hard case of tests/engine/hard (H_i = 100 m, slope 1, Π = 0.2) at dx = H_i/4,
// 192 particles, for 10 simulated seconds after settling.
nlohmann::json small_glacier() {
  return {{"name", "hard_small_glacier"},
          {"dim", 2},
          {"effects", {"gravity", "drive", "basal_friction", "plasticity", "softening", "outflow"}},
          {"ice", {{"thickness", 100.0}, {"upstream_length", 300.0}}},
          {"bed", {{"shape", "step"}, {"step_height", 100.0}, {"step_length", 100.0},
                   {"downstream_length", 400.0}}},
          {"numerics", {{"dx", 25.0}}},
          {"run", {{"end_time", 10.0}}},
          {"output", {{"vtu_interval", 0.0}, {"png", false}}}};
}

TEST(HardStudy, CaseBeyondStabilityIsRecordedAsFailedWithTheDiagnosis) {
  test::ScratchDir dir("hard_study");
  const nlohmann::json study_json = {{"name", "hard_cfl"},
                                     {"base_scene", small_glacier()},
                                     {"fixed", {{"cohesion_ratio", 0.2}}},
                                     {"sweep", {{"/numerics/cfl", {0.5, 2.0}}}},
                                     {"resources", {{"threads_per_case", 1}}}};
  const Study study = test::parse(study_json);
  ASSERT_EQ(study.cases.size(), 2u);
  RunnerOptions o;
  o.db_path = dir / "hard.db";
  o.jobs = 1;
  o.threads_per_case = 1;
  const RunnerReport r = run_study(study, o);
  EXPECT_EQ(r.done, 1u);
  EXPECT_EQ(r.failed, 1u);

  const auto rows = test::dump_rows(
      dir / "hard.db",
      "SELECT json_extract(scene_json, '$.numerics.cfl'), status, coalesce(failure_reason, '') "
      "FROM cases ORDER BY case_index");
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].substr(0, rows[0].find('|')), "0.5");
  EXPECT_EQ(rows[0].substr(rows[0].find('|')), "|done|") << rows[0];
  const std::string& bad = rows[1];
  std::printf("[hard] HardStudy: %s\n", bad.c_str());
  EXPECT_EQ(bad.rfind("2.0|failed|", 0), 0u) << bad;
  // The reason is the engine's diagnosis: step, particle, quantity and what to change.
  EXPECT_NE(bad.find("step "), std::string::npos) << bad;
  EXPECT_NE(bad.find("particle "), std::string::npos) << bad;
  EXPECT_TRUE(bad.find("in one step") != std::string::npos ||
              bad.find("above the physical bound") != std::string::npos ||
              bad.find("non-finite velocity or stress") != std::string::npos)
      << bad;
  EXPECT_NE(bad.find("numerics.cfl"), std::string::npos) << bad;
  EXPECT_EQ(test::pragma_integrity(dir / "hard.db"), "ok");
  EXPECT_NE(r.first_failure.find("unstable"), std::string::npos) << r.first_failure;
}

}  // namespace
}  // namespace crevasse

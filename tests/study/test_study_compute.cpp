// The compute a study database holds: a case served by another case's kept particles costs
// nothing here, a case measured again from its own run counts that run's engine time.
#include <gtest/gtest.h>

#include "study/store.hpp"
#include "study/study_compute.hpp"
#include "study_test_support.hpp"

namespace crevasse {
namespace {

TEST(StudyCompute, CountsEachRunOnceWhereItRan) {
  test::ScratchDir dir("compute");
  const Study study = test::parse(test::tiny_study(5));
  Store store = Store::open_writer(dir / "s.db");
  store.init_study(study);
  std::vector<const StudyCase*> cases;
  for (const auto& c : study.cases) cases.push_back(&c);
  store.add_cases(cases);
  // Case 0 ran; 1 was measured again from its own run (0.2 s now, 800 s of engine then); 2 was
  // served by a longer run's mark (its particle-steps and engine time are that run's, counted
  // there); 3 failed after 10 s; 4, at another H_i, has not run.
  store.exec(
      "UPDATE cases SET thickness_m = 400, status = 'done', wall_s = 1000, "
      "particle_steps = 2000000000, run_json = '{\"engine_wall_s\": 1000}' WHERE case_index = 0;"
      "UPDATE cases SET thickness_m = 400, status = 'done', wall_s = 0.2, "
      "particle_steps = 1000000000, run_json = '{\"engine_wall_s\": 800, \"measured_from\": "
      "{\"database\": \"s.db\"}}' WHERE case_index = 1;"
      "UPDATE cases SET thickness_m = 400, status = 'done', wall_s = 0.2, "
      "particle_steps = 5000000000, run_json = '{\"engine_wall_s\": 9000, \"measured_from\": "
      "{\"database\": \"t.db\", \"kept_at_gate_mark_of_case_id\": \"x\"}}' WHERE case_index = 2;"
      "UPDATE cases SET thickness_m = 400, status = 'failed', wall_s = 10, "
      "particle_steps = 10000000 WHERE case_index = 3;"
      "UPDATE cases SET thickness_m = 800 WHERE case_index = 4;");

  const std::vector<ComputeRow> rows = study_compute(store);
  ASSERT_EQ(rows.size(), 2u);
  EXPECT_EQ(rows[0].thickness_m, 400);
  EXPECT_EQ(rows[0].run, 3);
  EXPECT_EQ(rows[0].served, 1);
  EXPECT_EQ(rows[0].pending, 0);
  EXPECT_DOUBLE_EQ(rows[0].particle_steps, 3.01e9);
  EXPECT_DOUBLE_EQ(rows[0].wall_s, 1810.0);
  EXPECT_DOUBLE_EQ(rows[0].median_rate, 1.25e6);  // of 2e6, 1.25e6 and 1e6 per second
  EXPECT_EQ(rows[1].thickness_m, 800);
  EXPECT_EQ(rows[1].run, 0);
  EXPECT_EQ(rows[1].pending, 1);
  EXPECT_EQ(rows[1].median_rate, 0.0);

  const ComputeRow t = compute_total(rows);
  EXPECT_EQ(t.run, 3);
  EXPECT_EQ(t.served, 1);
  EXPECT_EQ(t.pending, 1);
  EXPECT_DOUBLE_EQ(t.wall_s, 1810.0);
}

}  // namespace
}  // namespace crevasse

// Shards split a study into disjoint, balanced, order-independent shares; merging the shard
// databases gives what one run gives; conflicting results are reported, other studies refused.
#include <gtest/gtest.h>

#include <set>

#include "engine/error.hpp"
#include "study/merge.hpp"
#include "study/runner.hpp"
#include "study/shard.hpp"
#include "study_test_support.hpp"

namespace crevasse {
namespace {

TEST(Shard, SharesAreDisjointBalancedAndCoverTheStudy) {
  const Study study = test::parse(test::tiny_study(7));
  for (int n = 1; n <= 8; ++n) {
    std::set<std::string> seen;
    std::size_t smallest = 1000, largest = 0;
    for (int i = 0; i < n; ++i) {
      const auto share = shard_cases(study, Shard{i, n});
      smallest = std::min(smallest, share.size());
      largest = std::max(largest, share.size());
      for (const StudyCase* c : share)
        EXPECT_TRUE(seen.insert(c->case_id).second) << "case in two shards";
      for (std::size_t k = 1; k < share.size(); ++k)
        EXPECT_LT(share[k - 1]->index, share[k]->index);
    }
    EXPECT_EQ(seen.size(), study.cases.size());
    EXPECT_LE(largest - smallest, 1u);
  }
}

TEST(Shard, DependsOnTheCasesNotOnTheFileLayout) {
  const std::string scene = test::tiny_scene().dump();
  const Study a =
      parse_study(R"({"name": "a", "base_scene": )" + scene +
                      R"(, "sweep": {"cohesion_ratio": [0.1, 0.2, 0.3], "thickness": [40, 50]}})",
                  ".", "a");
  const Study b = parse_study(
      R"({"sweep": {"thickness": [40, 50], "cohesion_ratio": [0.1, 0.2, 0.3]}, "name": "a",
                                  "base_scene": )" +
          scene + "}",
      ".", "b");
  for (int i = 0; i < 3; ++i) {
    std::set<std::string> sa, sb;
    for (const StudyCase* c : shard_cases(a, Shard{i, 3})) sa.insert(c->case_id);
    for (const StudyCase* c : shard_cases(b, Shard{i, 3})) sb.insert(c->case_id);
    EXPECT_EQ(sa, sb);
  }
}

RunnerOptions real_options(const std::filesystem::path& db,
                           std::optional<Shard> shard = std::nullopt) {
  RunnerOptions o;
  o.db_path = db;
  o.jobs = 2;
  o.threads_per_case = 1;
  o.shard = shard;
  return o;
}

TEST(Merge, ShardsMergedEqualOneRun) {
  test::ScratchDir dir("merge");
  const Study study = test::parse(test::tiny_study(5, 200));
  run_study(study, real_options(dir / "single.db"));
  for (int i = 0; i < 3; ++i)
    run_study(study, real_options(dir / ("shard" + std::to_string(i) + ".db"), Shard{i, 3}));
  EXPECT_EQ(Store::open_reader(dir / "shard1.db").counts().total(), 2);
  const MergeReport r =
      merge_databases(dir / "merged.db", {dir / "shard0.db", dir / "shard1.db", dir / "shard2.db"});
  EXPECT_EQ(r.inputs, 3u);
  EXPECT_EQ(r.copied, 5u);
  EXPECT_EQ(r.conflicts, 0u);
  EXPECT_EQ(test::result_dump(dir / "merged.db"), test::result_dump(dir / "single.db"));
  EXPECT_EQ(test::dump_rows(dir / "merged.db", "SELECT count(*) FROM sessions").at(0), "3");
  EXPECT_EQ(test::pragma_integrity(dir / "merged.db"), "ok");

  // Merging again changes nothing: identical cases are kept once.
  const MergeReport again =
      merge_databases(dir / "merged.db", {dir / "shard0.db", dir / "single.db"});
  EXPECT_EQ(again.copied, 0u);
  EXPECT_EQ(again.identical, 2u + 5u);
  EXPECT_EQ(test::result_dump(dir / "merged.db"), test::result_dump(dir / "single.db"));
}

TEST(Merge, AFinishedCaseReplacesAPendingOneAndConflictsAreReported) {
  test::ScratchDir dir("merge");
  const Study study = test::parse(test::tiny_study(4));
  auto make = [&](const std::string& name, double depth_scale, std::size_t fail_index) {
    RunnerOptions o;
    o.db_path = dir / name;
    o.jobs = 1;
    o.case_function = [=](const StudyCase& c, CaseContext&) {
      if (c.index == fail_index) throw SimulationError("unstable");
      return test::fake_outcome(c, depth_scale);
    };
    run_study(study, o);
  };
  make("a.db", 1.0, 99);  // all done
  make("b.db", 2.0, 0);   // case 0 failed, the others done with other depths
  const MergeReport r = merge_databases(dir / "out.db", {dir / "a.db", dir / "b.db"});
  EXPECT_EQ(r.copied, 4u);
  EXPECT_EQ(r.conflicts, 4u);
  ASSERT_EQ(r.conflict_lines.size(), 4u);
  for (const auto& line : r.conflict_lines)
    EXPECT_NE(line.find("kept out.db's"), std::string::npos) << line;
  // out.db keeps a.db's results.
  EXPECT_EQ(
      test::dump_rows(
          dir / "out.db",
          "SELECT group_concat(result_hash) FROM (SELECT result_hash FROM cases ORDER BY case_id)"),
      test::dump_rows(dir / "a.db",
                      "SELECT group_concat(result_hash) FROM (SELECT result_hash FROM cases ORDER "
                      "BY case_id)"));
}

TEST(Merge, RefusesAnotherStudyAndTheOutputAsInput) {
  test::ScratchDir dir("merge");
  RunnerOptions o;
  o.jobs = 1;
  o.case_function = [](const StudyCase& c, CaseContext&) { return test::fake_outcome(c); };
  o.db_path = dir / "a.db";
  run_study(test::parse(test::tiny_study(2)), o);
  o.db_path = dir / "b.db";
  run_study(test::parse(test::tiny_study(3)), o);
  try {
    merge_databases(dir / "out.db", {dir / "a.db", dir / "b.db"});
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("merge only databases of one study"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(merge_databases(dir / "a.db", {dir / "a.db"}), InputError);
  EXPECT_THROW(merge_databases(dir / "c.db", {dir / "missing.db"}), InputError);
}

}  // namespace
}  // namespace crevasse

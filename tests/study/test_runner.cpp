// The runner: cases run concurrently, a failing case does not stop the others, --fail-fast
// does, time limits fail a case, finished cases are never rerun, and real tiny simulations end
// up in the database with their crevasse measurements.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <map>
#include <mutex>
#include <set>
#include <thread>
#include <utility>
#include <vector>

#include "engine/error.hpp"
#include "study/runner.hpp"
#include "study_test_support.hpp"

namespace crevasse {
namespace {

using namespace std::chrono_literals;

// The runner and the study command's re-measurement check both ask this which cases a run starts.
TEST(CasesToRun, SkipsDoneAndFailedKeepsPendingRunningAndUnstoredWithinTheSelection) {
  std::vector<StudyCase> cases(5);
  const char* stored[] = {"done", "failed", "pending", "running", nullptr};
  std::map<std::string, std::string> status;
  std::vector<const StudyCase*> scope;
  for (std::size_t i = 0; i < cases.size(); ++i) {
    cases[i].index = i;
    cases[i].case_id = "id" + std::to_string(i);
    if (stored[i]) status[cases[i].case_id] = stored[i];
    scope.push_back(&cases[i]);
  }
  const auto indices = [](const std::vector<const StudyCase*>& v) {
    std::vector<std::size_t> out;
    for (const StudyCase* c : v) out.push_back(c->index);
    return out;
  };
  EXPECT_EQ(indices(cases_to_run(scope, status, {}, false)), (std::vector<std::size_t>{2, 3, 4}));
  EXPECT_EQ(indices(cases_to_run(scope, status, {}, true)), (std::vector<std::size_t>{1, 2, 3, 4}));
  EXPECT_EQ(indices(cases_to_run(scope, status, {0, 1, 3}, false)), (std::vector<std::size_t>{3}));
  EXPECT_TRUE(cases_to_run(scope, status, {0, 1}, false).empty());
  EXPECT_EQ(indices(cases_to_run(scope, status, {0, 1}, true)), (std::vector<std::size_t>{1}));
}

RunnerOptions fake_options(const std::filesystem::path& db, CaseFunction f, int jobs = 2) {
  RunnerOptions o;
  o.db_path = db;
  o.jobs = jobs;
  o.threads_per_case = 1;
  o.case_function = std::move(f);
  return o;
}

// The cases a case function was called for, from concurrent jobs.
struct CallLog {
  std::mutex m;
  std::multiset<std::size_t> calls;
  void record(std::size_t index) {
    std::lock_guard lock(m);
    calls.insert(index);
  }
  std::multiset<std::size_t> take() { return std::exchange(calls, {}); }
};

TEST(Runner, AFailingMiddleCaseIsRecordedAndTheOthersComplete) {
  test::ScratchDir dir("runner");
  const Study study = test::parse(test::tiny_study(5));
  auto fn = [](const StudyCase& c, CaseContext&) {
    if (c.index == 2) throw SimulationError("instability at step 17, particle 4: |v| = inf");
    return test::fake_outcome(c);
  };
  const RunnerReport r = run_study(study, fake_options(dir / "s.db", fn));
  EXPECT_EQ(r.done, 4u);
  EXPECT_EQ(r.failed, 1u);
  EXPECT_FALSE(r.stopped);
  EXPECT_NE(r.first_failure.find("instability at step 17"), std::string::npos);
  const auto rows =
      test::dump_rows(dir / "s.db",
                      "SELECT case_index, status, coalesce(failure_reason, '') FROM cases "
                      "ORDER BY case_index");
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows[2], "2|failed|instability at step 17, particle 4: |v| = inf");
  for (int i : {0, 1, 3, 4}) EXPECT_EQ(rows[i], std::to_string(i).append("|done|"));
  // Failed cases have no crevasse rows; the others have index+1 each.
  EXPECT_EQ(test::dump_rows(dir / "s.db", "SELECT count(*) FROM crevasses").at(0),
            std::to_string(1 + 2 + 4 + 5));
  EXPECT_EQ(test::pragma_integrity(dir / "s.db"), "ok");
}

TEST(Runner, OtherExceptionsFailTheCaseWithTheirReason) {
  test::ScratchDir dir("runner");
  const Study study = test::parse(test::tiny_study(3));
  auto fn = [](const StudyCase& c, CaseContext&) -> CaseOutcome {
    if (c.index == 0) throw std::runtime_error("measurement went wrong");
    if (c.index == 1) throw std::bad_alloc();
    return test::fake_outcome(c);
  };
  run_study(study, fake_options(dir / "s.db", fn));
  const auto rows =
      test::dump_rows(dir / "s.db", "SELECT failure_reason FROM cases ORDER BY case_index");
  EXPECT_EQ(rows[0], "error: measurement went wrong");
  EXPECT_EQ(rows[1], "out of memory");
  EXPECT_EQ(rows[2], "NULL");
}

TEST(Runner, FailFastStopsAtTheFirstFailureAndLeavesTheRestPending) {
  test::ScratchDir dir("runner");
  const Study study = test::parse(test::tiny_study(5));
  auto fn = [](const StudyCase& c, CaseContext&) {
    if (c.index == 1) throw SimulationError("NaN in particle 3");
    return test::fake_outcome(c);
  };
  RunnerOptions o = fake_options(dir / "s.db", fn, 1);
  o.fail_fast = true;
  const RunnerReport r = run_study(study, o);
  EXPECT_TRUE(r.stopped);
  EXPECT_EQ(r.done, 1u);
  EXPECT_EQ(r.failed, 1u);
  EXPECT_EQ(
      test::dump_rows(dir / "s.db",
                      "SELECT group_concat(status, ',') FROM (SELECT status FROM cases ORDER BY "
                      "case_index)")
          .at(0),
      "done,failed,pending,pending,pending");
}

TEST(Runner, OnlyTheChosenCasesRunAndTheOthersStayPending) {
  test::ScratchDir dir("runner");
  const Study study = test::parse(test::tiny_study(5));
  CallLog log;
  auto fn = [&](const StudyCase& c, CaseContext&) {
    log.record(c.index);
    return test::fake_outcome(c);
  };
  RunnerOptions o = fake_options(dir / "s.db", fn);
  o.only_cases = parse_case_list("3,1", study.cases.size());
  const RunnerReport r = run_study(study, o);
  EXPECT_EQ(r.done, 2u);
  EXPECT_EQ(log.take(), (std::multiset<std::size_t>{1, 3}));
  const std::string order =
      "SELECT group_concat(status, ',') FROM (SELECT status FROM cases ORDER BY case_index)";
  EXPECT_EQ(test::dump_rows(dir / "s.db", order).at(0), "pending,done,pending,done,pending");
  // Progress counts every finished case, chosen or not.
  o.only_cases = {0};
  const RunnerReport second = run_study(study, o);
  EXPECT_EQ(second.already_done, 2u);
  EXPECT_EQ(second.done, 1u);
  EXPECT_EQ(log.take(), (std::multiset<std::size_t>{0}));
  // The next session without a choice runs the rest, not the chosen cases again.
  const RunnerReport third = run_study(study, fake_options(dir / "s.db", fn));
  EXPECT_EQ(third.already_done, 3u);
  EXPECT_EQ(log.take(), (std::multiset<std::size_t>{2, 4}));
  EXPECT_EQ(test::dump_rows(dir / "s.db", order).at(0), "done,done,done,done,done");
}

TEST(Runner, ACaseListIsParsedOrRefusedNamingTheOption) {
  EXPECT_EQ(parse_case_list("30,33", 40), (std::vector<std::size_t>{30, 33}));
  EXPECT_EQ(parse_case_list("5-7,2,6", 40), (std::vector<std::size_t>{2, 5, 6, 7}));
  EXPECT_EQ(parse_case_list("0", 1), (std::vector<std::size_t>{0}));
  for (const char* bad : {"", "a", "1,,2", "3-", "-3", "1.5", "40", "7-3"}) {
    try {
      parse_case_list(bad, 40);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("--cases: ", 0), 0u) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
  try {
    parse_case_list("40", 40);
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("[0, 39]"), std::string::npos) << e.what();
  }
}

TEST(Runner, AChosenCaseOutsideTheShardIsRefusedBeforeAnythingRuns) {
  test::ScratchDir dir("runner");
  const Study study = test::parse(test::tiny_study(4));
  const auto in_shard = shard_cases(study, Shard{0, 2});
  std::size_t outside = 0;
  while (std::any_of(in_shard.begin(), in_shard.end(), [&](const StudyCase* c) { return c->index == outside; }))
    ++outside;
  bool ran = false;
  RunnerOptions o = fake_options(dir / "s.db", [&](const StudyCase& c, CaseContext&) {
    ran = true;
    return test::fake_outcome(c);
  });
  o.shard = Shard{0, 2};
  o.only_cases = {outside};
  EXPECT_THROW(run_study(study, o), InputError);
  EXPECT_FALSE(ran);
}

// A case function for fail-fast: case 0 fails after `delay`; every other case runs until it is
// asked to stop, and stops as cancelled.
CaseFunction first_case_fails_after(std::chrono::milliseconds delay) {
  return [delay](const StudyCase& c, CaseContext& ctx) {
    if (c.index == 0) {
      std::this_thread::sleep_for(delay);
      throw SimulationError("boom");
    }
    while (!ctx.stop_requested()) std::this_thread::sleep_for(5ms);  // a long case
    CaseOutcome o;
    o.cancelled = true;
    return o;
  };
}

TEST(Runner, FailFastCancelsRunningCasesWhichStayPending) {
  test::ScratchDir dir("runner");
  const Study study = test::parse(test::tiny_study(4));
  RunnerOptions o = fake_options(dir / "s.db", first_case_fails_after(50ms), 2);
  o.fail_fast = true;
  const RunnerReport r = run_study(study, o);
  EXPECT_TRUE(r.stopped);
  EXPECT_EQ(r.cancelled, 1u);
  const auto c = Store::open_reader(dir / "s.db").counts();
  EXPECT_EQ(c.failed, 1);
  EXPECT_EQ(c.pending, 3);
  EXPECT_EQ(c.running, 0);
}

TEST(Runner, ACaseOverItsTimeLimitFails) {
  test::ScratchDir dir("runner");
  const Study study = test::parse(test::tiny_study(3));
  auto fn = [](const StudyCase& c, CaseContext& ctx) {
    if (c.index != 1) return test::fake_outcome(c);
    while (!ctx.stop_requested() && !ctx.time_limit_exceeded()) std::this_thread::sleep_for(5ms);
    CaseOutcome o;
    o.cancelled = true;
    if (ctx.time_limit_exceeded()) o.out_of_time = "time limit: over " + std::to_string(ctx.time_limit_s()) + " s";
    return o;
  };
  RunnerOptions o = fake_options(dir / "s.db", fn);
  o.case_time_limit_s = 0.2;
  const RunnerReport r = run_study(study, o);
  EXPECT_EQ(r.failed, 1u);
  EXPECT_EQ(r.done, 2u);
  const auto reason =
      test::dump_rows(dir / "s.db", "SELECT failure_reason FROM cases WHERE case_index = 1").at(0);
  EXPECT_NE(reason.find("time limit"), std::string::npos) << reason;
}

// The case alone knows why it stopped: a stop signal that comes after the case's time limit
// has passed, while the case had not yet looked at its clock, leaves it pending.
TEST(Runner, AStopAfterTheTimeLimitPassedLeavesTheCasePending) {
  test::ScratchDir dir("runner");
  const Study study = test::parse(test::tiny_study(2));
  // Case 0's failure stops case 1 after its limit has passed.
  RunnerOptions o = fake_options(dir / "s.db", first_case_fails_after(300ms), 2);
  o.fail_fast = true;
  o.case_time_limit_s = 0.1;
  const RunnerReport r = run_study(study, o);
  EXPECT_EQ(r.cancelled, 1u);
  EXPECT_EQ(test::dump_rows(dir / "s.db", "SELECT status FROM cases WHERE case_index = 1").at(0), "pending");
}

TEST(Runner, CasesRunConcurrentlyUpToJobs) {
  test::ScratchDir dir("runner");
  const Study study = test::parse(test::tiny_study(6));
  std::atomic<int> now{0}, peak{0};
  auto fn = [&](const StudyCase& c, CaseContext&) {
    const int n = ++now;
    for (int p = peak.load(); n > p && !peak.compare_exchange_weak(p, n);) {
    }
    std::this_thread::sleep_for(150ms);
    --now;
    return test::fake_outcome(c);
  };
  const auto t0 = std::chrono::steady_clock::now();
  const RunnerReport r = run_study(study, fake_options(dir / "s.db", fn, 3));
  const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(r.done, 6u);
  EXPECT_EQ(r.jobs, 3);
  EXPECT_LE(peak.load(), 3);
  EXPECT_GE(peak.load(), 2);
  EXPECT_LT(wall, 6 * 0.15 * 0.8) << "no concurrency";
}

TEST(Runner, FinishedCasesAreNeverRunAgain) {
  test::ScratchDir dir("runner");
  const Study study = test::parse(test::tiny_study(4));
  CallLog log;
  const std::multiset<std::size_t>& calls = log.calls;
  auto fn = [&](const StudyCase& c, CaseContext&) {
    log.record(c.index);
    if (c.index == 3) throw SimulationError("unstable");
    return test::fake_outcome(c);
  };
  run_study(study, fake_options(dir / "s.db", fn));
  EXPECT_EQ(calls.size(), 4u);
  const auto before = test::dump_rows(
      dir / "s.db", "SELECT case_id, finished_at, session_id FROM cases ORDER BY case_id");

  const RunnerReport again = run_study(study, fake_options(dir / "s.db", fn));
  EXPECT_EQ(calls.size(), 4u) << "a stored case ran again";
  EXPECT_EQ(again.already_done, 3u);
  EXPECT_EQ(again.already_failed, 1u);
  EXPECT_EQ(again.ran, 0u);
  EXPECT_EQ(before,
            test::dump_rows(dir / "s.db",
                            "SELECT case_id, finished_at, session_id FROM cases ORDER BY case_id"));

  RunnerOptions retry = fake_options(dir / "s.db", fn);
  retry.retry_failed = true;
  const RunnerReport r3 = run_study(study, retry);
  EXPECT_EQ(r3.ran, 1u);
  EXPECT_EQ(calls.count(3), 2u);
  EXPECT_EQ(test::dump_rows(dir / "s.db", "SELECT count(*) FROM sessions").at(0), "3");
}

class CountingObserver : public StudyObserver {
 public:
  void on_start(const RunnerReport&, const RunnerProgress& p) override {
    start_pending = p.pending;
  }
  void on_case_finished(const StudyCase&, const CaseResult&, const RunnerProgress& p) override {
    ++finished;
    last = p;
  }
  void on_end(const RunnerReport&) override { ended = true; }
  std::size_t start_pending = 0, finished = 0;
  RunnerProgress last;
  bool ended = false;
};

TEST(Runner, ReportsProgressToItsObserver) {
  test::ScratchDir dir("runner");
  const Study study = test::parse(test::tiny_study(4));
  CountingObserver obs;
  RunnerOptions o = fake_options(
      dir / "s.db", [](const StudyCase& c, CaseContext&) { return test::fake_outcome(c); });
  o.observer = &obs;
  run_study(study, o);
  EXPECT_EQ(obs.start_pending, 4u);
  EXPECT_EQ(obs.finished, 4u);
  EXPECT_EQ(obs.last.done, 4u);
  EXPECT_EQ(obs.last.pending, 0u);
  EXPECT_EQ(obs.last.total, 4u);
  EXPECT_TRUE(obs.ended);
}

// A running case shows how far it has got: the observer sees it by its index in the study (not
// by its place among the cases this run starts: only 1 and 2 run, so case 2 is the second) while
// it runs, and not once it has finished.
class RunningCasesObserver : public StudyObserver {
 public:
  void on_progress(const RunnerProgress& p) override {
    for (const auto& [index, fraction] : p.running_cases)
      if (index == 2 && fraction == 0.25) seen.store(true);
    last = p;
  }
  std::atomic<bool> seen{false};
  RunnerProgress last;
};

TEST(Runner, ReportsHowFarEachRunningCaseHasGot) {
  test::ScratchDir dir("runner");
  const Study study = test::parse(test::tiny_study(3));
  RunningCasesObserver obs;
  RunnerOptions o = fake_options(dir / "s.db", [&](const StudyCase& c, CaseContext& ctx) {
    if (c.index == 2) {
      ctx.report_fraction(0.25);
      // Progress is reported about once a second; wait for it, but not forever.
      for (int i = 0; i < 100 && !obs.seen.load(); ++i)
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    return test::fake_outcome(c);
  });
  o.observer = &obs;
  o.only_cases = {1, 2};
  run_study(study, o);
  EXPECT_TRUE(obs.seen.load()) << "case 2 was never reported at 25 %";
  EXPECT_TRUE(obs.last.running_cases.empty());
}

// Real simulations: a few hundred steps of the tiny glacier per case, one engine thread each.
TEST(Runner, RealTinySimulationsAreStoredWithTheirMeasurements) {
  test::ScratchDir dir("runner");
  const Study study = test::parse(test::tiny_study(3, 300));
  RunnerOptions o;
  o.db_path = dir / "s.db";
  o.jobs = 2;
  o.threads_per_case = 1;
  const RunnerReport r = run_study(study, o);
  EXPECT_EQ(r.done, 3u) << r.first_failure;
  const auto rows =
      test::dump_rows(dir / "s.db",
                      "SELECT c.status, c.stop_reason, c.steps, c.threads, "
                      "s.particle_count > 0, c.peak_rss_bytes > 0, c.particle_steps > 0 "
                      "FROM cases c JOIN summaries s USING (case_id) ORDER BY case_index");
  ASSERT_EQ(rows.size(), 3u);
  for (const auto& row : rows) EXPECT_EQ(row, "done|max_steps|300|1|1|1|1");
  // Each case is measured under the other spacing rule too (the source study's "drop").
  const auto other = test::dump_rows(
      dir / "s.db",
      "SELECT json_extract(result_json, '$.extra.other_spacing_rule.spacing_rule'), "
      "json_type(result_json, '$.extra.other_spacing_rule.crevasse_count') FROM cases ORDER BY case_index");
  for (const auto& row : other) EXPECT_EQ(row, "drop|integer");
  // Deterministic with one engine thread per case: a second database holds the same results.
  RunnerOptions o2 = o;
  o2.db_path = dir / "t.db";
  o2.jobs = 1;
  run_study(study, o2);
  EXPECT_EQ(test::result_dump(dir / "s.db"), test::result_dump(dir / "t.db"));
}

// A side file that cannot be written (here its folder cannot be made: a regular file is in
// the way, as a full disk would stop it) is a warning: the case's result is stored all the same.
TEST(Runner, SideFilesThatCannotBeWrittenLeaveTheResultStored) {
  test::ScratchDir dir("runner");
  const Study study = test::parse(test::tiny_study(2, 300));
  test::write_text(dir / "a_file", "x");
  RunnerOptions o;
  o.db_path = dir / "s.db";
  o.jobs = 1;
  o.threads_per_case = 1;
  o.views_dir = dir / "a_file" / "views";
  o.particles_dir = dir / "a_file" / "particles";
  std::mutex m;
  std::vector<std::string> warnings;
  o.warn = [&](const std::string& w) {
    std::lock_guard<std::mutex> lock(m);
    warnings.push_back(w);
  };
  const RunnerReport r = run_study(study, o);
  EXPECT_EQ(r.done, 2u) << r.first_failure;
  EXPECT_EQ(r.failed, 0u);
  ASSERT_EQ(warnings.size(), 4u);  // the side views and the particles of each case
  for (const auto& w : warnings) EXPECT_NE(w.find("its result is stored"), std::string::npos) << w;
  EXPECT_EQ(test::dump_rows(dir / "s.db", "SELECT count(*) FROM summaries")[0], "2");
}

}  // namespace
}  // namespace crevasse

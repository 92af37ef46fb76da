#include <gtest/gtest.h>

#include "study/eta.hpp"

namespace crevasse {
namespace {

constexpr double kFresh = -1.0;  // resumed_from of a case that started from t = 0

// Times in seconds on a made-up clock: every expected value is worked by hand.
TEST(Eta, AFreshCaseIsProjectedFromItsStart) {
  EtaEstimator e(1);
  e.started(0, 10.0);
  e.observe(0, 0.0, kFresh, 10.0);
  EXPECT_FALSE(e.eta(0, 10.0));  // nothing done yet
  // First seen well on (a short case, or a slow first look): still counted from its start.
  e.observe(0, 0.2, kFresh, 42.0);
  e.observe(0, 0.25, kFresh, 50.0);
  // 0.25 in 40 s: 120 s still to go, plus two pending cases of 160 s each.
  EXPECT_NEAR(*e.eta(2, 50.0), 120.0 + 2 * 160.0, 1e-9);
}

TEST(Eta, AResumedCaseIsProjectedFromWhereItsCheckpointLeftIt) {
  EtaEstimator e(1);
  e.started(0, 0.0);
  e.observe(0, 0.0, kFresh, 1.0);   // loading its checkpoint: it has not said yet
  e.observe(0, 0.45, 0.45, 5.0);    // resumed at 45 %
  EXPECT_FALSE(e.eta(0, 5.0));
  e.observe(0, 0.55, 0.45, 105.0);
  // 10 % in 100 s: 450 s to go. Counting from 0 % would say 0.55 in 105 s, about 86 s to go.
  EXPECT_NEAR(*e.eta(0, 105.0), 450.0, 1e-9);
  // Finished with 1000 s of wall time over its sittings: the next pending case takes as long.
  e.finished(0, 1000.0);
  EXPECT_EQ(e.running(), 0u);
  EXPECT_NEAR(*e.eta(1, 560.0), 1000.0, 1e-9);
}

TEST(Eta, CasesAreSharedOverTheJobs) {
  EtaEstimator e(2);
  e.started(0, 0.0);
  e.started(1, 0.0);
  e.observe_running([](std::size_t slot) { return std::pair{slot == 0 ? 0.5 : 0.25, kFresh}; }, 50.0);
  // 50 s and 150 s still to run, two pending of (100 + 200)/2 s each: 500 s over two jobs.
  EXPECT_NEAR(*e.eta(2, 50.0), 250.0, 1e-9);
  e.stopped(1);
  EXPECT_EQ(e.running(), 1u);
  e.observe(1, 0.9, kFresh, 60.0);  // a slot no longer running is ignored
  EXPECT_EQ(e.running(), 1u);
}

}  // namespace
}  // namespace crevasse

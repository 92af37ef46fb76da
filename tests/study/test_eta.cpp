#include <gtest/gtest.h>

#include <map>

#include "study/eta.hpp"

namespace crevasse {
namespace {

// Times in seconds on a made-up clock: every expected value is worked by hand.
TEST(Eta, AFreshCaseIsProjectedFromItsStart) {
  EtaEstimator e(1);
  std::map<std::size_t, double> f{{0, 0.0}};
  auto fraction = [&](std::size_t s) { return f.at(s); };
  e.started(0, 10.0);
  EXPECT_FALSE(e.eta(0, fraction, 10.0));  // nothing done yet
  f[0] = 0.001;                             // first seen just started
  e.eta(0, fraction, 11.0);
  f[0] = 0.25;
  // 0.25 in 40 s: 120 s still to go, plus two pending cases of 160 s each.
  EXPECT_NEAR(*e.eta(2, fraction, 50.0), 120.0 + 2 * 160.0, 1e-9);
}

TEST(Eta, AResumedCaseIsProjectedFromWhereItsCheckpointLeftIt) {
  EtaEstimator e(1);
  std::map<std::size_t, double> f{{0, 0.0}};
  auto fraction = [&](std::size_t s) { return f.at(s); };
  e.started(0, 0.0);
  f[0] = 0.45;  // the checkpoint: first seen at 45 %
  EXPECT_FALSE(e.eta(0, fraction, 5.0));
  f[0] = 0.55;
  // 10 % in 100 s: 450 s to go. Counting from 0 % would say 0.55 in 105 s, about 86 s to go.
  EXPECT_NEAR(*e.eta(0, fraction, 105.0), 450.0, 1e-9);
  // Finished 450 s later: a whole case is 550 s / 0.55 = 1000 s, the next pending one too.
  e.finished(0, 555.0);
  EXPECT_NEAR(*e.eta(1, fraction, 560.0), 555.0 / 0.55, 1e-9);
}

TEST(Eta, CasesAreSharedOverTheJobs) {
  EtaEstimator e(2);
  std::map<std::size_t, double> f{{0, 0.0}, {1, 0.0}};
  auto fraction = [&](std::size_t s) { return f.at(s); };
  e.started(0, 0.0);
  e.started(1, 0.0);
  f[0] = f[1] = 0.001;
  e.eta(0, fraction, 1.0);
  f[0] = 0.5;
  f[1] = 0.25;
  // 50 s and 150 s still to run, two pending of (100 + 200)/2 s each: 500 s over two jobs.
  EXPECT_NEAR(*e.eta(2, fraction, 50.0), 250.0, 1e-9);
  e.stopped(1);
  EXPECT_EQ(e.running(), 1u);
}

}  // namespace
}  // namespace crevasse

// The progress line's pieces: durations and where each running case is.
#include <gtest/gtest.h>

#include "cli/progress_printer.hpp"

namespace crevasse {
namespace {

TEST(ProgressText, DurationsReadAsHoursMinutesSeconds) {
  EXPECT_EQ(format_duration(12.4), "12s");
  EXPECT_EQ(format_duration(200), "3m20s");
  EXPECT_EQ(format_duration(3720), "1h02m");
  EXPECT_EQ(format_duration(-1), "?");
}

TEST(ProgressText, RunningCasesByIndexWithTheirPercentage) {
  EXPECT_EQ(format_running_cases({}), "");
  EXPECT_EQ(format_running_cases({{9, 0.834}, {10, 0.5}}), " (case 9 at 83%, case 10 at 50%)");
  EXPECT_EQ(format_running_cases({{0, 0.0}, {1, 0.1}, {2, 0.2}, {3, 0.3}, {4, 0.4}, {5, 1.0}}),
            " (case 0 at 0%, case 1 at 10%, case 2 at 20%, case 3 at 30%, +2 more)");
}

}  // namespace
}  // namespace crevasse

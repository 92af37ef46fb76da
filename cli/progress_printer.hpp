#pragma once
// Progress lines for long work on the terminal: rewritten in place on a TTY, one line every
// few seconds otherwise (logs, CI).
#include <cstddef>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace crevasse {

std::string format_duration(double seconds);  // "1h02m", "3m20s", "12s"
std::string format_wall_time(double seconds);  // "12.3s" under a minute, else format_duration
// " (case 9 at 83%, case 10 at 51%)" from {case index, fraction 0-1}; past four cases the rest
// are counted (" …, +3 more)") so that the line fits a terminal; "" when none runs.
std::string format_running_cases(const std::vector<std::pair<std::size_t, double>>& cases);

class ProgressPrinter {
 public:
  explicit ProgressPrinter(std::FILE* out = stderr);
  void update(const std::string& line);  // replaces the current progress line
  void finish();                         // ends the progress line
 private:
  std::FILE* out_;
  bool tty_;
  bool open_ = false;
};

}  // namespace crevasse

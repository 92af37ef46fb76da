#pragma once
// Progress lines for long work on the terminal: rewritten in place on a TTY, one line every
// few seconds otherwise (logs, CI).
#include <cstdio>
#include <string>

namespace crevasse {

std::string format_duration(double seconds);  // "1h02m", "3m20s", "12s"
std::string format_wall_time(double seconds);  // "12.3s" under a minute, else format_duration

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

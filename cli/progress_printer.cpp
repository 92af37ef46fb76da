#include "cli/progress_printer.hpp"

#include <unistd.h>

#include <cmath>

namespace crevasse {

std::string format_duration(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return "?";
  const long s = std::lround(seconds);
  char buf[64];
  if (s >= 3600) std::snprintf(buf, sizeof buf, "%ldh%02ldm", s / 3600, (s % 3600) / 60);
  else if (s >= 60) std::snprintf(buf, sizeof buf, "%ldm%02lds", s / 60, s % 60);
  else std::snprintf(buf, sizeof buf, "%lds", s);
  return buf;
}

std::string format_wall_time(double seconds) {
  if (seconds >= 60) return format_duration(seconds);
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1fs", seconds);
  return buf;
}

std::string format_running_cases(const std::vector<std::pair<std::size_t, double>>& cases) {
  if (cases.empty()) return "";
  constexpr std::size_t shown = 4;
  std::string s = " (";
  for (std::size_t i = 0; i < cases.size() && i < shown; ++i) {
    char one[64];
    std::snprintf(one, sizeof one, "%scase %zu at %.0f%%", i ? ", " : "", cases[i].first,
                  100.0 * cases[i].second);
    s += one;
  }
  if (cases.size() > shown) s += ", +" + std::to_string(cases.size() - shown) + " more";
  return s + ")";
}

ProgressPrinter::ProgressPrinter(std::FILE* out) : out_(out), tty_(isatty(fileno(out)) != 0) {}

void ProgressPrinter::update(const std::string& line) {
  if (tty_) std::fprintf(out_, "\r\033[K%s", line.c_str());
  else std::fprintf(out_, "%s\n", line.c_str());
  std::fflush(out_);
  open_ = tty_;
}

void ProgressPrinter::finish() {
  if (open_) std::fprintf(out_, "\n");
  open_ = false;
  std::fflush(out_);
}

}  // namespace crevasse

#include "study/case_context.hpp"

namespace crevasse {

CaseContext::CaseContext(int threads, double time_limit_s,
                         const analysis::MeasureSettings& measurement,
                         const std::atomic<bool>& stop, CaseProgress& progress)
    : threads_(threads),
      time_limit_s_(time_limit_s),
      measurement_(measurement),
      stop_(stop),
      progress_(progress),
      start_(std::chrono::steady_clock::now()) {}

double CaseContext::elapsed_s() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

bool CaseContext::time_limit_exceeded() const {
  return time_limit_s_ > 0 && elapsed_s() > time_limit_s_;
}

}  // namespace crevasse

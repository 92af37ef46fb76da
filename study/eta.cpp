#include "study/eta.hpp"

#include <algorithm>

namespace crevasse {
namespace {
// Progress below this is too little to project a speed from.
constexpr double kMinProgress = 0.02;
}  // namespace

void EtaEstimator::started(std::size_t slot, double now_s) {
  Running r;
  r.start_s = now_s;
  running_[slot] = r;
}

void EtaEstimator::observe(std::size_t slot, double fraction, double resumed_from, double now_s) {
  const auto it = running_.find(slot);
  if (it != running_.end()) observe(it->second, fraction, resumed_from, now_s);
}

void EtaEstimator::observe(Running& r, double fraction, double resumed_from, double now_s) {
  r.fraction = std::clamp(fraction, 0.0, 1.0);
  r.seen_s = now_s;
  if (r.base_fraction) return;
  if (resumed_from >= 0.0) {
    r.base_fraction = r.fraction;
    r.base_s = now_s;
  } else if (r.fraction > 0.0) {
    r.base_fraction = 0.0;
    r.base_s = r.start_s;
  }
}

std::optional<double> EtaEstimator::speed(const Running& r) const {
  if (!r.base_fraction) return std::nullopt;
  const double done = r.fraction - *r.base_fraction;
  const double t = r.seen_s - *r.base_s;
  if (done < kMinProgress || t <= 0.0) return std::nullopt;
  return done / t;
}

void EtaEstimator::finished(std::size_t slot, double whole_wall_s) {
  running_.erase(slot);
  whole_case_s_.push_back(whole_wall_s);
}

std::optional<double> EtaEstimator::eta(std::size_t pending, double now_s) const {
  double per_case = 0.0;
  if (!whole_case_s_.empty()) {
    for (double w : whole_case_s_) per_case += w;
    per_case /= static_cast<double>(whole_case_s_.size());
  } else {
    int n = 0;
    for (const auto& [slot, r] : running_)
      if (const auto v = speed(r)) {
        per_case += 1.0 / *v;
        ++n;
      }
    if (n == 0) return std::nullopt;
    per_case /= n;
  }
  double remaining = static_cast<double>(pending) * per_case;
  for (const auto& [slot, r] : running_) {
    if (const auto v = speed(r))
      remaining += std::max(0.0, (1.0 - r.fraction) / *v - (now_s - r.seen_s));
    else
      remaining += per_case * (1.0 - r.fraction);
  }
  return remaining / jobs_;
}

}  // namespace crevasse

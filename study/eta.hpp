#pragma once
// How long the rest of a study will take, from the cases finished so far and the progress of
// the running ones. Times are passed in (seconds on any steady clock), so that the estimate
// can be checked without waiting.
#include <cstddef>
#include <map>
#include <optional>
#include <vector>

namespace crevasse {

class EtaEstimator {
 public:
  explicit EtaEstimator(int jobs) : jobs_(jobs < 1 ? 1 : jobs) {}
  void started(std::size_t slot, double now_s);
  void stopped(std::size_t slot) { running_.erase(slot); }
  // A case's whole duration counts for the cases still pending: this sitting's wall time
  // scaled up by the part it had done before (a case resumed from a checkpoint at 40 %
  // that took 60 s here would take 100 s from the start).
  void finished(std::size_t slot, double wall_s);
  std::size_t running() const { return running_.size(); }
  // Seconds until the pending and running cases are done, with `fraction(slot)` how far each
  // running case has got (0 to 1); none before anything can be projected.
  template <class Fraction>
  std::optional<double> eta(std::size_t pending, Fraction fraction, double now_s) {
    for (auto& [slot, r] : running_) observe(r, fraction(slot), now_s);
    return estimate(pending, now_s);
  }

 private:
  struct Running {
    double start_s = 0.0;
    // The first fraction seen and when: a resumed case starts where its checkpoint left it,
    // so its speed is measured from there, not from zero.
    std::optional<double> base_fraction, base_s;
    double fraction = 0.0, seen_s = 0.0;
  };
  void observe(Running& r, double fraction, double now_s);
  std::optional<double> speed(const Running& r) const;  // fraction per second
  std::optional<double> estimate(std::size_t pending, double now_s) const;

  int jobs_;
  std::map<std::size_t, Running> running_;
  std::vector<double> whole_case_s_;
};

}  // namespace crevasse

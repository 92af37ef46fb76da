#pragma once
// How long the rest of a study will take, from the cases finished so far and the progress of
// the running ones. Times are passed in (seconds on any steady clock), so that the estimate
// can be checked without waiting.
#include <cstddef>
#include <map>
#include <optional>
#include <utility>
#include <vector>

namespace crevasse {

class EtaEstimator {
 public:
  explicit EtaEstimator(int jobs) : jobs_(jobs < 1 ? 1 : jobs) {}
  void started(std::size_t slot, double now_s);
  void stopped(std::size_t slot) { running_.erase(slot); }
  // How far a running case has got (0 to 1) and, when it continued from a checkpoint, from
  // where (negative: it started fresh). A resumed case's speed counts from where it was first
  // seen after resuming, a fresh one's from its start.
  void observe(std::size_t slot, double fraction, double resumed_from, double now_s);
  // observe() for every running case: read(slot), called once per running case, gives its
  // {fraction, resumed_from}.
  template <class Read>
  void observe_running(Read read, double now_s) {
    for (auto& [slot, r] : running_) {
      const auto [fraction, resumed_from] = read(slot);
      observe(r, fraction, resumed_from, now_s);
    }
  }
  // A finished case's whole wall time, over all its sittings, stands for each pending case.
  void finished(std::size_t slot, double whole_wall_s);
  std::size_t running() const { return running_.size(); }
  // Seconds until the pending and running cases are done; none before anything can be projected.
  std::optional<double> eta(std::size_t pending, double now_s) const;

 private:
  struct Running {
    double start_s = 0.0;
    std::optional<double> base_fraction, base_s;  // where its speed is measured from
    double fraction = 0.0, seen_s = 0.0;
  };
  std::optional<double> speed(const Running& r) const;  // fraction per second
  static void observe(Running& r, double fraction, double resumed_from, double now_s);

  int jobs_;
  std::map<std::size_t, Running> running_;
  std::vector<double> whole_case_s_;
};

}  // namespace crevasse

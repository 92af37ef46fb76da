#pragma once
// The compute a study database holds, per H_i: the cases simulated, their particle-steps and engine
// wall time, and the cases served by another case's run. A served case was measured from particles
// a longer run kept at this case's stop: it costs seconds, and its run is counted where it ran. A
// case measured again from its own run's particles counts that run's engine time, not the seconds
// the re-measure took. Wall times add up per case: two cases run at once count twice.
#include <vector>

namespace crevasse {

class Store;

struct ComputeRow {
  double thickness_m = 0;
  long long run = 0;     // cases done or failed whose simulation this database paid for
  long long served = 0;  // cases done from another case's kept particles
  long long pending = 0;  // not finished (pending or running)
  double particle_steps = 0;
  double wall_s = 0;
  double median_rate = 0;  // particle-steps per second of engine wall time, median over cases run
};

// One row per H_i, in increasing H_i.
std::vector<ComputeRow> study_compute(Store& store);

// The sums over rows (thickness_m and median_rate are 0).
ComputeRow compute_total(const std::vector<ComputeRow>& rows);

}  // namespace crevasse

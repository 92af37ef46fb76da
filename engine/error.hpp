#pragma once
// The ways a case can fail. Each carries a message a user can act on; the CLI prints it on
// one line and maps InputError to exit code 2.
#include <stdexcept>
#include <string>

namespace crevasse {

// Bad input: the message names the field, the value and the allowed range.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The machine, not the input, stopped the command: a full disk, a file another process holds.
// The message names the path and the remedy; the CLI exits with 1, never with 2.
class ResourceError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The simulation went wrong (NaN, instability, time limit): the message says which step,
// which particle and which quantity.
class SimulationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The run reached run.wall_time_limit. It saved its checkpoint first when it had one to write
// (RunObserver::checkpoint_path), so the same run under a larger limit continues from it: the
// limit is not part of the scene a checkpoint is written for.
class TimeLimitError : public SimulationError {
 public:
  TimeLimitError(const std::string& what, double limit_s, double sim_time_s, double fraction_done, bool settled)
      : SimulationError(what), limit_s(limit_s), sim_time_s(sim_time_s), fraction_done(fraction_done), settled(settled) {}
  double limit_s;
  double sim_time_s;     // simulated time reached
  double fraction_done;  // of the stop rule, in [0, 1]; 0 while settling
  bool settled;          // false: the limit fired during the settling phase
};

}  // namespace crevasse

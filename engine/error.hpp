#pragma once
// The two ways a case can fail. Both carry a message a user can act on; the CLI prints it on
// one line and maps InputError to exit code 2.
#include <stdexcept>
#include <string>

namespace crevasse {

// Bad input: the message names the field, the value and the allowed range.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// The simulation went wrong (NaN, instability, time limit): the message says which step,
// which particle and which quantity.
class SimulationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace crevasse

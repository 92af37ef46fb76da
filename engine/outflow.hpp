#pragma once
// The outflow (effect `outflow`): ice within three cells of the downstream end has left the
// scene (docs/model.md) and is removed, its mass counted.
#include <optional>

#include "engine/gate_recorder.hpp"
#include "engine/particles.hpp"

namespace crevasse {

template <int Dim>
class Outflow {
 public:
  Outflow() = default;
  explicit Outflow(double x_line) : x_line_(x_line) {}

  // Removes the particles past the line. `front`: the largest x when the caller knows it (the
  // update's summary), so that the many steps that remove nothing cost nothing. Reads x;
  // compacts every particle array, archives the removed gate records (gate non-null). Returns
  // whether any particle was removed.
  bool remove(Particles<Dim>& P, GateRecorder<Dim>* gate, std::optional<double> front);

  double removed_mass() const { return removed_mass_; }
  void set_removed_mass(double m) { removed_mass_ = m; }  // checkpoints

 private:
  double x_line_ = 0.0;
  double removed_mass_ = 0.0;
};

extern template class Outflow<2>;
extern template class Outflow<3>;

}  // namespace crevasse

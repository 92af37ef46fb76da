#include "engine/inflow.hpp"

#include <cmath>

#include "engine/gate_recorder.hpp"

namespace crevasse {

template <int Dim>
bool Inflow<Dim>::feed(Particles<Dim>& P, double drive_shift) {
  // The ice within 2.5 cells of the back moves at exactly the drive speed (kHoldCells). Each
  // time the drive has moved by one particle spacing h, the band of ice h wide that entered
  // last, now at x ∈ [h, 2h), is copied h further back, into the place it has left: the same
  // F_E, stress, mass, velocity and height, so the ice enters settled and loaded, with no step
  // in its state. Serial, once every h/V_x of simulated time.
  const double h = h_;
  const double s = drive_shift;
  const auto due = static_cast<std::int64_t>(std::floor(s / h));  // columns entered by now
  bool fed = false;
  for (; columns_ < due; ++columns_) {
    // The band's place when the drive had moved k h, plus what it has moved since.
    const double since = s - static_cast<double>(columns_ + 1) * h;
    const double lo = h + since, hi = 2.0 * h + since;
    const std::size_t n = P.size();
    for (std::size_t q = 0; q < n; ++q) {
      if (!(P.x[q][0] >= lo && P.x[q][0] < hi)) continue;
      Vec<Dim> pos = P.x[q];
      pos[0] -= h;
      P.push_back(pos, P.mass[q], P.vol0[q], P.F_e[q], P.tau[q]);
      P.v.back() = P.v[q];
      P.C.back() = P.C[q];
      if (P.has_plastic_state()) P.eps_v_p.push_back(0.0);
      if (!P.gate_eps.empty()) GateRecorder<Dim>::add_entering(P, pos, s);
      mass_ += P.mass[q];
    }
    fed = true;
  }
  return fed;
}

template class Inflow<2>;
template class Inflow<3>;

}  // namespace crevasse

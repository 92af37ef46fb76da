#include "engine/gate_recorder.hpp"

namespace crevasse {

template <int Dim>
GateRecorder<Dim>::GateRecorder(Particles<Dim>& P, double gate_x) : gate_x_(gate_x) {
  const double gx = gate_x;
  P.x_ref.resize(P.size());
  P.gate_eps.assign(P.size(), kNotYet);
  double upstream_volume = 0.0;
  for (std::size_t p = 0; p < P.size(); ++p) {
    for (int a = 0; a < Dim; ++a) P.x_ref[p][a] = static_cast<float>(P.x[p][a]);
    if (P.x[p][0] < gx) upstream_volume += P.vol0[p];
    else P.gate_eps[p] = kNever;
  }
  // Every column of ice upstream of the gate is H_i high (on the plateau and, draped, on the
  // ramp), and the ice starts at x = 0.
  cross_section_ = upstream_volume > 0.0 ? upstream_volume / gx : 1.0;
}

template <int Dim>
void GateRecorder<Dim>::record(Particles<Dim>& P) {
  // Serial: one compare per particle, a few µs per step against milliseconds for the step.
  const double gx = gate_x_;
  for (std::size_t p = 0; p < P.size(); ++p) {
    if (P.gate_eps[p] != kNotYet || P.x[p][0] < gx) continue;
    P.gate_eps[p] = static_cast<float>(P.eps_v_p[p]);
    passed_volume_ += P.vol0[p];
  }
}

template <int Dim>
void GateRecorder<Dim>::archive_removed(const Particles<Dim>& P, const std::vector<char>& keep,
                                        std::size_t first) {
  for (std::size_t p = first; p < P.size(); ++p) {
    if (keep[p] || P.gate_eps[p] < 0.0f) continue;
    archive_.x.push_back(P.x_ref[p]);
    archive_.eps.push_back(P.gate_eps[p]);
  }
}

template <int Dim>
void GateRecorder<Dim>::add_entering(Particles<Dim>& P, const Vec<Dim>& pos, double drive_shift) {
  // The gate frame's "initial position": where this ice would have been at t = 0 had the slab
  // reached that far upstream, so the recorded field stays one continuous glacier.
  std::array<float, Dim> ref;
  for (int a = 0; a < Dim; ++a) ref[a] = static_cast<float>(pos[a]);
  ref[0] = static_cast<float>(pos[0] - drive_shift);
  P.x_ref.push_back(ref);
  P.gate_eps.push_back(kNotYet);
}

template <int Dim>
void GateRecorder<Dim>::add_to(ParticleSnapshot& s, const Particles<Dim>& P) const {
  constexpr int z = up_axis<Dim>;
  s.gate_x_m = gate_x_;
  s.gate_passed_length_m = passed_length();
  auto add = [&](const std::array<float, Dim>& xr, float eps) {
    s.gate_x_ref.push_back(xr[0]);
    s.gate_z_ref.push_back(xr[z]);
    if constexpr (Dim == 3) s.gate_y_ref.push_back(xr[1]);
    s.gate_eps_v_p.push_back(eps);
  };
  for (std::size_t i = 0; i < archive_.eps.size(); ++i) add(archive_.x[i], archive_.eps[i]);
  for (std::size_t p = 0; p < P.size(); ++p)
    if (P.gate_eps[p] >= 0.0f) add(P.x_ref[p], P.gate_eps[p]);
}

template class GateRecorder<2>;
template class GateRecorder<3>;

}  // namespace crevasse

#pragma once
// Particle state as structure of arrays. Hot fields of the step (x, v, C, F_E, τ, mass, V0)
// are always present; ε_v^p is allocated only when the scene names plasticity, so an elastic
// scene carries no plastic storage (docs/model.md).
#include <algorithm>
#include <array>
#include <cstdint>
#include <numeric>
#include <vector>

#include "engine/types.hpp"

namespace crevasse {

template <int Dim>
struct Particles {
  std::vector<Vec<Dim>> x;      // position [m]
  std::vector<Vec<Dim>> v;      // velocity [m/s]
  std::vector<Mat<Dim>> C;      // APIC affine velocity (velocity gradient estimate) [1/s]
  std::vector<Mat<Dim>> F_e;    // elastic deformation gradient [-]
  std::vector<Mat<Dim>> tau;    // Kirchhoff stress of F_e [Pa]
  std::vector<double> mass;     // [kg] (per unit depth in 2D)
  std::vector<double> vol0;     // reference volume [m^Dim]
  std::vector<double> eps_v_p;  // ε_v^p = ln J_P [-]; empty without plasticity
  // Drive: initial x of the particles of the pushed back layer, NaN for the others; empty
  // without the drive effect.
  std::vector<double> drive_x0;
  // Measurement gate (docs/measurement.md, "Gate frame"): each particle's initial position and
  // its ε_v^p when it first reached the gate, −1 before. Floats (12 B per particle in 2D): the
  // positions are only binned at dx and the damage only thresholded. Empty without a gate.
  std::vector<std::array<float, Dim>> x_ref;
  std::vector<float> gate_eps;

  std::size_t size() const { return x.size(); }
  bool has_plastic_state() const { return !eps_v_p.empty(); }

  void push_back(const Vec<Dim>& pos, double m, double v0, const Mat<Dim>& fe, const Mat<Dim>& t) {
    x.push_back(pos);
    v.push_back(Vec<Dim>::Zero());
    C.push_back(Mat<Dim>::Zero());
    F_e.push_back(fe);
    tau.push_back(t);
    mass.push_back(m);
    vol0.push_back(v0);
  }

  // Capacity of every hot array set to exactly the particle count (after seeding), so that
  // the in-place reorders below never carry spare capacity into the steps.
  void shrink_to_fit() {
    x.shrink_to_fit(); v.shrink_to_fit(); C.shrink_to_fit(); F_e.shrink_to_fit();
    tau.shrink_to_fit(); mass.shrink_to_fit(); vol0.shrink_to_fit();
  }

  // Reorders every array by `order`, a permutation of 0..size()−1 (order[i] = old index of the
  // new i-th particle). In place, cycle by cycle: the only extra memory is one bit per
  // particle, so a sorting step holds no second copy of any array (target ≤ 200 B/particle
  // at every step).
  void permute(const std::vector<std::uint32_t>& order) {
    std::vector<std::uint64_t> done((order.size() + 63) / 64);
    const auto apply = [&](auto& a) { permute_in_place(a, order, done); };
    apply(x); apply(v); apply(C); apply(F_e); apply(tau); apply(mass); apply(vol0);
    if (has_plastic_state()) apply(eps_v_p);
    if (!drive_x0.empty()) apply(drive_x0);
    if (!x_ref.empty()) { apply(x_ref); apply(gate_eps); }
  }

  // Keeps the particles with keep[i] true, in order (in place); returns the mass removed. Every
  // particle before `first` is kept.
  double compact(const std::vector<char>& keep, std::size_t first = 0) {
    double removed = 0.0;
    for (std::size_t i = first; i < size(); ++i)
      if (!keep[i]) removed += mass[i];
    const auto apply = [&](auto& a) { compact_in_place(a, keep, first); };
    apply(x); apply(v); apply(C); apply(F_e); apply(tau); apply(mass); apply(vol0);
    if (has_plastic_state()) apply(eps_v_p);
    if (!drive_x0.empty()) apply(drive_x0);
    if (!x_ref.empty()) { apply(x_ref); apply(gate_eps); }
    return removed;
  }

 private:
  // a_new[i] = a_old[order[i]], following each cycle of the permutation once.
  template <class T>
  static void permute_in_place(std::vector<T>& a, const std::vector<std::uint32_t>& order,
                               std::vector<std::uint64_t>& done) {
    std::fill(done.begin(), done.end(), 0);
    const auto seen = [&](std::size_t i) { return (done[i >> 6] >> (i & 63)) & 1u; };
    for (std::size_t start = 0; start < order.size(); ++start) {
      if (seen(start)) continue;
      T first = a[start];
      std::size_t i = start;
      for (;;) {
        done[i >> 6] |= std::uint64_t{1} << (i & 63);
        const std::size_t j = order[i];
        if (j == start) {
          a[i] = first;
          break;
        }
        a[i] = a[j];
        i = j;
      }
    }
  }
  template <class T>
  static void compact_in_place(std::vector<T>& a, const std::vector<char>& keep, std::size_t first) {
    std::size_t k = first;
    for (std::size_t i = first; i < a.size(); ++i)
      if (keep[i]) a[k++] = a[i];
    a.resize(k);
  }
};

}  // namespace crevasse

#pragma once
// Particle state as structure of arrays. Hot fields of the step (x, v, C, F_E, τ, mass, V0)
// are always present; ε_v^p is allocated only when the scene names plasticity, so an elastic
// scene carries no plastic storage (SPEC §4).
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

  // Reorders every array by `order` (order[i] = old index of the new i-th particle).
  void permute(const std::vector<std::uint32_t>& order) {
    apply(x, order); apply(v, order); apply(C, order); apply(F_e, order); apply(tau, order);
    apply(mass, order); apply(vol0, order);
    if (has_plastic_state()) apply(eps_v_p, order);
    if (!drive_x0.empty()) apply(drive_x0, order);
    if (!x_ref.empty()) { apply(x_ref, order); apply(gate_eps, order); }
  }

  // Keeps the particles with keep[i] true, in order; returns the mass removed.
  double compact(const std::vector<char>& keep) {
    std::vector<std::uint32_t> order;
    order.reserve(size());
    double removed = 0.0;
    for (std::size_t i = 0; i < size(); ++i) {
      if (keep[i]) order.push_back(static_cast<std::uint32_t>(i));
      else removed += mass[i];
    }
    permute(order);
    return removed;
  }

 private:
  template <class T>
  static void apply(std::vector<T>& a, const std::vector<std::uint32_t>& order) {
    std::vector<T> out(order.size());
    for (std::size_t i = 0; i < order.size(); ++i) out[i] = a[order[i]];
    a.swap(out);
  }
};

}  // namespace crevasse

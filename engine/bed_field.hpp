#pragma once
// The bed as the step reads it: its signed distance φ and normal tabulated on the lattice nodes
// of the domain (indexed (x, z)), so that contact on the grid and the particles' projection out
// of the rock cost a table look-up instead of a walk along the bed's polyline.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

#include "engine/bed.hpp"
#include "engine/fast_math.hpp"
#include "engine/types.hpp"

namespace crevasse {

template <int Dim>
class BedField {
 public:
  BedField() = default;
  // The table covers the domain [lo, hi] with three cells of margin, up to four cells above
  // the bed's highest point.
  BedField(const Bed& bed, const Vec<Dim>& lo, const Vec<Dim>& hi, double dx);

  // φ at x by bilinear interpolation of the table (clamped to it), and the interpolated unit
  // normal when `normal` is given.
  double phi(const Vec<Dim>& x, Vec<Dim>* normal) const { return phi(cell(x), normal); }

  // Grid contact: the outward normal at lattice node `node` when the node is in the table and
  // on or inside the bed (φ ≤ tolerance); false otherwise.
  bool contact_normal(const IVec<Dim>& node, double tolerance, Vec<Dim>& n) const {
    const int i = node[0] - i0_, k = node[up_axis<Dim>] - k0_;
    if (i < 0 || k < 0 || i >= ni_ || k >= nk_) return false;
    const std::size_t t = static_cast<std::size_t>(i) * nk_ + k;
    if (phi_[t] > tolerance) return false;
    n = Vec<Dim>::Zero();
    n[0] = normal_[t][0];
    n[up_axis<Dim>] = normal_[t][1];
    return true;
  }

  // Moves a point inside the rock back onto the bed along the normal (x −= φ n). Most ice is
  // far above the bed and returns at the first test.
  [[gnu::always_inline]] inline void project_out(Vec<Dim>& x) const {
    // First a test without divisions: above clear_z_ of its column (rounded either way) a
    // point's exact cell is clear (below).
    const int column = std::clamp(floor_to_int(x[0] * inv_dx_) - i0_, 0, ni_ - 2);
    if (x[up_axis<Dim>] >= clear_z_[static_cast<std::size_t>(column)]) return;
    const Cell c = cell(x);
    // A cell whose four corners have φ ≥ 0 interpolates φ ≥ 0 (non-negative weights): nothing
    // to do, and nothing to interpolate, for most of the ice.
    if (c.k >= clear_k_[static_cast<std::size_t>(c.i)]) return;
    // The normal (two more interpolations and a hypot) only for the few points inside.
    const double p = phi(c, nullptr);
    if (p >= 0.0) return;
    Vec<Dim> n;
    phi(c, &n);
    x -= p * n;
  }

 private:
  struct Cell {
    int i, k;       // the table's cell
    double fx, fz;  // place in it, in [0, 1]
  };
  Cell cell(const Vec<Dim>& x) const {
    // The table cell of x and x's place in it, clamped to the table.
    const double gx = x[0] / dx_ - i0_, gz = x[up_axis<Dim>] / dx_ - k0_;
    Cell c;
    c.i = std::clamp(floor_to_int(gx), 0, ni_ - 2);
    c.k = std::clamp(floor_to_int(gz), 0, nk_ - 2);
    c.fx = std::clamp(gx - c.i, 0.0, 1.0);
    c.fz = std::clamp(gz - c.k, 0.0, 1.0);
    return c;
  }
  double phi(const Cell& cell, Vec<Dim>* normal) const;

  double dx_ = 1.0, inv_dx_ = 1.0;
  int i0_ = 0, k0_ = 0, ni_ = 0, nk_ = 0;
  std::vector<double> phi_;
  std::vector<std::array<double, 2>> normal_;
  std::vector<int> clear_k_;     // per cell column: from this cell row up, φ ≥ 0 at every corner
  std::vector<double> clear_z_;  // per cell column: above this z, the point's cell is clear
};

template <int Dim>
double BedField<Dim>::phi(const Cell& cell, Vec<Dim>* normal) const {
  // Bilinear interpolation of the node table in (x, z).
  const int i = cell.i, k = cell.k;
  const double fx = cell.fx, fz = cell.fz;
  const double w[4] = {(1 - fx) * (1 - fz), (1 - fx) * fz, fx * (1 - fz), fx * fz};
  const std::size_t f[4] = {static_cast<std::size_t>(i) * nk_ + k, static_cast<std::size_t>(i) * nk_ + k + 1,
                            static_cast<std::size_t>(i + 1) * nk_ + k,
                            static_cast<std::size_t>(i + 1) * nk_ + k + 1};
  double phi = 0.0;
  for (int c = 0; c < 4; ++c) phi += w[c] * phi_[f[c]];
  if (normal) {
    double nx = 0.0, nz = 0.0;
    for (int c = 0; c < 4; ++c) {
      nx += w[c] * normal_[f[c]][0];
      nz += w[c] * normal_[f[c]][1];
    }
    normal->setZero();
    const double len = std::hypot(nx, nz);
    (*normal)[0] = len > 0 ? nx / len : 0.0;
    (*normal)[up_axis<Dim>] = len > 0 ? nz / len : 1.0;
  }
  return phi;
}

extern template class BedField<2>;
extern template class BedField<3>;

}  // namespace crevasse

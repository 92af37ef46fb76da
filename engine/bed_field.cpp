#include "engine/bed_field.hpp"

#include <tbb/parallel_for.h>

#include <limits>

namespace crevasse {

template <int Dim>
BedField<Dim>::BedField(const Bed& bed, const Vec<Dim>& lo, const Vec<Dim>& hi, double dx)
    : dx_(dx), inv_dx_(1.0 / dx) {
  const int x_axis = 0, z_axis = up_axis<Dim>;
  i0_ = static_cast<int>(std::floor(lo[x_axis] / dx)) - 3;
  k0_ = static_cast<int>(std::floor(lo[z_axis] / dx)) - 3;
  ni_ = static_cast<int>(std::ceil(hi[x_axis] / dx)) + 4 - i0_;
  // Rows up to 4 cells above the highest point of the bed, not up to the top of the domain:
  // above that row the signed distance is at least 4·dx, so no node there touches the bed
  // (contact skips nodes outside the table) and the clamped interpolation for a point above it
  // stays positive (no projection), exactly as with the full table. For a glacier the full
  // table was the largest per-domain array (≈ 60 B per particle at H_i = 300 m).
  double bed_top = -std::numeric_limits<double>::infinity();
  for (const auto& v : bed.vertices()) bed_top = std::max(bed_top, v[1]);
  const int full_nk = static_cast<int>(std::ceil(hi[z_axis] / dx)) + 4 - k0_;
  const int bed_nk = static_cast<int>(std::ceil(bed_top / dx)) + 5 - k0_;
  nk_ = std::max(2, std::min(full_nk, bed_nk));
  phi_.resize(static_cast<std::size_t>(ni_) * nk_);
  normal_.resize(phi_.size());
  tbb::parallel_for(0, ni_, [&](int i) {
    for (int k = 0; k < nk_; ++k) {
      const double x = (i0_ + i) * dx, z = (k0_ + k) * dx;
      const std::size_t f = static_cast<std::size_t>(i) * nk_ + k;
      phi_[f] = bed.signed_distance(x, z);
      normal_[f] = bed.normal(x, z);
    }
  });
  // Per column of cells, the lowest cell row from which every cell up to the table's top has
  // four corners with φ ≥ 0 (nk_ − 1 when the top cell has not).
  clear_k_.assign(static_cast<std::size_t>(ni_ - 1), nk_ - 1);
  const auto at = [&](int i, int k) { return phi_[static_cast<std::size_t>(i) * nk_ + k]; };
  for (int i = 0; i + 1 < ni_; ++i) {
    for (int k = nk_ - 2; k >= 0; --k) {
      if (!(at(i, k) >= 0.0 && at(i, k + 1) >= 0.0 && at(i + 1, k) >= 0.0 && at(i + 1, k + 1) >= 0.0))
        break;
      clear_k_[static_cast<std::size_t>(i)] = k;
    }
  }
  // The same as a height, safe for the column found from x·(1/dx) instead of x/dx (the two
  // may round to neighbouring columns): the highest clear row of this and the two neighbouring
  // columns, one cell higher still; never, when one of them has no clear cell at all (the
  // clamp to the table's top row would then land in a cell that is not clear).
  clear_z_.assign(clear_k_.size(), std::numeric_limits<double>::infinity());
  for (int i = 0; i + 1 < ni_; ++i) {
    int k = 0;
    for (int j = std::max(0, i - 1); j <= std::min(ni_ - 2, i + 1); ++j)
      k = std::max(k, clear_k_[static_cast<std::size_t>(j)]);
    if (k <= nk_ - 2) clear_z_[static_cast<std::size_t>(i)] = (k0_ + k + 2) * dx;
  }
}

template class BedField<2>;
template class BedField<3>;

}  // namespace crevasse

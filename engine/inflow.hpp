#pragma once
// The inflow (drive.boundary "inflow"): the glacier enters through the back of the domain. The
// grid holds the nodes of the last kHoldCells cells at the drive speed (a stage of the step),
// and this feeds the ice that entered, one particle spacing at a time.
#include <cstdint>

#include "engine/particles.hpp"

namespace crevasse {

template <int Dim>
class Inflow {
 public:
  // The nodes up to this many cells from the back are held: a quadratic stencil reaches 1.5
  // cells, so the ice within 2.5 cells of the back gathers only held nodes, which covers the
  // band the inflow copies (x < 2h ≤ 2 dx) at any particles per cell.
  static constexpr double kHoldCells = 3.0;

  Inflow() = default;
  explicit Inflow(double spacing) : h_(spacing) {}

  // Copies the band of ice that entered last one particle spacing upstream, once for every
  // spacing the drive has moved (`drive_shift`, at the current time) since the last. Reads x;
  // appends particles (and their gate records when the particles carry them). Returns whether
  // any were added.
  bool feed(Particles<Dim>& P, double drive_shift);

  double mass() const { return mass_; }              // that entered through the inflow
  std::int64_t columns() const { return columns_; }  // bands fed so far
  void restore(double mass, std::int64_t columns) {  // checkpoints
    mass_ = mass;
    columns_ = columns;
  }

 private:
  double h_ = 1.0;  // particle spacing
  double mass_ = 0.0;
  std::int64_t columns_ = 0;
};

extern template class Inflow<2>;
extern template class Inflow<3>;

}  // namespace crevasse

#pragma once
// The boundary conditions the step applies to the grid's velocities after the grid update:
// drives, contact with the bed, walls. Each reads the nodes' mass and velocity and writes the
// velocity only.
#include <vector>

#include "engine/bed_field.hpp"
#include "engine/grid.hpp"
#include "engine/particles.hpp"
#include "engine/scene.hpp"

namespace crevasse {

// Nodes with mass and x in [x_lo, x_hi] move at `speed` along x (and, when hold_vertical, not
// at all vertically).
template <int Dim>
void hold_nodes_at_speed(Grid<Dim>& grid, double x_lo, double x_hi, double speed, bool hold_vertical);

// The piston acts on the grid too: each node's x-velocity is pulled towards `speed` in
// proportion to the share of its mass that comes from the driven layer (particles with a
// drive_x0). `layer_mass` is per-node scratch.
template <int Dim>
void pull_nodes_with_piston(Grid<Dim>& grid, const Particles<Dim>& P, double speed, std::vector<double>& layer_mass);

// Coulomb contact with the static bed on nodes inside or on it, with coefficient mu.
template <int Dim>
void apply_bed_friction(Grid<Dim>& grid, const BedField<Dim>& bed, double mu);

// Free slip: on nodes at or beyond a wall along one of `axes`, the velocity into it is removed.
template <int Dim>
void apply_free_slip_walls(Grid<Dim>& grid, const std::vector<int>& axes, const Vec<Dim>& lo, const Vec<Dim>& hi);

// Nodes inside a box (moving with its velocity since t = 0) take the box's velocity.
template <int Dim>
void apply_velocity_boxes(Grid<Dim>& grid, const std::vector<VelocityBox>& boxes, double time);

}  // namespace crevasse

#pragma once
// Whether the ice rests on its bed where the bed drops (docs/measurement.md, "Contact with the
// ramp"). A glacier flowing over the step should stay in contact with the ramp; a rigid slab
// pushed over it instead rides on horizontally and leaves a gap beneath.
#include <cstddef>

#include "engine/snapshot.hpp"

namespace crevasse::analysis {

struct BedContact {
  // Over the columns one dx wide between x_min and x_max that hold ice: the largest gap between
  // the bed and the bottom of the ice, z_min − z_b − half a particle spacing (the lowest
  // particle centre of ice resting on its bed is that far up), never below 0 [m].
  double max_gap_m = 0.0;
  double max_gap_x_m = 0.0;      // centre of the column with the largest gap [m]
  std::size_t columns = 0;       // columns between x_min and x_max
  std::size_t empty_columns = 0; // of those, columns with no ice at all (not in max_gap_m)
};

// z_b from the snapshot's bed profile. Throws std::invalid_argument when it has none.
BedContact bed_contact(const ParticleSnapshot& s, double x_min, double x_max);
// Over the ramp, from the top of the step to its foot.
BedContact ramp_contact(const ParticleSnapshot& s);

}  // namespace crevasse::analysis

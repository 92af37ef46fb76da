#pragma once
// ParaView output: one VTK XML UnstructuredGrid (.vtu) per snapshot, particles as vertex cells,
// binary "raw" appended data (compact and fast, read by ParaView/VTK without extra libraries),
// and a .pvd collection that ParaView opens as a time series.
#include <string>
#include <utility>
#include <vector>

#include "engine/snapshot.hpp"

namespace crevasse {

// Writes position (3 components, y = 0 in 2D), velocity, eps_v_p, damage, pressure, von_mises,
// sigma_zz, volume. Throws std::runtime_error if the file cannot be written.
void write_vtu(const std::string& path, const ParticleSnapshot& s);

// (time [s], file name relative to the .pvd) pairs.
void write_pvd(const std::string& path, const std::vector<std::pair<double, std::string>>& files);

}  // namespace crevasse

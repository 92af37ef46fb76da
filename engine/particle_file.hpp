#pragma once
// The final particles of a run, kept so that a case can be measured again with other settings
// (`crevasse measure`) or opened in ParaView (`crevasse measure --vtu`) without simulating it
// again. One file holds a whole ParticleSnapshot: a JSON header with its scalars, the bed
// profile and any metadata the caller adds, then every per-particle and gate array, compressed
// with zlib. Positions and ε_v^p stay in double precision, so a measurement of the reloaded
// snapshot equals the measurement of the original; velocities and stresses, drawn but not
// measured, are kept in single precision. docs/measurement.md, "Measuring again".
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include "engine/snapshot.hpp"

namespace crevasse {

// Written through an AtomicFile: whole or absent. std::runtime_error naming the file when it
// cannot be written. `metadata` is stored as given (e.g. density, gravity, the measurement
// settings used) and returned by read_particle_file.
void write_particle_file(const std::filesystem::path& path, const ParticleSnapshot& snapshot,
                         const nlohmann::json& metadata = nlohmann::json::object());

struct ParticleFile {
  ParticleSnapshot snapshot;
  nlohmann::json metadata;
};

// InputError naming the file when it is missing, not a particle file, of a newer format,
// truncated or damaged (the arrays carry a CRC-32 and their lengths are checked).
ParticleFile read_particle_file(const std::filesystem::path& path);

// The metadata alone, read from the header without touching the particles: what a caller that
// only sorts files needs. InputError as above for a file that is not a particle file of this
// format; damage in the arrays is found only by read_particle_file.
nlohmann::json read_particle_file_metadata(const std::filesystem::path& path);

}  // namespace crevasse

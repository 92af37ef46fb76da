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
  bool header_checked = true;  // false for a format 1 file: its checksum covers only its arrays
};

// InputError naming the file when it is missing, not a particle file, of a newer format,
// truncated or damaged: one CRC-32 covers the whole file, header included, and the sizes and
// array lengths are checked. A format 1 file (an older crevasse) is read with only its arrays
// checked; header_checked says so, and unchecked_header_warning is the line to show.
ParticleFile read_particle_file(const std::filesystem::path& path);

// The metadata alone, without decompressing the particles: what a caller that only sorts files
// needs. The whole file's checksum is checked (format 2), so the refusals are those of
// read_particle_file but for damage inside a format 1 file's arrays.
struct ParticleFileHeader {
  nlohmann::json metadata;
  bool header_checked = true;
};
ParticleFileHeader read_particle_file_header(const std::filesystem::path& path);

std::string unchecked_header_warning(const std::filesystem::path& path);

}  // namespace crevasse

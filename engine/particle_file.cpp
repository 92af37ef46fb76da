#include "engine/particle_file.hpp"

#include <zlib.h>

#include <bit>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <string>
#include <stdexcept>

#include "engine/atomic_file.hpp"
#include "engine/error.hpp"

namespace crevasse {
namespace {

static_assert(std::endian::native == std::endian::little, "particle files are little-endian");

constexpr char kMagic[8] = {'C', 'R', 'V', 'P', 'T', 'C', 'L', '\n'};
constexpr char kEnd[8] = {'C', 'R', 'V', 'P', 'E', 'N', 'D', '\n'};
// Format 2: one CRC-32 over every byte before it, header included. Format 1 checked only its
// arrays; it is still read, and the reader says that its header is unchecked.
constexpr std::uint32_t kFormat = 2;
constexpr std::uint32_t kFormatArraysOnly = 1;

// Every per-particle and gate array, with the precision it is kept in: what the measurement
// reads in double, what is only drawn in single.
struct ArraySlot {
  const char* name;
  std::vector<double> ParticleSnapshot::*member;
  bool single;
};
constexpr ArraySlot kArrays[] = {
    {"x", &ParticleSnapshot::x, false},
    {"y", &ParticleSnapshot::y, false},
    {"z", &ParticleSnapshot::z, false},
    {"eps_v_p", &ParticleSnapshot::eps_v_p, false},
    {"vx", &ParticleSnapshot::vx, true},
    {"vy", &ParticleSnapshot::vy, true},
    {"vz", &ParticleSnapshot::vz, true},
    {"pressure_pa", &ParticleSnapshot::pressure_pa, true},
    {"von_mises_pa", &ParticleSnapshot::von_mises_pa, true},
    {"sigma_zz_pa", &ParticleSnapshot::sigma_zz_pa, true},
    {"volume_m3", &ParticleSnapshot::volume_m3, true},
    {"gate_x_ref", &ParticleSnapshot::gate_x_ref, false},
    {"gate_y_ref", &ParticleSnapshot::gate_y_ref, false},
    {"gate_z_ref", &ParticleSnapshot::gate_z_ref, false},
    {"gate_eps_v_p", &ParticleSnapshot::gate_eps_v_p, false},
};

std::uint32_t file_crc(const char* data, std::size_t n) {
  return static_cast<std::uint32_t>(crc32_z(0L, reinterpret_cast<const Bytef*>(data), n));
}

template <class T>
void put(std::string& out, const T& v) {
  out.append(reinterpret_cast<const char*>(&v), sizeof v);
}

nlohmann::json scalars(const ParticleSnapshot& s) {
  return {{"dim", s.dim},
          {"time_s", s.time_s},
          {"dx_m", s.dx_m},
          {"softening_zeta", s.softening_zeta},
          {"tensile_strength_pa", s.tensile_strength_pa},
          {"ice_thickness_m", s.ice_thickness_m},
          {"step_top_x_m", s.step_top_x_m},
          {"step_foot_x_m", s.step_foot_x_m},
          {"particle_spacing_m", s.particle_spacing_m},
          {"bed_profile", s.bed_profile},
          {"gate_x_m", s.gate_x_m},
          {"gate_passed_length_m", s.gate_passed_length_m},
          {"ice_front_x_m", s.ice_front_x_m},
          {"upstream_ice_front_x_m", s.upstream_ice_front_x_m}};
}

// JSON text keeps a double exactly only through its shortest round-trip form, which
// nlohmann::json writes; the scalars are read back bit for bit.
void read_scalars(const nlohmann::json& j, ParticleSnapshot& s) {
  s.dim = j.at("dim").get<int>();
  s.time_s = j.at("time_s").get<double>();
  s.dx_m = j.at("dx_m").get<double>();
  s.softening_zeta = j.at("softening_zeta").get<double>();
  s.tensile_strength_pa = j.at("tensile_strength_pa").get<double>();
  s.ice_thickness_m = j.at("ice_thickness_m").get<double>();
  s.step_top_x_m = j.at("step_top_x_m").get<double>();
  s.step_foot_x_m = j.at("step_foot_x_m").get<double>();
  s.particle_spacing_m = j.at("particle_spacing_m").get<double>();
  s.bed_profile = j.at("bed_profile").get<std::vector<std::array<double, 2>>>();
  s.gate_x_m = j.at("gate_x_m").get<double>();
  s.gate_passed_length_m = j.at("gate_passed_length_m").get<double>();
  s.ice_front_x_m = j.at("ice_front_x_m").get<double>();
  s.upstream_ice_front_x_m = j.at("upstream_ice_front_x_m").get<double>();
}

}  // namespace

void write_particle_file(const std::filesystem::path& path, const ParticleSnapshot& s,
                         const nlohmann::json& metadata) {
  nlohmann::json header = scalars(s);
  header["metadata"] = metadata;
  header["arrays"] = nlohmann::json::array();
  std::string raw;
  for (const ArraySlot& a : kArrays) {
    const std::vector<double>& v = s.*(a.member);
    header["arrays"].push_back({{"name", a.name}, {"count", v.size()}, {"type", a.single ? "f32" : "f64"}});
    for (double d : v) {
      if (a.single)
        put(raw, static_cast<float>(d));
      else
        put(raw, d);
    }
  }
  uLongf packed_size = compressBound(raw.size());
  std::string packed(packed_size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(packed.data()), &packed_size,
                reinterpret_cast<const Bytef*>(raw.data()), raw.size(), 6) != Z_OK)
    throw std::runtime_error("cannot compress the particles for " + path.string());
  packed.resize(packed_size);

  const std::string header_text = header.dump();
  std::string out(kMagic, sizeof kMagic);
  put(out, kFormat);
  put(out, static_cast<std::uint64_t>(header_text.size()));
  out += header_text;
  put(out, static_cast<std::uint64_t>(raw.size()));
  put(out, static_cast<std::uint64_t>(packed.size()));
  out += packed;
  put(out, file_crc(out.data(), out.size()));
  out.append(kEnd, sizeof kEnd);
  write_file_atomically(path, out);
}

namespace {

// A whole particle file in memory, its prelude parsed and, for format 2, its checksum checked:
// what both readers share, and so their refusals.
struct RawFile {
  std::uint32_t format = 0;
  std::string header_text;
  std::string bytes;          // the whole file
  std::size_t packed_at = 0;  // where the compressed arrays start in `bytes`
  std::uint64_t raw_size = 0, packed_size = 0;
  std::uint32_t arrays_crc = 0;  // format 1 only: the CRC-32 of the uncompressed arrays
};

RawFile read_raw(const std::filesystem::path& path, const std::string& where) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(where + ": no such particle file (a regular file)");
  std::ifstream f(path, std::ios::binary);
  if (!f) throw InputError(where + ": cannot read the particle file");
  char magic[sizeof kMagic];
  if (!f.read(magic, sizeof magic) || std::memcmp(magic, kMagic, sizeof kMagic) != 0)
    throw InputError(where + ": not a crevasse particle file");
  f.seekg(0);
  RawFile r;
  r.bytes.assign(std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>());
  if (!f.eof() && f.fail()) throw InputError(where + ": cannot read the particle file");
  const std::string& b = r.bytes;
  std::size_t at = sizeof kMagic;
  auto need = [&](std::uint64_t n) {
    if (n > b.size() - at) throw InputError(where + ": truncated particle file");
  };
  auto get = [&]<class T>(T& v) {
    need(sizeof v);
    std::memcpy(&v, b.data() + at, sizeof v);
    at += sizeof v;
  };
  get(r.format);
  if (r.format != kFormat && r.format != kFormatArraysOnly)
    throw InputError(where + ": particle file format " + std::to_string(r.format) + " (this crevasse reads formats " +
                     std::to_string(kFormatArraysOnly) + " and " + std::to_string(kFormat) + ")");
  std::uint64_t header_size = 0;
  get(header_size);
  need(header_size);
  r.header_text = b.substr(at, header_size);
  at += header_size;
  get(r.raw_size);
  get(r.packed_size);
  if (r.format == kFormatArraysOnly) get(r.arrays_crc);
  need(r.packed_size);
  r.packed_at = at;
  at += r.packed_size;
  if (r.format == kFormat) {
    const std::size_t summed = at;
    std::uint32_t crc = 0;
    get(crc);
    need(sizeof kEnd);
    if (std::memcmp(b.data() + at, kEnd, sizeof kEnd) == 0 && at + sizeof kEnd == b.size() &&
        file_crc(b.data(), summed) != crc)
      throw InputError(where + ": damaged particle file (it fails its checksum)");
  }
  need(sizeof kEnd);
  if (std::memcmp(b.data() + at, kEnd, sizeof kEnd) != 0 || at + sizeof kEnd != b.size())
    throw InputError(where + ": damaged particle file (no end marker where its sizes put it)");
  return r;
}

}  // namespace

ParticleFile read_particle_file(const std::filesystem::path& path) {
  const std::string where = path.string();
  const RawFile f = read_raw(path, where);
  ParticleFile out;
  out.header_checked = f.format == kFormat;
  std::string raw(f.raw_size, '\0');
  uLongf unpacked = f.raw_size;
  if (uncompress(reinterpret_cast<Bytef*>(raw.data()), &unpacked,
                 reinterpret_cast<const Bytef*>(f.bytes.data() + f.packed_at), f.packed_size) != Z_OK ||
      unpacked != f.raw_size ||
      (f.format == kFormatArraysOnly && crc32(0L, reinterpret_cast<const Bytef*>(raw.data()), raw.size()) != f.arrays_crc))
    throw InputError(where + ": damaged particle file (its arrays fail their checksum)");
  try {
    const nlohmann::json header = nlohmann::json::parse(f.header_text);
    read_scalars(header, out.snapshot);
    out.metadata = header.at("metadata");
    std::size_t pos = 0;
    for (const ArraySlot& a : kArrays) {
      const nlohmann::json* entry = nullptr;
      for (const auto& e : header.at("arrays"))
        if (e.at("name").get<std::string>() == a.name) entry = &e;
      if (!entry) throw std::runtime_error(std::string("array ") + a.name + " missing");
      const std::size_t count = entry->at("count").get<std::size_t>();
      const bool single = entry->at("type").get<std::string>() == "f32";
      const std::size_t width = single ? sizeof(float) : sizeof(double);
      if (count > (raw.size() - pos) / width) throw std::runtime_error(std::string("array ") + a.name + " overruns");
      std::vector<double>& v = out.snapshot.*(a.member);
      v.resize(count);
      for (std::size_t i = 0; i < count; ++i, pos += width) {
        if (single) {
          float x;
          std::memcpy(&x, raw.data() + pos, sizeof x);
          v[i] = x;
        } else {
          std::memcpy(&v[i], raw.data() + pos, sizeof(double));
        }
      }
    }
    if (pos != raw.size()) throw std::runtime_error("arrays do not fill the payload");
  } catch (const std::exception& e) {
    throw InputError(where + ": damaged particle file (" + e.what() + ")");
  }
  const ParticleSnapshot& s = out.snapshot;
  const std::size_t n = s.x.size();
  for (const auto* v : {&s.z, &s.eps_v_p})
    if (v->size() != n) throw InputError(where + ": damaged particle file (arrays of unequal length)");
  return out;
}

ParticleFileHeader read_particle_file_header(const std::filesystem::path& path) {
  const std::string where = path.string();
  const RawFile f = read_raw(path, where);
  try {
    return {nlohmann::json::parse(f.header_text).at("metadata"), f.format == kFormat};
  } catch (const std::exception& e) {
    throw InputError(where + ": damaged particle file (" + e.what() + ")");
  }
}

std::string unchecked_header_warning(const std::filesystem::path& path) {
  return path.string() + ": particle file format " + std::to_string(kFormatArraysOnly) +
         ": its checksum covers its arrays but not its header (time, geometry, measurement settings), "
         "so damage there would go unnoticed; write it again with this crevasse to have it checked";
}

}  // namespace crevasse

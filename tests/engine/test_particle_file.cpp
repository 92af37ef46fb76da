// Particle files (engine/particle_file.hpp): what is written is read back, positions and
// ε_v^p bit for bit, velocities and stresses to single precision; anything else than a whole
// file of this format is refused with an InputError naming the file, never read as data.
#include <gtest/gtest.h>
#include <unistd.h>
#include <zlib.h>

#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "engine/error.hpp"
#include "engine/particle_file.hpp"

namespace crevasse {
namespace {

ParticleSnapshot make_snapshot(int dim, std::size_t n) {
  ParticleSnapshot s;
  s.dim = dim;
  s.time_s = 123.456789012345;
  s.dx_m = 10.0;
  s.softening_zeta = 1234.5;
  s.tensile_strength_pa = 3.6e5;
  s.ice_thickness_m = 400.0;
  s.step_top_x_m = 800.0;
  s.step_foot_x_m = 1200.0;
  s.particle_spacing_m = 5.0;
  s.bed_profile = {{0.0, 200.0}, {800.0, 200.0}, {1200.0, 0.0}, {4000.0, 0.0}};
  s.gate_x_m = 1000.0;
  s.gate_passed_length_m = 1600.25;
  s.ice_front_x_m = 3590.125;
  s.upstream_ice_front_x_m = 2170.0625;
  for (std::size_t i = 0; i < n; ++i) {
    // Values with every bit of the mantissa in use, so that a float on the way would show.
    const double d = static_cast<double>(i) + 1.0 / 3.0;
    s.x.push_back(1000.0 * d / 7.0);
    s.z.push_back(0.1 + d * 0.7071067811865476);
    if (dim == 3) {
      s.y.push_back(d / 11.0);
      s.vy.push_back(0.5 * d);
    }
    s.eps_v_p.push_back(i % 3 == 0 ? 0.0 : 1e-3 * d / 9.0);
    s.vx.push_back(4.0 + d / 13.0);
    s.vz.push_back(-d / 17.0);
    s.pressure_pa.push_back(1e5 * d / 3.0);
    s.von_mises_pa.push_back(2e5 * d / 7.0);
    s.sigma_zz_pa.push_back(-3e5 * d / 11.0);
    s.volume_m3.push_back(25.0 + d / 19.0);
  }
  for (std::size_t i = 0; i < n / 2; ++i) {
    s.gate_x_ref.push_back(i / 3.0);
    s.gate_z_ref.push_back(200.0 + i / 7.0);
    if (dim == 3) s.gate_y_ref.push_back(i / 9.0);
    s.gate_eps_v_p.push_back(i % 2 ? 0.02 / 3.0 : 0.0);
  }
  return s;
}

std::filesystem::path temp_file(const std::string& name) {
  return std::filesystem::temp_directory_path() /
         ("crevasse_particle_file_" + name + "_" + std::to_string(::getpid()) + ".bin");
}

void expect_same(const std::vector<double>& a, const std::vector<double>& b, bool single, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (single)
      EXPECT_EQ(static_cast<double>(static_cast<float>(a[i])), b[i]) << what << " " << i;
    else
      EXPECT_EQ(a[i], b[i]) << what << " " << i;
  }
}

void round_trip(int dim) {
  const ParticleSnapshot s = make_snapshot(dim, 1001);
  const auto path = temp_file("rt" + std::to_string(dim));
  const nlohmann::json meta = {{"case_id", "abc"}, {"density_kg_m3", 917.0}, {"measurement", {{"frame", "passed"}}}};
  write_particle_file(path, s, meta);
  const ParticleFile f = read_particle_file(path);
  const ParticleFileHeader header = read_particle_file_header(path);
  EXPECT_EQ(header.metadata, meta);
  EXPECT_TRUE(header.header_checked);
  EXPECT_TRUE(f.header_checked);
  std::filesystem::remove(path);
  const ParticleSnapshot& r = f.snapshot;
  EXPECT_EQ(f.metadata, meta);
  EXPECT_EQ(r.dim, dim);
  for (auto m : {&ParticleSnapshot::time_s, &ParticleSnapshot::dx_m, &ParticleSnapshot::softening_zeta,
                 &ParticleSnapshot::tensile_strength_pa, &ParticleSnapshot::ice_thickness_m,
                 &ParticleSnapshot::step_top_x_m, &ParticleSnapshot::step_foot_x_m,
                 &ParticleSnapshot::particle_spacing_m, &ParticleSnapshot::gate_x_m,
                 &ParticleSnapshot::gate_passed_length_m, &ParticleSnapshot::ice_front_x_m,
                 &ParticleSnapshot::upstream_ice_front_x_m})
    EXPECT_EQ(s.*m, r.*m);
  EXPECT_EQ(s.bed_profile, r.bed_profile);
  expect_same(s.x, r.x, false, "x");
  expect_same(s.y, r.y, false, "y");
  expect_same(s.z, r.z, false, "z");
  expect_same(s.eps_v_p, r.eps_v_p, false, "eps_v_p");
  expect_same(s.gate_x_ref, r.gate_x_ref, false, "gate_x_ref");
  expect_same(s.gate_y_ref, r.gate_y_ref, false, "gate_y_ref");
  expect_same(s.gate_z_ref, r.gate_z_ref, false, "gate_z_ref");
  expect_same(s.gate_eps_v_p, r.gate_eps_v_p, false, "gate_eps_v_p");
  expect_same(s.vx, r.vx, true, "vx");
  expect_same(s.vy, r.vy, true, "vy");
  expect_same(s.vz, r.vz, true, "vz");
  expect_same(s.pressure_pa, r.pressure_pa, true, "pressure");
  expect_same(s.von_mises_pa, r.von_mises_pa, true, "von_mises");
  expect_same(s.sigma_zz_pa, r.sigma_zz_pa, true, "sigma_zz");
  expect_same(s.volume_m3, r.volume_m3, true, "volume");
}

TEST(ParticleFile, RoundTripKeepsPositionsAndDamageBitForBit2d) { round_trip(2); }
TEST(ParticleFile, RoundTripKeepsPositionsAndDamageBitForBit3d) { round_trip(3); }

std::string slurp(const std::filesystem::path& p) {
  std::ifstream f(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
}

void expect_refused(const std::filesystem::path& p, const std::string& bytes, const std::string& why) {
  std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
  try {
    read_particle_file(p);
    ADD_FAILURE() << "read a " << why;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
  }
}

// One checksum covers the whole file: a bit flipped anywhere in the header (a scalar such as the
// gate's position or the passed length, a metadata field, the array table, the sizes) is refused by
// both readers, as a flip in the arrays is.
TEST(ParticleFile, AFlippedBitInTheHeaderIsRefused) {
  const auto path = temp_file("header");
  write_particle_file(path, make_snapshot(2, 200), {{"case_id", "abc"}, {"measurement", {{"frame", "passed"}}}});
  const std::string whole = slurp(path);
  std::uint64_t header_size = 0;
  std::memcpy(&header_size, whole.data() + 12, sizeof header_size);
  const std::size_t sizes_end = 20 + header_size + 16;
  ASSERT_LT(sizes_end, whole.size());
  int flips = 0;
  for (const std::string field : {"\"gate_x_m\":", "\"gate_passed_length_m\":", "\"softening_zeta\":",
                                  "\"case_id\":", "\"frame\":", "\"count\":"}) {
    const std::size_t at = whole.find(field, 20);
    ASSERT_LT(at, 20 + header_size) << field;
    std::string bad = whole;
    bad[at + field.size() + 1] ^= 0x01;  // a digit or letter of its value: still valid JSON mostly
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bad;
    EXPECT_THROW(read_particle_file(path), InputError) << field;
    EXPECT_THROW(read_particle_file_header(path), InputError) << field;
    ++flips;
  }
  for (std::size_t k = 8; k < sizes_end; k += 5) {  // every part before the arrays
    std::string bad = whole;
    bad[k] ^= 0x04;
    std::ofstream(path, std::ios::binary | std::ios::trunc) << bad;
    EXPECT_THROW(read_particle_file(path), InputError) << "byte " << k;
    EXPECT_THROW(read_particle_file_header(path), InputError) << "byte " << k;
    ++flips;
  }
  EXPECT_GT(flips, 50);
  std::filesystem::remove(path);
}

// A file in the layout of format 1 (an older crevasse): the CRC-32 of the uncompressed arrays
// before them, none over the header.
std::string format_1_file(const std::string& format_2) {
  std::uint64_t header_size = 0, raw_size = 0, packed_size = 0;
  std::memcpy(&header_size, format_2.data() + 12, 8);
  const std::size_t sizes = 20 + header_size;
  std::memcpy(&raw_size, format_2.data() + sizes, 8);
  std::memcpy(&packed_size, format_2.data() + sizes + 8, 8);
  const std::string packed = format_2.substr(sizes + 16, packed_size);
  std::string raw(raw_size, '\0');
  uLongf n = raw_size;
  EXPECT_EQ(uncompress(reinterpret_cast<Bytef*>(raw.data()), &n, reinterpret_cast<const Bytef*>(packed.data()),
                       packed.size()),
            Z_OK);
  const auto crc = static_cast<std::uint32_t>(crc32(0L, reinterpret_cast<const Bytef*>(raw.data()), raw.size()));
  std::string out = format_2.substr(0, sizes + 16);
  out[8] = 1;
  out.append(reinterpret_cast<const char*>(&crc), sizeof crc);
  out += packed;
  out += format_2.substr(format_2.size() - 8);
  return out;
}

// Format 1 files are still read, their arrays checked, and the readers say that the header is
// not; damage in a format 1 file's arrays is still refused.
TEST(ParticleFile, Format1IsReadWithItsHeaderMarkedUnchecked) {
  const auto path = temp_file("format1");
  const ParticleSnapshot s = make_snapshot(2, 300);
  write_particle_file(path, s, {{"case_id", "old"}});
  const std::string old = format_1_file(slurp(path));
  std::ofstream(path, std::ios::binary | std::ios::trunc) << old;
  const ParticleFile f = read_particle_file(path);
  EXPECT_FALSE(f.header_checked);
  EXPECT_EQ(f.snapshot.x, s.x);
  EXPECT_EQ(f.metadata.at("case_id"), "old");
  EXPECT_FALSE(read_particle_file_header(path).header_checked);
  EXPECT_NE(unchecked_header_warning(path).find("header"), std::string::npos);
  std::string bad = old;
  bad[old.size() - 30] ^= 0x10;
  expect_refused(path, bad, "format 1 file with a flipped array byte");
  std::filesystem::remove(path);
}

TEST(ParticleFile, TruncatedDamagedAndForeignFilesAreRefused) {
  const auto path = temp_file("bad");
  write_particle_file(path, make_snapshot(2, 200));
  const std::string whole = slurp(path);
  ASSERT_GT(whole.size(), 100u);
  // Every cut, in steps small enough to land in each part (magic, header, sizes, payload, end).
  for (std::size_t cut = 0; cut < whole.size(); cut += 7) expect_refused(path, whole.substr(0, cut), "cut file");
  // The header reader checks the whole file too: no cut passes it.
  for (std::size_t cut = 0; cut < whole.size(); cut += 61) {
    std::ofstream(path, std::ios::binary | std::ios::trunc) << whole.substr(0, cut);
    EXPECT_THROW(read_particle_file_header(path), InputError) << "cut at " << cut;
  }
  expect_refused(path, whole + "x", "file with bytes after its end");
  // A byte flipped in the compressed arrays: zlib or the CRC-32 notices.
  for (std::size_t k : {whole.size() / 2, whole.size() - 20}) {
    std::string bad = whole;
    bad[k] = static_cast<char>(bad[k] ^ 0x10);
    expect_refused(path, bad, "flipped byte at " + std::to_string(k));
  }
  expect_refused(path, "<?xml version=\"1.0\"?>\n<VTKFile/>\n", "foreign file");
  std::string newer = whole;
  newer[8] = 3;  // format number
  expect_refused(path, newer, "newer format");
  std::filesystem::remove(path);
  EXPECT_THROW(read_particle_file(path), InputError);
  EXPECT_THROW(read_particle_file(std::filesystem::temp_directory_path()), InputError);
}

}  // namespace
}  // namespace crevasse

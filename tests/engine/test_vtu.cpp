// VTU writer (engine/vtu_writer.hpp): the header declares the number of points, each appended
// block starts at the offset the header gives and carries a UInt64 byte count equal to the
// size of its array (components × points × type size), and the data read back are the
// snapshot's. ParaView relies on exactly these.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>

#include "engine/snapshot.hpp"
#include "engine/vtu_writer.hpp"

namespace crevasse {
namespace {

ParticleSnapshot make_snapshot(int dim, std::size_t n) {
  ParticleSnapshot s;
  s.dim = dim;
  s.time_s = 1.5;
  s.softening_zeta = 100.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = static_cast<double>(i);
    s.x.push_back(d);
    s.z.push_back(2.0 * d + 0.5);
    s.vx.push_back(-d);
    s.vz.push_back(0.25 * d);
    if (dim == 3) {
      s.y.push_back(10.0 + d);
      s.vy.push_back(1.0);
    }
    s.eps_v_p.push_back(1e-3 * d);
    s.pressure_pa.push_back(1e3 * d);
    s.von_mises_pa.push_back(2e3 * d);
    s.sigma_zz_pa.push_back(-3e3 * d);
    s.volume_m3.push_back(0.25);
  }
  return s;
}

struct Declared {
  std::string name;
  std::string type;
  int components = 1;
  std::uint64_t offset = 0;
};

void check_file(int dim, std::size_t n) {
  const ParticleSnapshot snap = make_snapshot(dim, n);
  const auto path = std::filesystem::temp_directory_path() /
                    ("crevasse_test_vtu_" + std::to_string(dim) + "_" + std::to_string(n) + ".vtu");
  write_vtu(path.string(), snap);
  std::ifstream f(path, std::ios::binary);
  ASSERT_TRUE(f);
  const std::string text((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  std::filesystem::remove(path);

  const std::size_t data_start = text.find("<AppendedData encoding=\"raw\">");
  ASSERT_NE(data_start, std::string::npos);
  const std::string header = text.substr(0, data_start);
  const std::size_t underscore = text.find('_', data_start);
  ASSERT_NE(underscore, std::string::npos);
  const std::size_t base = underscore + 1;  // offsets count from the byte after '_'

  std::smatch m;
  ASSERT_TRUE(std::regex_search(header, m, std::regex("NumberOfPoints=\"(\\d+)\"")));
  EXPECT_EQ(std::stoull(m[1]), n);
  ASSERT_TRUE(std::regex_search(header, m, std::regex("NumberOfCells=\"(\\d+)\"")));
  EXPECT_EQ(std::stoull(m[1]), n);
  EXPECT_NE(header.find("header_type=\"UInt64\""), std::string::npos);

  // Every appended DataArray, in file order.
  std::vector<Declared> arrays;
  const std::regex tag("<DataArray ([^>]*)format=\"appended\" offset=\"(\\d+)\"");
  for (auto it = std::sregex_iterator(header.begin(), header.end(), tag);
       it != std::sregex_iterator(); ++it) {
    Declared d;
    const std::string attrs = (*it)[1];
    d.offset = std::stoull((*it)[2]);
    std::smatch a;
    if (std::regex_search(attrs, a, std::regex("type=\"(\\w+)\""))) d.type = a[1];
    if (std::regex_search(attrs, a, std::regex("Name=\"(\\w+)\""))) d.name = a[1];
    if (std::regex_search(attrs, a, std::regex("NumberOfComponents=\"(\\d+)\"")))
      d.components = std::stoi(a[1]);
    arrays.push_back(d);
  }
  // 7 point-data arrays, the points, and connectivity/offsets/types.
  ASSERT_EQ(arrays.size(), 11u);
  const std::map<std::string, std::size_t> type_size{{"Float64", 8}, {"Int64", 8}, {"UInt8", 1}};
  std::uint64_t expected_offset = 0;
  for (const Declared& d : arrays) {
    ASSERT_TRUE(type_size.count(d.type)) << d.type;
    const std::uint64_t bytes = static_cast<std::uint64_t>(d.components) * n * type_size.at(d.type);
    EXPECT_EQ(d.offset, expected_offset) << d.name;  // blocks are contiguous, in order
    std::uint64_t stored = 0;
    ASSERT_LE(base + d.offset + sizeof(stored) + bytes, text.size());
    std::memcpy(&stored, text.data() + base + d.offset, sizeof(stored));
    EXPECT_EQ(stored, bytes) << d.name;
    expected_offset += sizeof(stored) + bytes;
  }
  // After the last block: the closing tags only.
  EXPECT_EQ(text.substr(base + expected_offset), "\n</AppendedData>\n</VTKFile>\n");

  // The points block (the one in <Points>, 3 components) reads back as (x, y or 0, z).
  const std::size_t points_index = 7;
  ASSERT_EQ(arrays[points_index].components, 3);
  std::vector<double> pts(3 * n);
  // memcpy with the null data() of an empty vector is undefined even for 0 bytes (UBSan).
  if (n > 0) std::memcpy(pts.data(), text.data() + base + arrays[points_index].offset + 8, 3 * n * 8);
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_EQ(pts[3 * i], snap.x[i]);
    EXPECT_EQ(pts[3 * i + 1], dim == 3 ? snap.y[i] : 0.0);
    EXPECT_EQ(pts[3 * i + 2], snap.z[i]);
  }
  // Damage is 1 − exp(−ζ ε_v^p) (docs/measurement.md).
  for (const Declared& d : arrays) {
    if (d.name != "damage") continue;
    std::vector<double> dmg(n);
    if (n > 0) std::memcpy(dmg.data(), text.data() + base + d.offset + 8, n * 8);
    for (std::size_t i = 0; i < n; ++i)
      EXPECT_DOUBLE_EQ(dmg[i], 1.0 - std::exp(-snap.softening_zeta * snap.eps_v_p[i]));
  }
}

TEST(VtuWriter, HeaderAndAppendedBlocks2d) { check_file(2, 37); }
TEST(VtuWriter, HeaderAndAppendedBlocks3d) { check_file(3, 5); }
TEST(VtuWriter, EmptySnapshot) { check_file(2, 0); }

TEST(VtuWriter, UnwritablePathThrows) {
  EXPECT_THROW(write_vtu("/nonexistent_dir_crevasse/x.vtu", make_snapshot(2, 3)),
               std::runtime_error);
}

}  // namespace
}  // namespace crevasse

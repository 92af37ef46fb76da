#include "engine/vtu_writer.hpp"

#include <cstdint>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "engine/atomic_file.hpp"

namespace crevasse {
namespace {

struct Array {
  std::string name;
  int components;
  std::vector<double> data;  // written as Float64
};

}  // namespace

void write_vtu(const std::string& path, const ParticleSnapshot& s) {
  const std::size_t n = s.size();
  std::vector<Array> point_data;
  auto vec3 = [&](const std::vector<double>& a, const std::vector<double>& b, const std::vector<double>& c) {
    std::vector<double> out(3 * n, 0.0);
    for (std::size_t i = 0; i < n; ++i) {
      out[3 * i] = a[i];
      out[3 * i + 1] = b.empty() ? 0.0 : b[i];
      out[3 * i + 2] = c[i];
    }
    return out;
  };
  // 2D (x, z) is written as (x, 0, z) so that ParaView shows the flow plane as x–z.
  const std::vector<double> points = vec3(s.x, s.y, s.z);
  point_data.push_back({"velocity", 3, vec3(s.vx, s.vy, s.vz)});
  point_data.push_back({"eps_v_p", 1, s.eps_v_p});
  std::vector<double> damage(n);
  for (std::size_t i = 0; i < n; ++i) damage[i] = s.damage(i);
  point_data.push_back({"damage", 1, damage});
  point_data.push_back({"pressure", 1, s.pressure_pa});
  point_data.push_back({"von_mises", 1, s.von_mises_pa});
  point_data.push_back({"sigma_zz", 1, s.sigma_zz_pa});
  point_data.push_back({"volume", 1, s.volume_m3});

  AtomicFile file(path);  // ParaView never sees half a snapshot
  std::ofstream f(file.temp_path(), std::ios::binary);
  if (!f) throw std::runtime_error("cannot write " + path);
  std::uint64_t offset = 0;
  auto block_bytes = [](std::size_t count, std::size_t size) { return sizeof(std::uint64_t) + count * size; };
  f << "<?xml version=\"1.0\"?>\n"
    << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
    << "<UnstructuredGrid>\n"
    << "<FieldData><DataArray type=\"Float64\" Name=\"TimeValue\" NumberOfTuples=\"1\" format=\"ascii\">"
    << s.time_s << "</DataArray></FieldData>\n"
    << "<Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << n << "\">\n<PointData>\n";
  for (const auto& a : point_data) {
    f << "<DataArray type=\"Float64\" Name=\"" << a.name << "\" NumberOfComponents=\"" << a.components
      << "\" format=\"appended\" offset=\"" << offset << "\"/>\n";
    offset += block_bytes(a.data.size(), sizeof(double));
  }
  f << "</PointData>\n<Points>\n<DataArray type=\"Float64\" NumberOfComponents=\"3\" format=\"appended\" offset=\""
    << offset << "\"/>\n</Points>\n";
  offset += block_bytes(points.size(), sizeof(double));
  f << "<Cells>\n<DataArray type=\"Int64\" Name=\"connectivity\" format=\"appended\" offset=\"" << offset << "\"/>\n";
  offset += block_bytes(n, sizeof(std::int64_t));
  f << "<DataArray type=\"Int64\" Name=\"offsets\" format=\"appended\" offset=\"" << offset << "\"/>\n";
  offset += block_bytes(n, sizeof(std::int64_t));
  f << "<DataArray type=\"UInt8\" Name=\"types\" format=\"appended\" offset=\"" << offset << "\"/>\n";
  f << "</Cells>\n</Piece>\n</UnstructuredGrid>\n<AppendedData encoding=\"raw\">\n_";
  auto write_block = [&](const void* data, std::size_t bytes) {
    const std::uint64_t header = bytes;
    f.write(reinterpret_cast<const char*>(&header), sizeof(header));
    f.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
  };
  for (const auto& a : point_data) write_block(a.data.data(), a.data.size() * sizeof(double));
  write_block(points.data(), points.size() * sizeof(double));
  std::vector<std::int64_t> ids(n), offsets(n);
  for (std::size_t i = 0; i < n; ++i) {
    ids[i] = static_cast<std::int64_t>(i);
    offsets[i] = static_cast<std::int64_t>(i + 1);
  }
  write_block(ids.data(), n * sizeof(std::int64_t));
  write_block(offsets.data(), n * sizeof(std::int64_t));
  const std::vector<std::uint8_t> types(n, 1);  // VTK_VERTEX
  write_block(types.data(), n);
  f << "\n</AppendedData>\n</VTKFile>\n";
  f.close();
  if (!f) throw std::runtime_error("write failed: " + path + " (disk full?)");
  file.commit();
}

void write_pvd(const std::string& path, const std::vector<std::pair<double, std::string>>& files) {
  std::ostringstream f;
  f << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n<Collection>\n";
  for (const auto& [t, name] : files)
    f << "<DataSet timestep=\"" << t << "\" part=\"0\" file=\"" << name << "\"/>\n";
  f << "</Collection>\n</VTKFile>\n";
  write_file_atomically(path, f.str());
}

}  // namespace crevasse

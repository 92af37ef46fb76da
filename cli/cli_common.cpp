#include "cli/cli_common.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstdio>
#include <cstring>

#include "engine/error.hpp"

namespace crevasse {
namespace fs = std::filesystem;

std::string format_number(double v, const char* format) {
  char buf[48];
  std::snprintf(buf, sizeof buf, format, v);
  return buf;
}

void create_output_directory(const std::string& option, const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir))
    throw InputError(option + ": cannot create directory " + dir.string() +
                     (ec ? " (" + ec.message() + ")" : ""));
}

void check_output_directory(const std::string& option, const fs::path& dir,
                            const std::vector<std::string>& files) {
  std::error_code ec;
  fs::path existing = fs::absolute(dir, ec);
  if (ec) existing = dir;
  const fs::path wanted = existing;
  while (!fs::exists(fs::status(existing, ec)) && existing.has_relative_path())
    existing = existing.parent_path();
  if (!fs::is_directory(existing, ec))
    throw InputError(option + ": " + existing.string() + " exists and is not a folder" +
                     (existing == wanted ? std::string() : ", so " + dir.string() + " cannot be made"));
  // A file made and removed again: permission bits say nothing to root, and nothing at all
  // about /proc or a read-only mount.
  std::string probe = (existing / ".crevasse-probe-XXXXXX").string();
  const int fd = ::mkstemp(probe.data());
  if (fd < 0)
    throw InputError(option + ": cannot write in " + existing.string() + " (" + std::strerror(errno) + ")");
  ::close(fd);
  ::unlink(probe.c_str());
  // A command killed between its probe's mkstemp and unlink leaves the probe behind: clear such
  // leftovers (another command's live probe, if any, only loses a file it is about to unlink).
  for (const auto& e : fs::directory_iterator(existing, ec))
    if (e.path().filename().string().rfind(".crevasse-probe-", 0) == 0) fs::remove(e.path(), ec);
  for (const std::string& name : files) {  // a name ending in '/' is a folder
    const fs::path p = dir / name;
    if (!fs::exists(fs::symlink_status(p, ec))) continue;
    const bool folder = !name.empty() && name.back() == '/';
    if (folder ? !fs::is_directory(p, ec) : !fs::is_regular_file(p, ec))
      throw InputError(option + ": " + p.string() + " is in the way (it exists and is not a " +
                       (folder ? "folder" : "regular file") + ")");
  }
}

void check_output_file(const std::string& option, const fs::path& file) {
  std::error_code ec;
  const fs::path parent = file.has_parent_path() ? file.parent_path() : fs::path(".");
  check_output_directory(option, parent);
  if (fs::exists(fs::symlink_status(file, ec)) && !fs::is_regular_file(fs::status(file, ec)))
    throw InputError(option + ": " + file.string() + " exists and is not a regular file");
}

bool same_path(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);  // links of any kind
  const fs::path ca = fs::weakly_canonical(fs::absolute(a, ec), ec), cb = fs::weakly_canonical(fs::absolute(b, ec), ec);
  return !ec && ca == cb;
}

void check_output_is_not_input(const std::string& option, const fs::path& output, const std::vector<NamedPath>& inputs) {
  for (const NamedPath& in : inputs)
    if (same_path(output, in.path))
      throw InputError(option + ": " + output.string() + " is also " + in.option + " (" + in.path.string() +
                       "): a command never writes over what it reads; choose another path");
}

void check_confidence_level(double level) {
  if (!(level > 0.5 && level < 1.0))
    throw InputError("--level: " + format_number(level, "%.17g") + " is outside (0.5, 1)");
  if (format_number(level, "%.4g") == "1")
    throw InputError("--level: " + format_number(level, "%.17g") +
                     " rounds to 1 (its intervals would be infinite); the largest is 0.9999");
}

std::vector<fs::path> write_png_and_svg(const analysis::Figure& figure, const fs::path& stem) {
  const fs::path png = stem.string() + ".png", svg = stem.string() + ".svg";
  figure.write_png(png.string());
  figure.write_svg(svg.string());
  return {png, svg};
}

void set_quartile_bar(analysis::RegimePoint& p,
                      const std::array<std::optional<double>, 3>& quartiles) {
  if (quartiles[0] && quartiles[2] && *quartiles[0] > 0.0) {
    p.y_q25 = *quartiles[0];
    p.y_q75 = *quartiles[2];
  }
}

}  // namespace crevasse

#include "cli/cli_common.hpp"

#include <cstdio>

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

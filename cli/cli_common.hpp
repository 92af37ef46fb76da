#pragma once
// Helpers that several commands share: numbers in tables and progress lines, the output folder,
// figures written as PNG and SVG, and the quartile bar of a point on a regime diagram.
#include <array>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "analysis/plot.hpp"
#include "analysis/regime_diagram.hpp"

namespace crevasse {

// `v` through printf's `format` ("%.3g" by default), for tables and progress lines.
std::string format_number(double v, const char* format = "%.3g");

// Creates `dir` and its parents for a command's output; InputError naming `option` when it
// cannot.
void create_output_directory(const std::string& option, const std::filesystem::path& dir);

// Output paths are checked before any work, as input paths are, so that a bad one costs no
// simulation and leaves no partial output: `dir` must be a folder or not exist yet below a
// folder this process may write to, and each of `files` (names inside it) must not exist as
// anything but a regular file. InputError naming `option` and the path otherwise.
void check_output_directory(const std::string& option, const std::filesystem::path& dir,
                            const std::vector<std::string>& files = {});
// The same for one output file: its folder as above, the file absent or a regular file.
void check_output_file(const std::string& option, const std::filesystem::path& file);

// Whether two paths name one file or folder once symbolic links are followed (and, when both
// exist, whether they are hard links to one file).
bool same_path(const std::filesystem::path& a, const std::filesystem::path& b);

// No output of a command may be one of its inputs: InputError naming `option`, the path and the
// input it would overwrite, when `output` is one of `inputs` (same_path).
struct NamedPath {
  std::string option;
  std::filesystem::path path;
};
void check_output_is_not_input(const std::string& option, const std::filesystem::path& output,
                               const std::vector<NamedPath>& inputs);

// --level of fit, calibrate and predict: in (0.5, 1), and below 1 as the tables show it (4
// significant digits): a level that rounds to 1 has infinite intervals. InputError otherwise.
void check_confidence_level(double level);

// Writes `figure` as <stem>.png and <stem>.svg; returns the two paths, PNG first.
std::vector<std::filesystem::path> write_png_and_svg(const analysis::Figure& figure,
                                                     const std::filesystem::path& stem);

// The error bar of a regime-diagram point from a case's quartiles (Q25, median, Q75): set when
// both ends are known and Q25 is positive (the axes are logarithmic), else left as none.
void set_quartile_bar(analysis::RegimePoint& p,
                      const std::array<std::optional<double>, 3>& quartiles);

}  // namespace crevasse

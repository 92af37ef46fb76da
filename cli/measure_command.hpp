#pragma once
// `crevasse measure FILE [--set KEY=VALUE ...] [--out DIR] [--vtu FILE]`: measures the final
// particles of a case again (a file kept by `crevasse study --keep-particles` or written by
// `crevasse run`), with the settings the case was measured with unless --set changes them.
// Reads only: the study database is not touched.
#include <string>
#include <vector>

namespace crevasse {

struct MeasureCommandOptions {
  std::string particle_path;
  std::vector<std::string> settings;  // KEY=VALUE, measurement keys of docs/study_format.md
  std::string out_dir;                // non-empty: crevasses.csv, measurement.json, side views
  std::string vtu_path;               // non-empty: the particles as VTU, for ParaView
};

int measure_command(const MeasureCommandOptions& opt);

}  // namespace crevasse

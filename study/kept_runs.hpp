#pragma once
// A case function that measures a study's cases from the final particles another study kept
// (`crevasse study --keep-particles`) instead of simulating them again. The measurement is the
// only thing that may differ between the two studies: a kept file is used for a case only when
// it was written for the same scene by this engine version, which its metadata proves (the case
// hash of this case's scene under the kept file's measurement settings is the kept file's case
// id). The run's record (stop reason, steps, simulated time, masses) comes from the kept study's
// database, so a case measured this way stores the result a full run would store.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "study/case_context.hpp"

namespace crevasse {

class KeptRuns {
 public:
  // Reads the header of every *_particles.bin in `particles_dir`, and opens `db` read-only.
  // InputError naming the option when the folder holds no such file or the database cannot be
  // read. A file that is damaged or not a study's is not a refusal: it fails the case its name
  // gives (case_NNN_particles.bin), or is named by warnings().
  KeptRuns(std::filesystem::path db, const std::filesystem::path& particles_dir);

  // The case function (CaseFunction). SimulationError when no kept file belongs to the case,
  // its file is damaged, or its run is not stored as done in the database.
  CaseOutcome operator()(const StudyCase& study_case, CaseContext& ctx) const;

  // One line per file the study's cases will not use (damaged without a case of that number,
  // of another scene or engine version, not written by a study) and per older file whose header
  // is not covered by its checksum.
  std::vector<std::string> warnings(const Study& study) const;

  // Every particle file in the folder: what the study reads, and so what it must not write.
  const std::vector<std::filesystem::path>& files() const { return paths_; }
  std::size_t file_count() const { return files_.size(); }

 private:
  struct Kept {
    std::filesystem::path path;
    std::string case_id;
    std::string engine_version;
    nlohmann::json measurement;
    nlohmann::json gate_mark;  // null, or the records of a run kept at a gate mark (study/engine_case.cpp)
    bool header_checked = true;
  };
  struct Unusable {
    std::filesystem::path path;
    std::string reason;
  };
  const Kept* find(const StudyCase& study_case) const;
  const Unusable* damaged_file_of(const StudyCase& study_case) const;
  std::filesystem::path db_;
  std::filesystem::path dir_;
  std::vector<std::filesystem::path> paths_;
  std::vector<Kept> files_;
  std::vector<Unusable> unusable_;
};

// "case_NNN_particles.bin" → NNN; nullopt for any other name.
std::optional<std::size_t> kept_particles_case_index(const std::filesystem::path& file);

}  // namespace crevasse

#pragma once
// A case function that measures a study's cases from the final particles another study kept
// (`crevasse study --keep-particles`) instead of simulating them again. The measurement is the
// only thing that may differ between the two studies: a kept file is used for a case only when
// it was written for the same scene by this engine version, which its metadata proves (the case
// hash of this case's scene under the kept file's measurement settings is the kept file's case
// id). The run's record (stop reason, steps, simulated time, masses) comes from the kept study's
// database, so a case measured this way stores the result a full run would store.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "study/case_context.hpp"

namespace crevasse {

class KeptRuns {
 public:
  // Reads the metadata of every *_particles.bin in `particles_dir`, and opens `db` read-only.
  // InputError naming the option when the folder holds no particle file or the database
  // cannot be read.
  KeptRuns(std::filesystem::path db, const std::filesystem::path& particles_dir);

  // The case function (CaseFunction). SimulationError when no kept file belongs to the case,
  // or its run is not stored as done in the database.
  CaseOutcome operator()(const StudyCase& study_case, CaseContext& ctx) const;

  std::size_t file_count() const { return files_.size(); }

 private:
  struct Kept {
    std::filesystem::path path;
    std::string case_id;
    std::string engine_version;
    nlohmann::json measurement;
  };
  const Kept* find(const StudyCase& study_case) const;
  std::filesystem::path db_;
  std::filesystem::path dir_;
  std::vector<Kept> files_;
};

}  // namespace crevasse

#include "study/kept_runs.hpp"

#include <algorithm>

#include "engine/error.hpp"
#include "engine/particle_file.hpp"
#include "study/case_hash.hpp"
#include "study/engine_case.hpp"
#include "study/store.hpp"

namespace crevasse {

KeptRuns::KeptRuns(std::filesystem::path db, const std::filesystem::path& particles_dir)
    : db_(std::move(db)), dir_(particles_dir) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(db_, ec))
    throw InputError("--remeasure: " + db_.string() + " is not a study database (no such file)");
  if (!std::filesystem::is_directory(dir_, ec))
    throw InputError("--particles-from: " + dir_.string() + " is not a folder");
  std::vector<std::filesystem::path> paths;
  for (const auto& e : std::filesystem::directory_iterator(dir_, ec)) {
    const std::string name = e.path().filename().string();
    const std::string tail = "_particles.bin";
    if (name.size() > tail.size() && name.compare(name.size() - tail.size(), tail.size(), tail) == 0)
      paths.push_back(e.path());
  }
  std::sort(paths.begin(), paths.end());
  for (const auto& p : paths) {
    // The particles are read by the case that uses them.
    const nlohmann::json meta = read_particle_file_metadata(p);
    if (!meta.contains("case_id") || !meta.contains("measurement") || !meta.contains("engine_version"))
      continue;  // not written by a study
    files_.push_back({p, meta.at("case_id").get<std::string>(), meta.at("engine_version").get<std::string>(),
                      meta.at("measurement")});
  }
  if (files_.empty())
    throw InputError("--particles-from: " + dir_.string() +
                     " holds no case_NNN_particles.bin written by crevasse study --keep-particles");
  // Fails here, with the option's name, rather than in every case.
  try {
    Store::open_reader(db_);
  } catch (const std::exception& e) {
    throw InputError("--remeasure: " + std::string(e.what()));
  }
}

const KeptRuns::Kept* KeptRuns::find(const StudyCase& study_case) const {
  for (const Kept& k : files_)
    if (k.engine_version == CREVASSE_ENGINE_VERSION &&
        case_hash(study_case.scene, k.measurement, k.engine_version) == k.case_id)
      return &k;
  return nullptr;
}

CaseOutcome KeptRuns::operator()(const StudyCase& study_case, CaseContext& ctx) const {
  const Kept* kept = find(study_case);
  if (!kept)
    throw SimulationError("no particles kept in " + dir_.string() + " for this case's scene and engine version " +
                          CREVASSE_ENGINE_VERSION + "; run it without --remeasure (--retry-failed)");
  nlohmann::json result, run;
  {
    Store store = Store::open_reader(db_);
    Statement s(store.handle(), "SELECT status, result_json, run_json FROM cases WHERE case_id = ?");
    s.bind(1, kept->case_id);
    if (!s.step() || s.text(0) != "done")
      throw SimulationError("the kept particles " + kept->path.filename().string() + " belong to case " +
                            kept->case_id.substr(0, 10) + ", which " + db_.string() + " does not hold as done");
    result = nlohmann::json::parse(s.text(1));
    run = nlohmann::json::parse(s.text(2));
  }
  ParticleFile file = read_particle_file(kept->path);
  CaseOutcome out;
  out.stop_reason = result.at("stop_reason").get<std::string>();
  out.steps = result.at("steps").get<std::int64_t>();
  out.particle_steps = result.at("particle_steps").get<std::int64_t>();
  out.sim_time_s = result.at("sim_time_s").get<double>();
  out.result_extra = result.at("extra");
  out.result_extra.erase("other_spacing_rule");  // measured again below
  out.result_extra.erase("over_time");  // taken in the old measurement's frame
  out.run_json = run;
  out.run_json.erase("peak_rss_exact");  // the runner's, for this process
  out.run_json["measured_from"] = {
      {"database", db_.string()}, {"case_id", kept->case_id}, {"particles", kept->path.string()}};
  measure_final_state(study_case, ctx, file.snapshot, out);
  return out;
}

}  // namespace crevasse

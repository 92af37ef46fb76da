#include "study/kept_runs.hpp"

#include <algorithm>
#include <cctype>
#include <set>

#include "analysis/measurement_io.hpp"
#include "engine/error.hpp"
#include "engine/particle_file.hpp"
#include "study/case_hash.hpp"
#include "study/engine_case.hpp"
#include "study/store.hpp"

namespace crevasse {
namespace {

const std::string kTail = "_particles.bin";

bool ends_with_tail(const std::string& name) {
  return name.size() > kTail.size() && name.compare(name.size() - kTail.size(), kTail.size(), kTail) == 0;
}

}  // namespace

std::optional<std::size_t> kept_particles_case_index(const std::filesystem::path& file) {
  const std::string name = file.filename().string();
  const std::string head = "case_";
  if (!ends_with_tail(name) || name.compare(0, head.size(), head) != 0) return std::nullopt;
  const std::string digits = name.substr(head.size(), name.size() - head.size() - kTail.size());
  if (digits.empty() || digits.size() > 9 || !std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c) != 0; })) return std::nullopt;
  return static_cast<std::size_t>(std::stoul(digits));
}

KeptRuns::KeptRuns(std::filesystem::path db, const std::filesystem::path& particles_dir)
    : db_(std::move(db)), dir_(particles_dir) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(db_, ec))
    throw InputError("--remeasure: " + db_.string() + " is not a study database (no such file)");
  if (!std::filesystem::is_directory(dir_, ec))
    throw InputError("--particles-from: " + dir_.string() + " is not a folder");
  for (const auto& e : std::filesystem::directory_iterator(dir_, ec))
    if (ends_with_tail(e.path().filename().string())) paths_.push_back(e.path());
  std::sort(paths_.begin(), paths_.end());
  if (paths_.empty())
    throw InputError("--particles-from: " + dir_.string() +
                     " holds no case_NNN_particles.bin written by crevasse study --keep-particles");
  for (const auto& p : paths_) {
    // The particles are read by the case that uses them; the header is checked here.
    try {
      const ParticleFileHeader h = read_particle_file_header(p);
      const nlohmann::json& meta = h.metadata;
      if (!meta.is_object() || !meta.contains("case_id") || !meta.contains("measurement") ||
          !meta.contains("engine_version"))
        unusable_.push_back({p, "not written by crevasse study --keep-particles"});
      else
        files_.push_back({p, meta.at("case_id").get<std::string>(), meta.at("engine_version").get<std::string>(),
                          meta.at("measurement"), meta.value("gate_mark", nlohmann::json()), h.header_checked});
    } catch (const std::exception& e) {
      unusable_.push_back({p, e.what()});
    }
  }
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

const KeptRuns::Unusable* KeptRuns::damaged_file_of(const StudyCase& study_case) const {
  for (const Unusable& u : unusable_)
    if (kept_particles_case_index(u.path) == study_case.index) return &u;
  return nullptr;
}

std::vector<std::string> KeptRuns::warnings(const Study& study) const {
  std::vector<std::string> out;
  std::set<std::filesystem::path> used;
  std::set<std::size_t> indices;
  for (const StudyCase& c : study.cases) {
    indices.insert(c.index);
    if (const Kept* k = find(c)) used.insert(k->path);
  }
  // Files of other cases are one line: a longer study's folder holds many (its final particles
  // and those kept at other gate marks).
  std::vector<const Kept*> strays;
  for (const Kept& k : files_) {
    if (!used.count(k.path))
      strays.push_back(&k);
    else if (!k.header_checked)
      out.push_back(unchecked_header_warning(k.path));
  }
  if (strays.size() == 1)
    out.push_back(strays[0]->path.string() + ": its particles belong to no case of this study (another scene, or engine " +
                  strays[0]->engine_version + "); ignored");
  else if (strays.size() > 1)
    out.push_back(std::to_string(strays.size()) + " kept particle files in " + dir_.string() +
                  " belong to no case of this study (another scene or engine version), e.g. " +
                  strays[0]->path.filename().string() + "; ignored");
  for (const Unusable& u : unusable_) {
    const auto index = kept_particles_case_index(u.path);
    if (!index || !indices.count(*index))
      out.push_back(u.reason.rfind(u.path.string(), 0) == 0 ? u.reason + "; it names no case of this study, ignored"
                                                            : u.path.string() + ": " + u.reason + "; ignored");
  }
  return out;
}

CaseOutcome KeptRuns::operator()(const StudyCase& study_case, CaseContext& ctx) const {
  const Kept* kept = find(study_case);
  if (!kept) {
    if (const Unusable* u = damaged_file_of(study_case))
      throw SimulationError("its kept particles cannot be used: " + u->reason);
    throw SimulationError("no particles kept in " + dir_.string() + " for this case's scene and engine version " +
                          CREVASSE_ENGINE_VERSION + "; run it without --remeasure (--retry-failed)");
  }
  nlohmann::json result, run;
  if (!kept->gate_mark.is_null()) {
    // Kept by a longer run at this case's stop: its records travel with the particles.
    try {
      result = kept->gate_mark.at("result");
      run = kept->gate_mark.at("run");
    } catch (const nlohmann::json::exception& e) {
      throw SimulationError("its kept particles " + kept->path.filename().string() +
                            " carry unreadable gate-mark records: " + e.what());
    }
  } else {
    Store store = Store::open_reader(db_);
    Statement s(store.handle(), "SELECT status, result_json, run_json FROM cases WHERE case_id = ?");
    s.bind(1, kept->case_id);
    if (!s.step() || s.text(0) != "done")
      throw SimulationError("the kept particles " + kept->path.filename().string() + " belong to case " +
                            kept->case_id.substr(0, 10) + ", which " + db_.string() + " does not hold as done");
    result = nlohmann::json::parse(s.text(1));
    run = nlohmann::json::parse(s.text(2));
  }
  ParticleFile file;
  try {
    file = read_particle_file(kept->path);
  } catch (const InputError& e) {
    throw SimulationError(std::string("its kept particles cannot be used: ") + e.what());
  }
  CaseOutcome out;
  out.stop_reason = result.at("stop_reason").get<std::string>();
  out.steps = result.at("steps").get<std::int64_t>();
  out.particle_steps = result.at("particle_steps").get<std::int64_t>();
  out.sim_time_s = result.at("sim_time_s").get<double>();
  out.result_extra = result.at("extra");
  out.result_extra.erase("other_spacing_rule");  // measured again below
  out.result_extra.erase("over_time");             // kept below when still the run's own
  out.run_json = run;
  out.run_json.erase("peak_rss_exact");  // the runner's, for this process
  out.run_json["measured_from"] = {
      {"database", db_.string()}, {"case_id", kept->case_id}, {"particles", kept->path.string()}};
  if (!kept->gate_mark.is_null())
    out.run_json["measured_from"]["kept_at_gate_mark_of_case_id"] = kept->gate_mark.value("of_case_id", "");
  measure_final_state(study_case, ctx, file.snapshot, out);
  // The field over time was measured as the run went: it stays when the settings are the run's
  // own (the same study measured again by a newer detector), not when they differ.
  const nlohmann::json& extra = result.at("extra");
  const bool own_settings =
      kept->gate_mark.is_null() && out.measurement && result.contains("measurement") &&
      result["measurement"].value("settings", nlohmann::json()) == analysis::settings_to_json(out.measurement->settings);
  if (own_settings && extra.contains("over_time")) {
    out.result_extra["over_time"] = extra["over_time"];
    out.run_json["over_time_measured_during_run"] = true;
  }
  return out;
}

}  // namespace crevasse

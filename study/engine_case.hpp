#pragma once
// The real case function of the runner: simulate the case's scene with the engine, then
// measure its crevasses (docs/measurement.md) at the end of the run.
#include "study/case_context.hpp"

namespace crevasse {

// Runs the engine (the case's time limit, when shorter, becomes run.wall_time_limit;
// cancellation goes through the engine's observer) and measures the final snapshot with
// ctx.measurement(). A case out of time comes back as CaseOutcome::out_of_time, its checkpoint
// saved; throws SimulationError on instability or non-finite results.
CaseOutcome run_engine_case(const StudyCase& study_case, CaseContext& ctx);

// Measures a case's final state into `out` with ctx.measurement(), and under the other spacing
// rule too (result_extra.other_spacing_rule), and writes its side files when ctx asks for them.
// Throws SimulationError when the measurement fails. The stop signal and the case's time limit
// (the shorter of it and run.wall_time_limit, counted from the case's start) end it as they end
// a run: `out` comes back cancelled, with out_of_time set for the limit.
void measure_final_state(const StudyCase& study_case, CaseContext& ctx, const ParticleSnapshot& final_snapshot,
                         CaseOutcome& out);

// case_NNN_ (NNN as --dry-run lists the cases), the stem of every file a case writes.
std::string case_file_stem(std::size_t index);

// What a kept particle file carries besides the particles (engine/particle_file.hpp): the case,
// ρ_i and g (for Π), and the study's measurement settings, which `crevasse measure` starts from.
nlohmann::json particle_file_metadata(const SceneConfig& scene, const analysis::MeasureSettings& measurement,
                                      const std::string& case_id, const std::string& label);

}  // namespace crevasse

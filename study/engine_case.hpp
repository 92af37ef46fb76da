#pragma once
// The real case function of the runner: simulate the case's scene with the engine, then
// measure its crevasses (docs/measurement.md) at the end of the run.
#include "study/case_context.hpp"

namespace crevasse {

// Runs the engine (the runner's time limit becomes run.wall_time_limit; cancellation goes
// through the engine's observer) and measures the final snapshot with ctx.measurement().
// Throws SimulationError on instability, time limit or non-finite results.
CaseOutcome run_engine_case(const StudyCase& study_case, CaseContext& ctx);

}  // namespace crevasse

// The crevasse command line. Every error is caught here, printed on one line, and mapped to an
// exit code: 2 for bad input, 1 for a failed simulation or any other error.
#include <CLI/CLI.hpp>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <new>
#include <optional>
#include <string>
#include <system_error>

#include "cli/accuracy_command.hpp"
#include "cli/calibrate_command.hpp"
#include "cli/export_command.hpp"
#include "cli/fit_command.hpp"
#include "cli/measure_command.hpp"
#include "cli/merge_command.hpp"
#include "cli/plot_command.hpp"
#include "cli/run_command.hpp"
#include "cli/status_command.hpp"
#include "cli/study_command.hpp"
#include "engine/error.hpp"
#include "engine/json_input.hpp"
#include "study/memory_reserve.hpp"

namespace {

// --ramp-ice and --clear-of-front, one or neither: which crevasses of each case are read
// (docs/measurement.md, "The ramp's ice", "Clear of the front").
void add_reading_flags(CLI::App* command, crevasse::CaseReading& reading, const std::string& ramp_help,
                       const std::string& front_help) {
  CLI::Option* ramp = command->add_flag_callback(
      "--ramp-ice", [&reading] { reading = crevasse::CaseReading::ramp_ice; }, ramp_help);
  CLI::Option* front = command->add_flag_callback(
      "--clear-of-front", [&reading] { reading = crevasse::CaseReading::clear_of_front; },
      front_help);
  ramp->excludes(front);
}

// A message as one printable line of bounded length: it may echo user input (a key, a value), and
// neither a terminal escape nor a megabyte of a bad value belongs on the user's terminal.
std::string one_line(const std::string& what) {
  constexpr std::size_t kMaxMessage = 600;
  std::string s;
  for (const char c : what.substr(0, kMaxMessage))
    s += c == '\n' ? std::string("\\n") : c == '\r' ? std::string("\\r") : std::string(1, c);
  s = crevasse::printable(s);
  if (what.size() > kMaxMessage)
    s += "... (" + std::to_string(what.size() - kMaxMessage) + " more bytes)";
  return s;
}

// CLI11's Range lets NaN through (every comparison with NaN is false), and "inf" or "1e400" reach
// the commands as infinities: every floating-point option is required to be finite.
const CLI::Validator kFinite(
    [](std::string& s) -> std::string {
      char* end = nullptr;
      const double v = std::strtod(s.c_str(), &end);
      if (s.empty() || end != s.c_str() + s.size()) return "'" + s + "' is not a number";
      if (!std::isfinite(v)) return "'" + s + "' is not a finite number";
      return "";
    },
    "FINITE");

// An empty path or name is never meant: `--out ''` wrote into the current folder and `--db ''`
// fell back to the default database. Every text option and argument refuses it.
const CLI::Validator kNonEmpty(
    [](std::string& s) -> std::string { return s.empty() ? std::string("empty value") : std::string(); },
    "");

// `crevasse --version`: the program, the engine (its version enters every case hash), and the
// build that made this binary.
std::string version_text() {
  return std::string("crevasse ") + CREVASSE_VERSION + " (engine " + CREVASSE_ENGINE_VERSION +
         ", " + CREVASSE_BUILD_TYPE + " build, " + CREVASSE_COMPILER + ")";
}

}  // namespace

namespace {

int run_command_line(int argc, char** argv) {
  CLI::App app{"crevasse: scaling laws of glacier fracture from MPM parameter studies"};
  app.require_subcommand(1);
  app.set_version_flag("--version", version_text(),
                       "Print the program, engine and build versions and exit");

  crevasse::RunCommandOptions run_opt;
  auto* run = app.add_subcommand("run", "Simulate one scene: VTU snapshots, side-view PNG, crevasse measurement");
  run->add_option("scene", run_opt.scene_path, "Scene JSON file (see README, studies/scenes/)")->required();
  run->add_option("--out", run_opt.out_dir, "Output directory")->required();
  run->add_option("--vtu-interval", run_opt.vtu_interval, "Simulated seconds between VTU snapshots (overrides the scene)")->check(CLI::Range(0.0, 1e9));
  run->add_option("--measure-interval", run_opt.measure_interval, "Also measure the crevasses every this many simulated seconds, to see whether the pattern has settled (measurements_over_time.csv)")->check(CLI::Range(0.0, 1e9));
  run->add_option("--threads", run_opt.threads, "Worker threads (default: all cores)")->check(CLI::Range(1, 1024));
  run->add_flag("--quiet", run_opt.quiet, "No progress output");

  crevasse::StudyCommandOptions study_opt;
  auto* study = app.add_subcommand("study", "Run or resume a parameter study into its SQLite database");
  study->add_option("file", study_opt.study_path, "Study JSON file (see docs/study_format.md, studies/)")->required();
  study->add_option("--db", study_opt.db_path, "Database (default results/<name>.db)");
  study->add_option("--jobs", study_opt.jobs, "Cases at once (default: cores / threads per case)")->check(CLI::Range(1, 1024));
  study->add_option("--threads-per-case", study_opt.threads_per_case, "Engine threads per case (default 1)")->check(CLI::Range(1, 1024));
  study->add_option("--case-time-limit", study_opt.case_time_limit_s, "Wall seconds per case, 0 = none (default: the study's resources)")->check(CLI::Range(0.0, 1e8));
  study->add_option("--shard", study_opt.shard, "Run only shard I of N (I/N, 0 <= I < N)");
  study->add_option("--cases", study_opt.cases,
                    "Run only these cases, by index as --dry-run lists them (e.g. 30,33 or 20-25); the others stay pending");
  study->add_flag("--fail-fast", study_opt.fail_fast, "Stop at the first failing case");
  study->add_flag("--retry-failed", study_opt.retry_failed, "Run cases stored as failed again");
  study->add_flag("--dry-run", study_opt.dry_run, "List the cases and their hashes; run nothing");
  study->add_flag("--quiet", study_opt.quiet, "No progress output");
  study->add_option("--views", study_opt.views_dir, "Folder for the side views of each case run (case_NNN_side_view.png, case_NNN_gate_view.png; NNN as in --dry-run)");
  study->add_option("--remeasure", study_opt.remeasure_db, "Measure the cases from the particles another study kept, instead of simulating them: that study's database (give --particles-from too)");
  study->add_option("--particles-from", study_opt.particles_from, "With --remeasure: the folder where that study kept its particles (its DB.particles/, or --particles-dir)");
  study->add_flag("--keep-particles", study_opt.keep_particles, "Keep each case's final particles (case_NNN_particles.bin, about 1 MB per 40 000 particles) in DB.particles/ beside the database, to measure again with crevasse measure or --remeasure");
  study->add_option("--particles-dir", study_opt.particles_dir, "Keep the final particles in this folder instead of DB.particles/ (implies --keep-particles)");

  crevasse::MeasureCommandOptions measure_opt;
  auto* measure = app.add_subcommand("measure", "Measure a case's final particles again (crevasse study --keep-particles, crevasse run), e.g. with other settings");
  measure->add_option("file", measure_opt.particle_path, "Particle file (case_NNN_particles.bin, final_particles.bin)")->required();
  measure->add_option("--set", measure_opt.settings, "Measurement setting KEY=VALUE over the case's own (repeatable; keys as in a study file's measurement, docs/measurement.md)");
  measure->add_option("--out", measure_opt.out_dir, "Folder for crevasses.csv, measurement.json and the side views of this measurement");
  measure->add_option("--vtu", measure_opt.vtu_path, "Write the particles as a VTU file for ParaView");

  crevasse::StatusCommandOptions status_opt;
  auto* status = app.add_subcommand("status", "Summarise a study database (safe while the study runs)");
  status->add_option("db", status_opt.db_paths, "Study database (several with --compute)")->required();
  status->add_flag("--all", status_opt.all_cases, "List every finished case");
  status->add_flag("--compute", status_opt.compute_table,
                   "Only the compute the databases hold, per H_i, as a Markdown table: cases run, cases served "
                   "by another case's kept particles, particle-steps, engine wall time");

  crevasse::ExportCommandOptions export_opt;
  auto* export_cmd = app.add_subcommand("export", "Write a study database as CSV files, one per table");
  export_cmd->add_option("db", export_opt.db_path, "Study database")->required();
  export_cmd->add_option("--csv", export_opt.csv_dir, "Output directory")->required();

  std::string merge_out;
  std::vector<std::string> merge_in;
  auto* merge = app.add_subcommand("merge", "Combine the databases of one study's shards");
  merge->add_option("out", merge_out, "Output database (created or extended)")->required();
  merge->add_option("inputs", merge_in, "Input databases")->required();

  crevasse::FitCommandOptions fit_opt;
  auto* fit = app.add_subcommand("fit", "Fit power laws and a broken line to median L_p/H_i and D_p/H_i; store them in the fits table");
  fit->add_option("db", fit_opt.db_path, "Study database")->required();
  fit->add_option("--group", fit_opt.groups, "Group on the horizontal axis (repeatable; 'all' = every group that varies; default cohesion_ratio)");
  fit->add_option("--fixed-exponents", fit_opt.fixed_exponents, "Broken line of L_p/H_i: exponents below,above the breakpoint, each a number or 'free' (e.g. 1,free)");
  fit->add_option("--fixed-depth-exponents", fit_opt.fixed_depth_exponents, "The same for D_p/H_i");
  fit->add_option("--level", fit_opt.level, "Confidence level of the intervals (default 0.95)");
  fit->add_flag("--exclude-fragmented", fit_opt.exclude_fragmented, "Leave out cases flagged fragmented");
  fit->add_flag("--include-under-resolved", fit_opt.include_under_resolved, "Fit cases flagged under_resolved (c/(rho_i g) < 3 dx) too; by default they are left out");
  fit->add_flag("--no-store", fit_opt.no_store, "Print the table only; do not write the fits table");
  add_reading_flags(fit, fit_opt.reading, "Read only the draped window's first L_s, the ice that lay over the ramp at the start (docs/measurement.md, \"The ramp's ice\"); stored beside the window's fits as ramp_ice_*", "Read the window but its last H_i, the ice next to the outflow's face (docs/measurement.md, \"Clear of the front\"); stored beside the window's fits as clear_of_front_*");

  crevasse::PlotCommandOptions plot_opt;
  auto* plot = app.add_subcommand("plot", "Regime diagrams and spacing CDFs of a study as PNG and SVG");
  plot->add_option("db", plot_opt.db_path, "Study database")->required();
  plot->add_option("--out", plot_opt.out_dir, "Output directory")->required();
  plot->add_option("--group", plot_opt.group, "Horizontal axis (default cohesion_ratio)");
  plot->add_option("--colour-by", plot_opt.colour_by, "Marker colour/shape by this group (default thickness)");
  plot->add_option("--model", plot_opt.model, "Fit drawn: auto (broken line when warranted), single, broken, none");
  plot->add_option("--fixed-exponents", plot_opt.fixed_exponents, "As crevasse fit (default: what the fits table used)");
  plot->add_option("--fixed-depth-exponents", plot_opt.fixed_depth_exponents, "As crevasse fit");
  plot->add_option("--cdf-cases", plot_opt.cdf_cases, "Case indexes for the spacing and depth CDFs (default: up to 4 spread over the group)")->delimiter(',');
  plot->add_option("--cdf-normalise", plot_opt.cdf_normalise, "Spacing CDFs normalised by: median (of each case), thickness (H_i), bending (sqrt(c H_i/(rho_i g))), strength (c/(rho_i g)), none; the depth CDFs of the same cases are over H_i");
  plot->add_option("--add-cases", plot_opt.add_cases, "Other study databases whose cases are drawn too, not fitted (e.g. 3D cases on the 2D diagram)")->delimiter(',');
  plot->add_flag("--include-under-resolved", plot_opt.include_under_resolved, "Fit and draw under_resolved cases (c/(rho_i g) < 3 dx) like the others; by default they are drawn hollow and not fitted");
  add_reading_flags(plot, plot_opt.reading, "Read only the draped window's first L_s, the ice that lay over the ramp at the start (docs/measurement.md, \"The ramp's ice\"); figures named ramp_ice_*", "Read the window but its last H_i, the ice next to the outflow's face (docs/measurement.md, \"Clear of the front\"); figures named clear_of_front_*");
  plot->add_flag("--exclude-fragmented", plot_opt.exclude_fragmented, "Leave fragmented cases out of the drawn fit, marked on the bottom edge (default: as the fits table was made)");

  crevasse::CalibrateCommandOptions calibrate_opt;
  std::optional<double> calibrate_thickness;
  auto* calibrate = app.add_subcommand("calibrate", "Estimate the tensile strength c from an observed crevasse spacing");
  calibrate->add_option("--db", calibrate_opt.db_path, "Study database (its fits table, or fits made now)")->required();
  calibrate->add_option("--spacing", calibrate_opt.spacing_m, "Observed median crevasse spacing L_p [m]");
  calibrate->add_option("--spacing-quartiles", calibrate_opt.spacing_quartiles, "Observed spacing quartiles Q25,Q75 [m]");
  calibrate->add_option("--thickness", calibrate_thickness, "Ice thickness H_i at the site [m]");
  calibrate->add_option("--level", calibrate_opt.level, "Confidence level (default 0.95)");
  calibrate->add_option("--observations", calibrate_opt.observations_path, "Field observations file (studies/field/observations.json): every site as a table, instead of --spacing");
  calibrate->add_option("--csv", calibrate_opt.csv_path, "With --observations: write the table as CSV too");
  add_reading_flags(calibrate, calibrate_opt.reading, "Use the laws fitted to the ramp's ice (crevasse fit --ramp-ice)", "Use the laws fitted clear of the front (crevasse fit --clear-of-front)");

  crevasse::PredictCommandOptions predict_opt;
  auto* predict = app.add_subcommand("predict", "Predict crevasse spacing and depth for a tensile strength and thickness");
  predict->add_option("--db", predict_opt.db_path, "Study database (its fits table, or fits made now)")->required();
  predict->add_option("--cohesion", predict_opt.tensile_strength_pa, "Tensile strength c [Pa]")->required();
  predict->add_option("--thickness", predict_opt.thickness_m, "Ice thickness H_i [m]")->required();
  predict->add_option("--level", predict_opt.level, "Confidence level (default 0.95)");
  add_reading_flags(predict, predict_opt.reading, "Use the laws fitted to the ramp's ice (crevasse fit --ramp-ice)", "Use the laws fitted clear of the front (crevasse fit --clear-of-front)");

  crevasse::AccuracyCommandOptions accuracy_opt;
  auto* accuracy = app.add_subcommand("accuracy", "Accuracy against cost of a study over the numerics (studies/accuracy_flowing.json): table and figure");
  accuracy->add_option("db", accuracy_opt.db_path, "Study database")->required();
  accuracy->add_option("--out", accuracy_opt.out_dir, "Output directory")->required();
  accuracy->add_option("--add-cases", accuracy_opt.add_dbs, "More databases whose finished cases are added as rows <stem>:<index> (repeatable)");
  accuracy->add_option("--reference", accuracy_opt.reference_index, "Case index of the reference run (default: the finest run with a spacing)");

  // Parse errors on one line, like every other refusal.
  app.failure_message([](const CLI::App*, const CLI::Error& e) {
    return "crevasse: error: " + one_line(e.what()) + "\n";
  });

  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; }))
    for (CLI::Option* o : sub->get_options())
      if (o->get_type_name().rfind("TEXT", 0) == 0) {
        o->check(kNonEmpty);
      } else if (o->get_type_name().rfind("FLOAT", 0) == 0) {
        o->check(kFinite);
      }
  try {
    app.parse(argc, argv);
    if (*run) return crevasse::run_command(run_opt);
    if (*study) {
      for (int i = 0; i < argc; ++i) study_opt.command_line += std::string(i ? " " : "") + argv[i];
      return crevasse::study_command(study_opt);
    }
    if (*measure) return crevasse::measure_command(measure_opt);
    if (*status) return crevasse::status_command(status_opt);
    if (*export_cmd) return crevasse::export_command(export_opt);
    if (*merge) return crevasse::merge_command(merge_out, merge_in);
    if (*fit) return crevasse::fit_command(fit_opt);
    if (*plot) return crevasse::plot_command(plot_opt);
    if (*calibrate) {
      calibrate_opt.thickness_m = calibrate_thickness;
      if (calibrate_opt.observations_path.empty() && calibrate->count("--spacing") == 0)
        throw crevasse::InputError("--spacing: required (the observed median spacing in m), or give --observations FILE");
      return crevasse::calibrate_command(calibrate_opt);
    }
    if (*predict) return crevasse::predict_command(predict_opt);
    if (*accuracy) return crevasse::accuracy_command(accuracy_opt);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  } catch (const crevasse::InputError& e) {
    std::fprintf(stderr, "crevasse: error: %s\n", one_line(e.what()).c_str());
    return 2;
  } catch (const crevasse::SimulationError& e) {
    std::fprintf(stderr, "crevasse: simulation failed: %s\n", one_line(e.what()).c_str());
    return 1;
  } catch (const std::bad_alloc&) {
    crevasse::rearm_memory_reserve();
    std::fprintf(stderr, "crevasse: error: out of memory; free memory or raise the limit (ulimit -v), "
                         "then run the same command again\n");
    return 1;
  } catch (const std::system_error& e) {
    std::fprintf(stderr, "crevasse: error: the system refused a resource (%s); free memory or raise "
                         "the limits (ulimit -u, -v), then run the same command again\n",
                 one_line(e.what()).c_str());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "crevasse: error: %s\n", one_line(e.what()).c_str());
    return 1;
  }
  return 0;
}

// Output that never reached the user is an error: a full disk or a closed pipe behind stdout
// (or stderr) turns an exit code 0 into 1.
int check_streams(int code) {
  errno = 0;
  if (std::fflush(stdout) != 0 || std::ferror(stdout)) {
    const int err = errno;
    std::fprintf(stderr, "crevasse: error: writing to standard output failed (%s)\n",
                 err ? std::strerror(err) : "write error");
    if (code == 0) code = 1;
  }
  if (std::fflush(stderr) != 0 || std::ferror(stderr)) {
    if (code == 0) code = 1;
  }
  return code;
}

}  // namespace

int main(int argc, char** argv) {
  crevasse::arm_memory_reserve(16u << 20);
  return check_streams(run_command_line(argc, argv));
}

// The crevasse command line. Every error is caught here, printed on one line, and mapped to an
// exit code: 2 for bad input, 1 for a failed simulation or any other error.
#include <CLI/CLI.hpp>
#include <cstdio>
#include <exception>

#include "engine/error.hpp"
#include "study/run_command.hpp"

int main(int argc, char** argv) {
  CLI::App app{"crevasse: scaling laws of glacier fracture from MPM parameter studies"};
  app.require_subcommand(1);

  crevasse::RunCommandOptions run_opt;
  auto* run = app.add_subcommand("run", "Simulate one scene: VTU snapshots, side-view PNG, crevasse measurement");
  run->add_option("scene", run_opt.scene_path, "Scene JSON file (see README, studies/scenes/)")->required();
  run->add_option("--out", run_opt.out_dir, "Output directory")->required();
  run->add_option("--vtu-interval", run_opt.vtu_interval, "Simulated seconds between VTU snapshots (overrides the scene)");
  run->add_option("--threads", run_opt.threads, "Worker threads (default: all cores)");
  run->add_flag("--quiet", run_opt.quiet, "No progress output");

  try {
    app.parse(argc, argv);
    if (*run) return crevasse::run_command(run_opt);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  } catch (const crevasse::InputError& e) {
    std::fprintf(stderr, "crevasse: error: %s\n", e.what());
    return 2;
  } catch (const crevasse::SimulationError& e) {
    std::fprintf(stderr, "crevasse: simulation failed: %s\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "crevasse: error: %s\n", e.what());
    return 1;
  }
  return 0;
}

#pragma once
// `crevasse study FILE [--db PATH] [--jobs N] ...`: runs (or resumes) a study into its SQLite
// database, with progress on stderr.
#include <string>

namespace crevasse {

struct StudyCommandOptions {
  std::string study_path;
  std::string db_path;  // "" → results/<name>.db (results/<name>.shard-I-of-N.db with --shard)
  int jobs = 0;         // 0 → resources.jobs, else cores / threads per case
  int threads_per_case = 0;         // 0 → resources.threads_per_case, else 1
  double case_time_limit_s = -1.0;  // < 0 → resources.case_time_limit_s
  std::string shard;                // "I/N" or ""
  std::string cases;                // "--cases" list or ""
  bool fail_fast = false;
  bool retry_failed = false;
  bool dry_run = false;  // list the cases and their hashes; run nothing, create nothing
  bool quiet = false;
  std::string views_dir;  // non-empty: side views of every case run, case_NNN_side_view.png
  // Keep each case's final particles (case_NNN_particles.bin) in particles_dir, by default
  // DB.particles beside the database; a particles_dir implies keep_particles.
  bool keep_particles = false;
  std::string particles_dir;
  // Both or neither: measure the cases from the particles another study kept, with that
  // study's database for the runs' records, instead of simulating them (study/kept_runs.hpp).
  std::string remeasure_db;
  std::string particles_from;
  std::string command_line;  // recorded in the sessions table
};

// 0 when every case in scope is done; 1 when some failed or --fail-fast stopped the run.
// Throws InputError (exit 2) for a bad study file, database or option.
int study_command(const StudyCommandOptions& opt);

}  // namespace crevasse

#pragma once
// The SQLite file of one study (docs/study_format.md; schema in docs/database.md): tables study, sessions,
// cases, crevasses, summaries. WAL journal, so readers (crevasse status, sqlite3) never block the
// writer and never see a half-written case; exactly one writer, enforced by an flock on the
// database file itself (so on the file, not on the path that names it) that the kernel
// releases even when the writer is killed. Every finished case is
// written in one transaction, so a SIGKILL leaves each case either wholly stored or not at all.
#include <sqlite3.h>

#include <cstdint>
#include <filesystem>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "analysis/crevasse_measure.hpp"
#include "study/study_file.hpp"

namespace crevasse {

// 2: cases.under_resolved. A version-1 file is upgraded when a writer opens it and read as it is.
inline constexpr int kStoreSchemaVersion = 2;


// One prepared statement. Bind indices start at 1, column indices at 0.
class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql);
  ~Statement();
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;

  Statement& bind(int i, const std::string& v);
  Statement& bind(int i, const char* v) { return bind(i, std::string(v)); }
  Statement& bind(int i, double v);
  Statement& bind(int i, std::int64_t v);
  Statement& bind(int i, int v) { return bind(i, static_cast<std::int64_t>(v)); }
  Statement& bind(int i, std::nullopt_t);
  template <class T>
  Statement& bind(int i, const std::optional<T>& v) {
    return v ? bind(i, *v) : bind(i, std::nullopt);
  }
  bool step();  // true while a row is available; throws on error
  void run();   // step() to completion
  void reset();

  int columns() const;
  std::string column_name(int c) const;
  bool is_null(int c) const;
  std::string text(int c) const;  // "" for NULL
  double real(int c) const;
  std::int64_t integer(int c) const;
  std::optional<std::string> optional_text(int c) const;
  std::optional<double> optional_real(int c) const;
  // Whether column c holds a finite number (an INTEGER or REAL value): a TEXT or BLOB value, which
  // real() would read as 0, or an infinity, is not data of a numeric column.
  bool is_finite_number(int c) const;

 private:
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
  std::string sql_;
};

// Deterministic results of one finished case plus its bookkeeping.
struct CaseResult {
  std::string case_id;
  std::string status;          // "done" or "failed"
  std::string failure_reason;  // failed only
  std::string stop_reason;     // engine stop reason (done only)
  std::int64_t steps = 0;
  std::int64_t particle_steps = 0;
  double sim_time_s = 0.0;
  double wall_s = 0.0;
  std::optional<std::int64_t> peak_rss_bytes;
  int threads = 1;
  std::string started_at;  // ISO 8601 UTC
  std::string finished_at;
  std::string session_id;
  nlohmann::json run_json = nlohmann::json::object();     // masses, stage timings, particle counts
  nlohmann::json result_json = nlohmann::json::object();  // the deterministic part, hashed
  std::optional<analysis::CrevasseMeasurement> measurement;  // done only
};

struct StatusCounts {
  std::int64_t pending = 0, running = 0, done = 0, failed = 0;
  std::int64_t total() const { return pending + running + done + failed; }
};

struct SessionInfo {
  std::string session_id;  // host:pid:start-milliseconds, unique across machines
  std::string host;
  std::int64_t pid = 0;
  std::string started_at;
  int jobs = 1;
  int threads_per_case = 1;
  std::string shard;  // "I/N" or ""
  std::string command;
};

class Store {
 public:
  // Opens (creating when absent) the database as its one writer: takes the lock, sets WAL,
  // creates the schema. Throws InputError when the path is unusable or another writer still
  // holds the file after `wait_s` seconds.
  // `option` names the path in messages as the command line gave it ("--db", "OUT"; "" for none).
  static Store open_writer(const std::filesystem::path& path, double wait_s = 10.0,
                           const std::string& option = "--db");
  // Opens an existing database read-only. Throws InputError when it does not exist or is not a
  // crevasse study database.
  static Store open_reader(const std::filesystem::path& path);
  // Whether `path` is an empty file or an SQLite database with no table and user_version 0: the
  // shell a writer killed before it wrote the schema leaves, which holds nothing to keep.
  static bool is_blank(const std::filesystem::path& path);

  Store(Store&& other) noexcept;
  Store& operator=(Store&&) = delete;
  Store(const Store&) = delete;
  ~Store();

  sqlite3* handle() const { return db_; }
  int schema_version() const;  // PRAGMA user_version
  // The SQL for a cases row's under_resolved flag: the column, or in a version-1 file the rule
  // (analysis::strength_under_resolved) evaluated over the row.
  std::string under_resolved_column() const;
  const std::filesystem::path& path() const { return path_; }
  void exec(const std::string& sql);
  // Runs `body` inside BEGIN IMMEDIATE ... COMMIT; rolls back and rethrows on an exception.
  template <class F>
  void transaction(F&& body) {
    exec("BEGIN IMMEDIATE");
    try {
      body();
      exec("COMMIT");
    } catch (...) {
      sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
      throw;
    }
  }

  // Writer. On a new database writes the study row; on an existing one checks that it holds
  // the same study (same case hashes), else throws InputError.
  void init_study(const Study& study);
  void begin_session(const SessionInfo& session);
  void end_session(const std::string& session_id, const std::string& outcome,
                   std::int64_t cases_run);
  // Adds the cases not yet present as 'pending'. Cases present keep their state.
  void add_cases(const std::vector<const StudyCase*>& cases);
  // 'running' rows left by a killed run become 'pending' again; returns how many.
  std::int64_t reset_running();
  void mark_running(const std::string& case_id, const std::string& session_id,
                    const std::string& started_at, int threads);
  void mark_pending(const std::string& case_id);
  // Stores a finished case (row update, crevasses, summary) in one transaction.
  void record_result(const CaseResult& result);
  // Folds the WAL into the main file so that the .db alone is complete.
  void checkpoint();

  // Readers.
  std::map<std::string, std::string> statuses();  // case_id → status
  StatusCounts counts();
  std::optional<std::string> study_hash();

 private:
  Store(sqlite3* db, std::filesystem::path path, int lock_fd);
  sqlite3* db_ = nullptr;
  std::filesystem::path path_;
  int lock_fd_ = -1;
};

// Current UTC time as "YYYY-MM-DDTHH:MM:SS.mmmZ".
std::string utc_now_iso8601();

}  // namespace crevasse

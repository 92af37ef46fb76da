#include "study/store.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <stdexcept>
#include <vector>

#include "analysis/measurement_io.hpp"
#include "engine/error.hpp"
#include "study/case_hash.hpp"

namespace crevasse {
namespace fs = std::filesystem;

namespace {

// Schema version 1; docs/database.md describes every column.
constexpr const char* kSchema = R"SQL(
CREATE TABLE IF NOT EXISTS study (
  id INTEGER PRIMARY KEY CHECK (id = 1),
  name TEXT NOT NULL,
  description TEXT NOT NULL,
  study_hash TEXT NOT NULL,
  case_count INTEGER NOT NULL,
  file_text TEXT NOT NULL,
  base_scene_json TEXT NOT NULL,
  measurement_json TEXT NOT NULL,
  engine_version TEXT NOT NULL,
  host TEXT NOT NULL,
  started_at TEXT NOT NULL,
  ended_at TEXT
);
CREATE TABLE IF NOT EXISTS sessions (
  session_id TEXT PRIMARY KEY,
  host TEXT NOT NULL,
  pid INTEGER NOT NULL,
  started_at TEXT NOT NULL,
  ended_at TEXT,
  jobs INTEGER NOT NULL,
  threads_per_case INTEGER NOT NULL,
  shard TEXT NOT NULL,
  command TEXT NOT NULL,
  outcome TEXT,
  cases_run INTEGER
);
CREATE TABLE IF NOT EXISTS cases (
  case_id TEXT PRIMARY KEY,
  case_index INTEGER NOT NULL,
  label TEXT NOT NULL,
  replica INTEGER NOT NULL,
  status TEXT NOT NULL CHECK (status IN ('pending', 'running', 'done', 'failed')),
  thickness_m REAL NOT NULL,
  cohesion_ratio REAL NOT NULL,
  step_length_ratio REAL NOT NULL,
  step_height_ratio REAL NOT NULL,
  slope REAL,
  width_ratio REAL,
  tensile_strength_pa REAL NOT NULL,
  step_length_m REAL NOT NULL,
  step_height_m REAL NOT NULL,
  width_m REAL,
  dx_m REAL NOT NULL,
  dim INTEGER NOT NULL,
  seed INTEGER NOT NULL,
  axes_json TEXT NOT NULL,
  scene_json TEXT NOT NULL,
  engine_version TEXT NOT NULL,
  attempts INTEGER NOT NULL DEFAULT 0,
  session_id TEXT,
  started_at TEXT,
  finished_at TEXT,
  failure_reason TEXT,
  stop_reason TEXT,
  wall_s REAL,
  peak_rss_bytes INTEGER,
  threads INTEGER,
  steps INTEGER,
  particle_steps INTEGER,
  sim_time_s REAL,
  run_json TEXT,
  result_json TEXT,
  result_hash TEXT,
  under_resolved INTEGER NOT NULL DEFAULT 0
);
CREATE INDEX IF NOT EXISTS cases_by_status ON cases(status);
CREATE TABLE IF NOT EXISTS crevasses (
  case_id TEXT NOT NULL REFERENCES cases(case_id),
  crevasse_index INTEGER NOT NULL,
  x_m REAL NOT NULL,
  surface_z_m REAL NOT NULL,
  bottom_z_m REAL NOT NULL,
  depth_m REAL NOT NULL,
  depth_over_h REAL NOT NULL,
  width_m REAL NOT NULL,
  spacing_to_next_m REAL,
  spacing_over_h REAL,
  particle_count INTEGER NOT NULL,
  merged_count INTEGER NOT NULL,
  PRIMARY KEY (case_id, crevasse_index)
);
CREATE TABLE IF NOT EXISTS summaries (
  case_id TEXT PRIMARY KEY REFERENCES cases(case_id),
  measurement_time_s REAL NOT NULL,
  crevasse_count INTEGER NOT NULL,
  spacing_count INTEGER NOT NULL,
  dropped_spacing_count INTEGER NOT NULL,
  spacing_q25_m REAL, spacing_median_m REAL, spacing_q75_m REAL,
  spacing_q25_over_h REAL, spacing_median_over_h REAL, spacing_q75_over_h REAL,
  depth_q25_m REAL, depth_median_m REAL, depth_q75_m REAL,
  depth_q25_over_h REAL, depth_median_over_h REAL, depth_q75_over_h REAL,
  window_min_x_m REAL NOT NULL,
  window_max_x_m REAL NOT NULL,
  particle_count INTEGER NOT NULL,
  window_particle_count INTEGER NOT NULL,
  damaged_particle_count INTEGER NOT NULL,
  cluster_count INTEGER NOT NULL,
  no_crevasse INTEGER NOT NULL,
  fragmented INTEGER NOT NULL,
  has_spacing INTEGER NOT NULL,
  empty_window INTEGER NOT NULL,
  empty_snapshot INTEGER NOT NULL,
  spacings_json TEXT NOT NULL,
  settings_json TEXT NOT NULL
);
)SQL";

// A failed write (full disk, file-size limit, lost write permission) surfaces as FULL or IOERR,
// a file another process holds past the busy timeout as BUSY or LOCKED: ResourceError with the
// path and what to do. The transaction is rolled back, so what was stored stays whole and the
// same command continues. Anything else is an error of this program.
[[noreturn]] void sql_fail(sqlite3* db, int rc, const std::string& what) {
  const std::string path = db && sqlite3_db_filename(db, "main") ? sqlite3_db_filename(db, "main") : "";
  const std::string msg = db ? sqlite3_errmsg(db) : "out of memory";
  const std::string head = "database " + (path.empty() ? std::string("(in memory)") : path) + ": " + msg +
                           " (while running '" + what + "')";
  switch (rc & 0xff) {
    case SQLITE_FULL:
    case SQLITE_IOERR:
    case SQLITE_READONLY:
    case SQLITE_CANTOPEN:
      throw ResourceError(head + "; the disk may be full or the file not writable: free space or fix the path, then "
                                 "run the same command again to resume (what is stored is kept)");
    case SQLITE_BUSY:
    case SQLITE_LOCKED:
      throw ResourceError(head + "; another process holds the database: wait for it to finish, then run the "
                                 "same command again");
    default:
      throw std::runtime_error(head);
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------------
Statement::Statement(sqlite3* db, const std::string& sql) : db_(db), sql_(sql) {
  if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &stmt_, nullptr) != SQLITE_OK)
    sql_fail(db_, sqlite3_errcode(db_), sql.substr(0, 60));
}
Statement::~Statement() { sqlite3_finalize(stmt_); }

Statement& Statement::bind(int i, const std::string& v) {
  if (sqlite3_bind_text(stmt_, i, v.data(), static_cast<int>(v.size()), SQLITE_TRANSIENT) !=
      SQLITE_OK)
    sql_fail(db_, sqlite3_errcode(db_), "bind");
  return *this;
}
Statement& Statement::bind(int i, double v) {
  if (sqlite3_bind_double(stmt_, i, v) != SQLITE_OK) sql_fail(db_, sqlite3_errcode(db_), "bind");
  return *this;
}
Statement& Statement::bind(int i, std::int64_t v) {
  if (sqlite3_bind_int64(stmt_, i, v) != SQLITE_OK) sql_fail(db_, sqlite3_errcode(db_), "bind");
  return *this;
}
Statement& Statement::bind(int i, std::nullopt_t) {
  if (sqlite3_bind_null(stmt_, i) != SQLITE_OK) sql_fail(db_, sqlite3_errcode(db_), "bind");
  return *this;
}
bool Statement::step() {
  const int rc = sqlite3_step(stmt_);
  if (rc == SQLITE_ROW) return true;
  if (rc == SQLITE_DONE) return false;
  sql_fail(db_, rc, sql_.substr(0, 60));
}
void Statement::run() {
  while (step()) {
  }
  reset();
}
void Statement::reset() {
  sqlite3_reset(stmt_);
  sqlite3_clear_bindings(stmt_);
}
int Statement::columns() const { return sqlite3_column_count(stmt_); }
std::string Statement::column_name(int c) const { return sqlite3_column_name(stmt_, c); }
bool Statement::is_null(int c) const { return sqlite3_column_type(stmt_, c) == SQLITE_NULL; }
std::string Statement::text(int c) const {
  const auto* p = sqlite3_column_text(stmt_, c);
  return p ? std::string(reinterpret_cast<const char*>(p),
                         static_cast<std::size_t>(sqlite3_column_bytes(stmt_, c)))
           : std::string();
}
double Statement::real(int c) const { return sqlite3_column_double(stmt_, c); }
std::int64_t Statement::integer(int c) const { return sqlite3_column_int64(stmt_, c); }
std::optional<std::string> Statement::optional_text(int c) const {
  return is_null(c) ? std::nullopt : std::optional<std::string>(text(c));
}
bool Statement::is_finite_number(int c) const {
  const int type = sqlite3_column_type(stmt_, c);
  return (type == SQLITE_INTEGER || type == SQLITE_FLOAT) && std::isfinite(real(c));
}
std::optional<double> Statement::optional_real(int c) const {
  return is_null(c) ? std::nullopt : std::optional<double>(real(c));
}

// ---------------------------------------------------------------------------------------------
std::string utc_now_iso8601() {
  const auto now = std::chrono::system_clock::now();
  const std::time_t t = std::chrono::system_clock::to_time_t(now);
  const auto ms =
      std::chrono::duration_cast<std::chrono::milliseconds>(now.time_since_epoch()).count() % 1000;
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%04d-%02d-%02dT%02d:%02d:%02d.%03dZ", tm.tm_year + 1900,
                tm.tm_mon + 1, tm.tm_mday, tm.tm_hour, tm.tm_min, tm.tm_sec, static_cast<int>(ms));
  return buf;
}

Store::Store(sqlite3* db, fs::path path, int lock_fd)
    : db_(db), path_(std::move(path)), lock_fd_(lock_fd) {}

Store::Store(Store&& o) noexcept : db_(o.db_), path_(std::move(o.path_)), lock_fd_(o.lock_fd_) {
  o.db_ = nullptr;
  o.lock_fd_ = -1;
}

Store::~Store() {
  if (db_) sqlite3_close_v2(db_);
  if (lock_fd_ >= 0) ::close(lock_fd_);  // releases the flock
}

void Store::exec(const std::string& sql) {
  char* err = nullptr;
  if (const int rc = sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &err); rc != SQLITE_OK) {
    sqlite3_free(err);  // sqlite3_errmsg says the same
    sql_fail(db_, rc, sql.substr(0, 40));
  }
}

namespace {

// analysis::strength_under_resolved over a cases row, for files written before the column.
std::string under_resolved_rule_sql() {
  char floor[64];
  std::snprintf(floor, sizeof floor, "%.17g",
                analysis::kStrengthLengthMinCells * (1.0 - analysis::kStrengthFloorTolerance));
  return "(tensile_strength_pa / (json_extract(scene_json, '$.ice.density') * "
         "json_extract(scene_json, '$.gravity.g')) < " + std::string(floor) + " * dx_m)";
}

int read_user_version(sqlite3* db) {
  Statement s(db, "PRAGMA user_version");
  return s.step() ? static_cast<int>(s.integer(0)) : 0;
}

std::int64_t table_count(sqlite3* db) {
  Statement s(db, "SELECT count(*) FROM sqlite_master WHERE type = 'table'");
  return s.step() ? s.integer(0) : 0;
}

// Every schema version has these tables; another program's database, whatever its user_version,
// lacks at least one.
bool has_study_tables(sqlite3* db) {
  Statement s(db, "SELECT count(*) FROM sqlite_master WHERE type = 'table' AND name IN "
                  "('study', 'sessions', 'cases', 'crevasses', 'summaries')");
  return s.step() && s.integer(0) == 5;
}

}  // namespace

Store Store::open_writer(const fs::path& path, double wait_s, const std::string& option) {
  const std::string where = (option.empty() ? "" : option + " ") + path.string();
  std::error_code ec;
  if (fs::exists(path, ec) && !fs::is_regular_file(path, ec))  // follows symbolic links
    throw InputError(where + ": not a regular file; a study database is an ordinary file");
  // What this call creates is removed again when it refuses, so the file system is left as
  // found; only what it created (O_EXCL says so) and, for the file, only while it holds the
  // lock, so another process's new database is never removed.
  std::vector<fs::path> created_dirs;  // deepest first
  for (fs::path p = path.parent_path(); !p.empty() && !fs::exists(p, ec); p = p.parent_path())
    created_dirs.push_back(p);
  if (!created_dirs.empty()) {
    fs::create_directories(path.parent_path(), ec);
    if (ec)
      throw InputError(where + ": cannot create directory " + path.parent_path().string() + " (" +
                       ec.message() + ")");
  }
  bool created = false, locked = false;
  const auto undo = [&] {
    if (created && locked) fs::remove(path, ec);
    for (const fs::path& d : created_dirs) fs::remove(d, ec);  // only while empty
  };
  int fd = ::open(path.c_str(), O_RDWR | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  created = fd >= 0;
  if (!created && errno == EEXIST) fd = ::open(path.c_str(), O_RDWR | O_CLOEXEC);
  if (fd < 0) {
    const std::string why = std::strerror(errno);
    undo();
    throw InputError(where + ": cannot open (" + why + ")");
  }
  // One writer per file, whatever path names it: the flock is on the database file itself, so a
  // symbolic or hard link to it meets the same lock. (SQLite's own locks are POSIX record locks,
  // which do not interact with flock on Linux.) Readers hold a shared lock for a moment while no
  // writer runs, so a writer waits up to 10 s before it gives up.
  for (int tries = 0; !locked; ++tries) {
    locked = ::flock(fd, LOCK_EX | LOCK_NB) == 0;
    if (locked || errno != EWOULDBLOCK || tries >= wait_s * 10.0) break;
    ::usleep(100000);
  }
  if (!locked) {
    undo();
    ::close(fd);
    throw ResourceError(where +
                        ": another crevasse process is writing to this database (the file is "
                        "locked); wait for it to end and run the same command again" +
                        (option == "--db" ? std::string(", or use another --db") : std::string()));
  }
  sqlite3* db = nullptr;
  if (sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr) !=
      SQLITE_OK) {
    const std::string msg = db ? sqlite3_errmsg(db) : "out of memory";
    sqlite3_close_v2(db);
    undo();
    ::close(fd);
    throw InputError(where + ": cannot open the database (" + msg + ")");
  }
  Store store(db, path, fd);
  sqlite3_busy_timeout(db, 10000);
  try {
    // Decided on reads alone, before the WAL switch (which rewrites the header): a file that is
    // not a study database stays as it was.
    int version = 0;
    try {
      version = read_user_version(db);
    } catch (const std::runtime_error& e) {
      throw InputError(where + ": not an SQLite database, so not a crevasse study database (" + e.what() + ")");
    }
    const bool empty = table_count(db) == 0;
    if (empty ? version != 0 : version == 0 || !has_study_tables(db))
      throw InputError(where +
                       ": this file is an SQLite database but not a crevasse study database");
    if (version > kStoreSchemaVersion)
      throw InputError(where + ": schema version " + std::to_string(version) +
                       " was written by a newer crevasse (this one reads " +
                       std::to_string(kStoreSchemaVersion) + ")");
    {
      Statement wal(db, "PRAGMA journal_mode = WAL");
      if (!wal.step() || wal.text(0) != "wal")
        throw InputError(
            where +
            ": the database cannot use the WAL journal (is the file system local and writable?)");
    }
    store.exec("PRAGMA synchronous = FULL");
    store.exec("PRAGMA foreign_keys = ON");
    if (version != kStoreSchemaVersion) store.transaction([&] {
      if (version == 1) {
        store.exec("ALTER TABLE cases ADD COLUMN under_resolved INTEGER NOT NULL DEFAULT 0");
        store.exec("UPDATE cases SET under_resolved = " + under_resolved_rule_sql());
      }
      store.exec(kSchema);
      store.exec("PRAGMA user_version = " + std::to_string(kStoreSchemaVersion));
    });
    // The flag is derived from the row: a file written under an older rule is brought up to
    // the current one, so fits and diagrams never leave out a case the rule keeps.
    if (version >= 2) {
      const std::string rule = under_resolved_rule_sql();
      store.exec("UPDATE cases SET under_resolved = " + rule + " WHERE under_resolved != " + rule);
    }
  } catch (const std::runtime_error& e) {
    const bool resource = dynamic_cast<const ResourceError*>(&e) != nullptr;
    const std::string message = dynamic_cast<const InputError*>(&e) || resource
                                    ? std::string(e.what())
                                    : where + ": cannot write the database (" + e.what() + ")";
    if (created) {  // a database this call began (full disk, no file descriptors): none at all
      sqlite3_close_v2(store.db_);
      store.db_ = nullptr;
      for (const char* suffix : {"-wal", "-shm", "-journal"}) fs::remove(path.string() + suffix, ec);
      undo();  // still under the lock, which the store releases after
    }
    if (resource) throw ResourceError(message);
    throw InputError(message);
  }
  return store;
}

Store Store::open_reader(const fs::path& path) {
  const std::string where = path.string();
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(where + ": no such database");
  // A FIFO or device would block the open or the first read forever.
  if (!fs::is_regular_file(path, ec))
    throw InputError(where + ": not a regular file; a study database is an ordinary file");
  // With no writer (the shared lock is granted) and no WAL left by a killed one, the file is
  // read as immutable: nothing is created beside it (-wal, -shm), and the shared lock, held
  // until the reader closes, keeps a writer from starting meanwhile. With a writer running,
  // it is read through the writer's WAL as usual.
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw InputError(where + ": cannot open (" + std::strerror(errno) + ")");
  const fs::path wal = path.string() + "-wal";
  const bool quiet = ::flock(fd, LOCK_SH | LOCK_NB) == 0 &&
                     (!fs::exists(wal, ec) || fs::file_size(wal, ec) == 0);
  if (!quiet) {
    ::close(fd);
    fd = -1;
  }
  std::string uri = "file:";
  for (const unsigned char c : fs::absolute(path, ec).string()) {
    if (std::isalnum(c) || c == '/' || c == '.' || c == '-' || c == '_') {
      uri += static_cast<char>(c);
    } else {
      char hex[4];
      std::snprintf(hex, sizeof hex, "%%%02X", c);
      uri += hex;
    }
  }
  if (quiet) uri += "?immutable=1";
  sqlite3* db = nullptr;
  if (sqlite3_open_v2(uri.c_str(), &db, SQLITE_OPEN_READONLY | SQLITE_OPEN_URI, nullptr) !=
      SQLITE_OK) {
    const std::string msg = db ? sqlite3_errmsg(db) : "out of memory";
    sqlite3_close_v2(db);
    if (fd >= 0) ::close(fd);
    throw InputError(where + ": cannot open the database (" + msg + ")");
  }
  Store store(db, path, fd);
  sqlite3_busy_timeout(db, 10000);
  int version = 0;
  try {
    version = read_user_version(db);
  } catch (const std::runtime_error& e) {
    throw InputError(where + ": not an SQLite database, so not a crevasse study database (" + e.what() + ")");
  }
  if (version >= 1 && version <= kStoreSchemaVersion && !has_study_tables(db))
    throw InputError(where + ": not a crevasse study database (it lacks a study's tables)");
  if (version < 1 || version > kStoreSchemaVersion)
    throw InputError(where + ": not a crevasse study database of schema version 1 to " +
                     std::to_string(kStoreSchemaVersion) + " (found " + std::to_string(version) +
                     ")");
  return store;
}

bool Store::is_blank(const fs::path& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) return false;
  if (fs::file_size(path, ec) == 0 && !ec) return true;
  sqlite3* db = nullptr;
  bool blank = false;
  if (sqlite3_open_v2(path.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) == SQLITE_OK) {
    try {
      blank = read_user_version(db) == 0 && table_count(db) == 0;
    } catch (const std::exception&) {
      blank = false;  // not SQLite: not ours to replace
    }
  }
  sqlite3_close_v2(db);
  return blank;
}

int Store::schema_version() const { return read_user_version(db_); }

std::string Store::under_resolved_column() const {
  return schema_version() >= 2 ? "under_resolved" : under_resolved_rule_sql();
}

std::optional<std::string> Store::study_hash() {
  Statement s(db_, "SELECT study_hash FROM study WHERE id = 1");
  if (!s.step()) return std::nullopt;
  return s.text(0);
}

void Store::init_study(const Study& study) {
  if (const auto stored = study_hash()) {
    if (*stored != study.study_hash) {
      Statement s(db_, "SELECT name, case_count FROM study WHERE id = 1");
      s.step();
      throw InputError("--db " + path_.string() + ": holds study '" + s.text(0) + "' (" +
                       std::to_string(s.integer(1)) +
                       " cases) with other parameters or engine version than '" + study.name +
                       "' (" + std::to_string(study.cases.size()) +
                       " cases); use another --db for the changed study");
    }
    return;
  }
  char host[256] = "unknown";
  gethostname(host, sizeof host - 1);
  Statement s(db_,
              "INSERT INTO study (id, name, description, study_hash, case_count, file_text, "
              "base_scene_json, "
              "measurement_json, engine_version, host, started_at) VALUES (1, ?, ?, ?, ?, ?, ?, ?, "
              "?, ?, ?)");
  s.bind(1, study.name)
      .bind(2, study.description)
      .bind(3, study.study_hash)
      .bind(4, static_cast<std::int64_t>(study.cases.size()))
      .bind(5, study.source_text)
      .bind(6, study.base_scene.dump())
      .bind(7, study.measurement_json.dump())
      .bind(8, std::string(CREVASSE_ENGINE_VERSION))
      .bind(9, std::string(host))
      .bind(10, utc_now_iso8601());
  s.run();
}

void Store::begin_session(const SessionInfo& x) {
  Statement s(db_,
              "INSERT INTO sessions (session_id, host, pid, started_at, jobs, threads_per_case, "
              "shard, command) "
              "VALUES (?, ?, ?, ?, ?, ?, ?, ?)");
  s.bind(1, x.session_id).bind(2, x.host).bind(3, x.pid).bind(4, x.started_at).bind(5, x.jobs);
  s.bind(6, x.threads_per_case).bind(7, x.shard).bind(8, x.command);
  s.run();
}

void Store::end_session(const std::string& session_id, const std::string& outcome,
                        std::int64_t cases_run) {
  const std::string now = utc_now_iso8601();
  transaction([&] {
    Statement s(
        db_, "UPDATE sessions SET ended_at = ?, outcome = ?, cases_run = ? WHERE session_id = ?");
    s.bind(1, now).bind(2, outcome).bind(3, cases_run).bind(4, session_id);
    s.run();
    Statement e(db_, "UPDATE study SET ended_at = ? WHERE id = 1");
    e.bind(1, now);
    e.run();
  });
}

void Store::add_cases(const std::vector<const StudyCase*>& cases) {
  transaction([&] {
    Statement s(
        db_,
        "INSERT OR IGNORE INTO cases (case_id, case_index, label, replica, status, thickness_m, "
        "cohesion_ratio, step_length_ratio, step_height_ratio, slope, width_ratio, "
        "tensile_strength_pa, "
        "step_length_m, step_height_m, width_m, dx_m, dim, seed, axes_json, scene_json, "
        "engine_version, under_resolved) "
        "VALUES (?, ?, ?, ?, 'pending', ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
    for (const StudyCase* c : cases) {
      const SceneConfig& sc = c->scene;
      s.bind(1, c->case_id)
          .bind(2, static_cast<std::int64_t>(c->index))
          .bind(3, c->label)
          .bind(4, c->replica);
      s.bind(5, c->groups.thickness_m)
          .bind(6, c->groups.cohesion_ratio)
          .bind(7, c->groups.step_length_ratio);
      s.bind(8, c->groups.step_height_ratio)
          .bind(9, c->groups.slope)
          .bind(10, c->groups.width_ratio);
      s.bind(11, sc.tensile_strength).bind(12, sc.step_length).bind(13, sc.step_height);
      s.bind(14, sc.dim == 3 ? std::optional<double>(sc.width) : std::nullopt);
      s.bind(15, sc.dx).bind(16, sc.dim).bind(17, static_cast<std::int64_t>(sc.seed));
      s.bind(18, c->axes.dump())
          .bind(19, c->scene_json.dump())
          .bind(20, std::string(CREVASSE_ENGINE_VERSION));
      s.bind(21, analysis::strength_under_resolved(sc.tensile_strength, sc.density, sc.gravity,
                                                   sc.dx)
                     ? 1
                     : 0);
      s.run();
    }
  });
}

std::int64_t Store::reset_running() {
  exec("UPDATE cases SET status = 'pending' WHERE status = 'running'");
  return sqlite3_changes(db_);
}

void Store::mark_running(const std::string& case_id, const std::string& session_id,
                         const std::string& started_at, int threads) {
  Statement s(db_,
              "UPDATE cases SET status = 'running', session_id = ?, started_at = ?, threads = ?, "
              "attempts = attempts + 1 WHERE case_id = ?");
  s.bind(1, session_id).bind(2, started_at).bind(3, threads).bind(4, case_id);
  s.run();
}

void Store::mark_pending(const std::string& case_id) {
  Statement s(db_, "UPDATE cases SET status = 'pending' WHERE case_id = ? AND status = 'running'");
  s.bind(1, case_id);
  s.run();
}

void Store::record_result(const CaseResult& r) {
  const std::string result_text = r.result_json.dump();
  transaction([&] {
    Statement u(db_,
                "UPDATE cases SET status = ?, failure_reason = ?, stop_reason = ?, session_id = ?, "
                "started_at = ?, "
                "finished_at = ?, wall_s = ?, peak_rss_bytes = ?, threads = ?, steps = ?, "
                "particle_steps = ?, "
                "sim_time_s = ?, run_json = ?, result_json = ?, result_hash = ? WHERE case_id = ?");
    u.bind(1, r.status);
    u.bind(2, r.status == "failed" ? std::optional<std::string>(r.failure_reason) : std::nullopt);
    u.bind(3, r.stop_reason.empty() ? std::nullopt : std::optional<std::string>(r.stop_reason));
    u.bind(4, r.session_id).bind(5, r.started_at).bind(6, r.finished_at).bind(7, r.wall_s);
    u.bind(8, r.peak_rss_bytes).bind(9, r.threads).bind(10, r.steps).bind(11, r.particle_steps);
    u.bind(12, r.sim_time_s).bind(13, r.run_json.dump()).bind(14, result_text);
    u.bind(15, sha256_hex(result_text)).bind(16, r.case_id);
    u.run();
    if (sqlite3_changes(db_) != 1)
      throw std::runtime_error("database: case " + r.case_id + " is not in the cases table");
    Statement dc(db_, "DELETE FROM crevasses WHERE case_id = ?");
    dc.bind(1, r.case_id);
    dc.run();
    Statement ds(db_, "DELETE FROM summaries WHERE case_id = ?");
    ds.bind(1, r.case_id);
    ds.run();
    if (!r.measurement) return;
    const analysis::CrevasseMeasurement& m = *r.measurement;
    const double h = m.settings.ice_thickness_m;
    Statement ic(db_,
                 "INSERT INTO crevasses (case_id, crevasse_index, x_m, surface_z_m, bottom_z_m, "
                 "depth_m, depth_over_h, "
                 "width_m, spacing_to_next_m, spacing_over_h, particle_count, merged_count) "
                 "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?)");
    for (std::size_t i = 0; i < m.crevasses.size(); ++i) {
      const analysis::Crevasse& c = m.crevasses[i];
      ic.bind(1, r.case_id)
          .bind(2, static_cast<std::int64_t>(i))
          .bind(3, c.x_m)
          .bind(4, c.surface_z_m);
      ic.bind(5, c.bottom_z_m)
          .bind(6, c.depth_m)
          .bind(7, h > 0 ? c.depth_m / h : 0.0)
          .bind(8, c.width_m);
      ic.bind(9, c.spacing_to_next_m);
      ic.bind(10, c.spacing_to_next_m && h > 0 ? std::optional<double>(*c.spacing_to_next_m / h)
                                               : std::nullopt);
      ic.bind(11, static_cast<std::int64_t>(c.particle_count))
          .bind(12, static_cast<std::int64_t>(c.merged_count));
      ic.run();
    }
    auto q = [](const std::optional<analysis::QuartileSummary>& s,
                int which) -> std::optional<double> {
      if (!s) return std::nullopt;
      return which == 0 ? s->q25 : which == 1 ? s->median : s->q75;
    };
    Statement is(
        db_,
        "INSERT INTO summaries (case_id, measurement_time_s, crevasse_count, spacing_count, "
        "dropped_spacing_count, spacing_q25_m, spacing_median_m, spacing_q75_m, "
        "spacing_q25_over_h, "
        "spacing_median_over_h, spacing_q75_over_h, depth_q25_m, depth_median_m, depth_q75_m, "
        "depth_q25_over_h, depth_median_over_h, depth_q75_over_h, window_min_x_m, window_max_x_m, "
        "particle_count, window_particle_count, damaged_particle_count, cluster_count, "
        "no_crevasse, "
        "fragmented, has_spacing, empty_window, empty_snapshot, spacings_json, settings_json) "
        "VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, ?, "
        "?, ?, ?)");
    int k = 0;
    auto add = [&](const auto& v) { is.bind(++k, v); };
    add(r.case_id);
    add(m.time_s);
    add(static_cast<std::int64_t>(m.crevasses.size()));
    add(static_cast<std::int64_t>(m.spacings_m.size()));
    add(static_cast<std::int64_t>(m.dropped_spacing_count));
    for (const auto* s : {&m.spacing_m, &m.spacing_over_h, &m.depth_m, &m.depth_over_h})
      for (int w = 0; w < 3; ++w) add(q(*s, w));
    add(m.settings.window_min_x_m);
    add(m.settings.window_max_x_m);
    for (std::size_t n :
         {m.particle_count, m.window_particle_count, m.damaged_particle_count, m.cluster_count})
      add(static_cast<std::int64_t>(n));
    for (bool b : {m.flags.no_crevasse, m.flags.fragmented, m.flags.has_spacing,
                   m.flags.empty_window, m.flags.empty_snapshot})
      add(static_cast<int>(b));
    add(nlohmann::json(m.spacings_m).dump());
    add(analysis::settings_to_json(m.settings).dump());
    is.run();
  });
}

void Store::checkpoint() { exec("PRAGMA wal_checkpoint(TRUNCATE)"); }

std::map<std::string, std::string> Store::statuses() {
  std::map<std::string, std::string> out;
  Statement s(db_, "SELECT case_id, status FROM cases");
  while (s.step()) out[s.text(0)] = s.text(1);
  return out;
}

StatusCounts Store::counts() {
  StatusCounts c;
  Statement s(db_, "SELECT status, count(*) FROM cases GROUP BY status");
  while (s.step()) {
    const std::string st = s.text(0);
    const std::int64_t n = s.integer(1);
    if (st == "pending")
      c.pending = n;
    else if (st == "running")
      c.running = n;
    else if (st == "done")
      c.done = n;
    else if (st == "failed")
      c.failed = n;
  }
  return c;
}

}  // namespace crevasse

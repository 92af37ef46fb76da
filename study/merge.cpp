#include "study/merge.hpp"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <map>
#include <optional>

#include "engine/atomic_file.hpp"
#include "engine/error.hpp"
#include "study/store.hpp"

namespace crevasse {
namespace fs = std::filesystem;

namespace {

struct CaseState {
  std::string status;
  std::string result_hash;
  std::string label;
};

std::map<std::string, CaseState> case_states(Store& store, const std::string& schema) {
  std::map<std::string, CaseState> out;
  Statement s(store.handle(),
              "SELECT case_id, status, coalesce(result_hash, ''), label FROM " + schema + ".cases");
  while (s.step()) out[s.text(0)] = {s.text(1), s.text(2), s.text(3)};
  return out;
}

bool finished(const std::string& status) { return status == "done" || status == "failed"; }

void copy_case(Store& store, const std::string& case_id) {
  for (const char* table : {"crevasses", "summaries", "cases"}) {
    Statement d(store.handle(), std::string("DELETE FROM main.") + table + " WHERE case_id = ?");
    d.bind(1, case_id);
    d.run();
  }
  for (const char* table : {"cases", "crevasses", "summaries"}) {
    Statement i(store.handle(), std::string("INSERT INTO main.") + table + " SELECT * FROM src." +
                                    table + " WHERE case_id = ?");
    i.bind(1, case_id);
    i.run();
  }
  Statement p(store.handle(),
              "UPDATE main.cases SET status = 'pending' WHERE case_id = ? AND status = 'running'");
  p.bind(1, case_id);
  p.run();
}

// Merges each input into `store` (OUT, or the file that becomes OUT), one transaction per input.
void merge_inputs(Store& store, const fs::path& out, const std::vector<fs::path>& inputs, MergeReport& report) {
  for (const auto& in : inputs) {
    {
      Statement a(store.handle(), "ATTACH DATABASE ? AS src");
      a.bind(1, in.string());
      a.run();
    }
    try {
      std::optional<std::string> src_hash, src_name;
      {
        Statement s(store.handle(), "SELECT study_hash, name FROM src.study WHERE id = 1");
        if (s.step()) {
          src_hash = s.text(0);
          src_name = s.text(1);
        }
      }
      if (!src_hash) throw InputError(in.string() + ": holds no study (was it ever run?)");
      store.transaction([&] {
        if (const auto mine = store.study_hash()) {
          if (*mine != *src_hash) {
            Statement s(store.handle(), "SELECT name FROM main.study WHERE id = 1");
            s.step();
            throw InputError(in.string() + ": holds study '" + *src_name + "', not the study '" +
                             s.text(0) + "' already in " + out.string() +
                             " (other cases or engine version); merge only "
                             "databases of one study");
          }
          store.exec(
              "UPDATE main.study SET ended_at = (SELECT nullif(max(coalesce(a.ended_at, ''), "
              "coalesce(b.ended_at, '')), '') "
              "FROM main.study a, src.study b) WHERE id = 1");
        } else {
          store.exec("INSERT INTO main.study SELECT * FROM src.study");
        }
        store.exec("INSERT OR IGNORE INTO main.sessions SELECT * FROM src.sessions");
        const auto mine = case_states(store, "main");
        const auto theirs = case_states(store, "src");
        for (const auto& [id, src] : theirs) {
          const auto it = mine.find(id);
          if (it == mine.end() || (!finished(it->second.status) && finished(src.status))) {
            copy_case(store, id);
            ++report.copied;
            continue;
          }
          const CaseState& dst = it->second;
          if (!finished(src.status)) continue;  // nothing to add
          if (dst.status == src.status && dst.result_hash == src.result_hash) {
            ++report.identical;
            continue;
          }
          ++report.conflicts;
          std::string line = "case " + id.substr(0, 12) + " (" + src.label +
                             "): " + out.filename().string() + " has " + dst.status + " (result " +
                             dst.result_hash.substr(0, 12) + "), " + in.filename().string() +
                             " has " + src.status + " (result " + src.result_hash.substr(0, 12) +
                             ")";
          if (dst.status == "failed" && src.status == "done") {
            copy_case(store, id);
            line += "; kept the finished result from " + in.filename().string();
          } else {
            line += "; kept " + out.filename().string() + "'s";
          }
          report.conflict_lines.push_back(line);
        }
      });
    } catch (...) {
      sqlite3_exec(store.handle(), "DETACH DATABASE src", nullptr, nullptr, nullptr);
      throw;
    }
    store.exec("DETACH DATABASE src");
    ++report.inputs;
  }
}

// Serialises the merges into one folder: held while a merge looks at OUT and writes it, so that
// two merges into one new OUT never both decide to create it.
class FolderLock {
 public:
  explicit FolderLock(const fs::path& dir) {
    fd_ = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
    if (fd_ < 0) throw InputError("merge: OUT: cannot open the folder " + dir.string() + " (" + std::strerror(errno) + ")");
    while (::flock(fd_, LOCK_EX) != 0 && errno == EINTR) {
    }
  }
  FolderLock(const FolderLock&) = delete;
  FolderLock& operator=(const FolderLock&) = delete;
  ~FolderLock() { ::close(fd_); }  // releases the flock

 private:
  int fd_ = -1;
};

}  // namespace

MergeReport merge_databases(const fs::path& out, const std::vector<fs::path>& inputs) {
  if (inputs.empty()) throw InputError("merge: give at least one input database");
  std::error_code ec;
  for (const auto& in : inputs) {
    if (fs::exists(out) && fs::equivalent(in, out, ec))
      throw InputError("merge: input " + in.string() +
                       " is the output database; give a new OUT path");
  }
  // Every input is checked before OUT is opened, so a refusal writes nothing: each exists, is a
  // study database of this schema (the tables are copied column by column), and all hold one
  // study, the one already in OUT if OUT exists.
  std::optional<std::string> study;
  std::string study_from;
  const auto same_study = [&](const fs::path& db, bool output) {
    Store reader = Store::open_reader(db);
    if (reader.schema_version() != kStoreSchemaVersion)
      throw InputError("merge: " + db.string() + " was written by an older crevasse (schema " +
                       "version 1); resume its study once with this crevasse to upgrade it");
    const std::optional<std::string> hash = reader.study_hash();
    if (!hash) {
      if (output) return;
      throw InputError("merge: " + db.string() + ": holds no study (was it ever run?)");
    }
    if (study && *study != *hash)
      throw InputError("merge: " + db.string() + " holds another study than " + study_from +
                       " (other cases or engine version); merge only databases of one study");
    study = hash;
    study_from = db.string();
  };
  for (const auto& in : inputs) same_study(in, false);
  const fs::path folder = out.has_parent_path() ? out.parent_path() : fs::path(".");
  fs::create_directories(folder, ec);
  const FolderLock lock(folder);
  MergeReport report;
  // A new OUT (or the blank shell a killed merge or study left) is built beside it and renamed
  // into place once whole: a kill or a full disk leaves no OUT, never a partial one.
  const bool fresh = !fs::exists(fs::symlink_status(out, ec)) || Store::is_blank(out);
  if (!fresh) {
    same_study(out, true);
    Store store = Store::open_writer(out, 10.0, "merge: OUT");
    merge_inputs(store, out, inputs, report);
    store.checkpoint();
    return report;
  }
  AtomicFile file(out);
  const auto remove_temp = [&] {
    for (const char* suffix : {"-wal", "-shm", "-journal"}) fs::remove(file.temp_path().string() + suffix, ec);
  };
  try {
    {
      Store store = Store::open_writer(file.temp_path(), 10.0, "merge: OUT");
      merge_inputs(store, out, inputs, report);
      store.checkpoint();
    }  // closed: the last connection folds the WAL into the file and removes it
    remove_temp();
    // A blank shell's WAL and shared memory belong to it, not to the new file.
    for (const char* suffix : {"-wal", "-shm"}) fs::remove(out.string() + suffix, ec);
    file.commit();
  } catch (const std::runtime_error& e) {
    remove_temp();
    // The user named OUT, not the file that was to become it.
    std::string message = e.what();
    const std::string temp = file.temp_path().string();
    for (std::size_t at = message.find(temp); at != std::string::npos; at = message.find(temp, at))
      message.replace(at, temp.size(), out.string());
    if (dynamic_cast<const InputError*>(&e)) throw InputError(message);
    if (dynamic_cast<const ResourceError*>(&e)) throw ResourceError(message);
    throw std::runtime_error(message);
  }
  return report;
}

}  // namespace crevasse

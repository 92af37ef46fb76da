#pragma once
// Files appear whole or not at all: a writer fills a temporary file beside the target and
// renames it over the target only once it is complete, so a kill, a full disk or an error
// midway leaves the previous file (or none), never a truncated one.
#include <filesystem>
#include <string>

namespace crevasse {

class AtomicFile {
 public:
  explicit AtomicFile(std::filesystem::path target);
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;
  ~AtomicFile();  // removes the temporary file unless commit() renamed it

  // Where to write: hidden, beside the target (same file system, so the rename is atomic), and
  // named after this process, so that two writers never share one.
  const std::filesystem::path& temp_path() const { return temp_; }
  const std::filesystem::path& target() const { return target_; }
  // Renames the temporary file over the target; std::runtime_error naming both when it cannot.
  void commit();

 private:
  std::filesystem::path target_, temp_;
  bool committed_ = false;
};

// Writes `content` to `target` through an AtomicFile; std::runtime_error naming the file when
// it cannot be written whole (a full disk, a size limit).
void write_file_atomically(const std::filesystem::path& target, const std::string& content);

}  // namespace crevasse

#pragma once
// CSV output shared by `crevasse export`, `calibrate --csv` and `accuracy`: RFC 4180 fields and a
// file that reports a failed write (full disk) when it is closed.
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "engine/atomic_file.hpp"
#include "engine/error.hpp"

namespace crevasse {

// RFC 4180: quote a field holding a comma, quote or line break; double inner quotes.
inline std::string csv_field(const std::string& v) {
  if (v.find_first_of(",\"\r\n") == std::string::npos) return v;
  std::string out = "\"";
  for (char c : v) {
    if (c == '"') out += '"';
    out += c;
  }
  return out + "\"";
}

class CsvFile {
 public:
  // `option` names the command-line option the path came from, for messages.
  // Written to a temporary file that close() renames over `path`: a kill or a full disk
  // leaves the previous file or none, never a truncated one.
  CsvFile(const std::filesystem::path& path, std::string option = "--csv")
      : path_(path), option_(std::move(option)), file_(path), out_(file_.temp_path()) {
    if (!out_) throw InputError(option_ + ": cannot write " + path.string());
  }
  void row(const std::vector<std::string>& fields) {
    for (std::size_t i = 0; i < fields.size(); ++i) out_ << (i ? "," : "") << csv_field(fields[i]);
    out_ << "\n";
  }
  void close() {
    out_.close();
    if (!out_)
      throw std::runtime_error(option_ + ": writing " + path_.string() + " failed (disk full?)");
    file_.commit();
  }

 private:
  std::filesystem::path path_;
  std::string option_;
  AtomicFile file_;
  std::ofstream out_;
};

}  // namespace crevasse

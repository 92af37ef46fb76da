#include "engine/atomic_file.hpp"

#include <signal.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <stdexcept>
#include <string>

namespace crevasse {

AtomicFile::AtomicFile(std::filesystem::path target) : target_(std::move(target)) {
  const std::string prefix = "." + target_.filename().string() + ".tmp-";
  temp_ = target_.parent_path() / (prefix + std::to_string(::getpid()));
  // The temporary files of writers that were killed (their process is gone) are removed.
  std::error_code ec;
  const std::filesystem::path dir = target_.has_parent_path() ? target_.parent_path() : ".";
  for (const auto& e : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(prefix, 0) != 0) continue;
    const std::string pid = name.substr(prefix.size());
    if (pid.empty() || pid.size() > 9 || pid.find_first_not_of("0123456789") != std::string::npos) continue;
    if (::kill(static_cast<pid_t>(std::stol(pid)), 0) != 0 && errno == ESRCH)
      std::filesystem::remove(e.path(), ec);
  }
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  std::error_code ec;
  std::filesystem::remove(temp_, ec);
}

void AtomicFile::commit() {
  std::error_code ec;
  std::filesystem::rename(temp_, target_, ec);
  if (ec)
    throw std::runtime_error("cannot rename " + temp_.string() + " to " + target_.string() + " (" +
                             ec.message() + ")");
  committed_ = true;
}

void write_file_atomically(const std::filesystem::path& target, const std::string& content) {
  AtomicFile file(target);
  {
    std::ofstream f(file.temp_path(), std::ios::binary | std::ios::trunc);
    if (!f) throw std::runtime_error("cannot write " + target.string() + ": " + std::strerror(errno));
    f.write(content.data(), static_cast<std::streamsize>(content.size()));
    f.close();
    if (!f) throw std::runtime_error("writing " + target.string() + " failed (disk full?)");
  }
  file.commit();
}

}  // namespace crevasse

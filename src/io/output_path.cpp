#include "panmap/io/output_path.h"

#include <filesystem>

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <string>

#include "panmap/core/error.h"

namespace panmap {
namespace fs = std::filesystem;

void checkOutputFolder(const std::string& dir, const std::string& flag) {
  std::error_code ec;
  const fs::path path = fs::absolute(dir, ec);
  const std::string what = flag + " " + dir;
  if (fs::exists(path, ec)) {
    if (!fs::is_directory(path, ec)) throw Error(what + " is a file, not a folder");
    if (::access(path.c_str(), W_OK | X_OK) != 0) throw Error(what + ": folder not writable");
    return;
  }
  fs::path parent = path.parent_path();
  while (parent.has_relative_path() && !fs::exists(parent, ec)) parent = parent.parent_path();
  if (!fs::is_directory(parent, ec)) {
    throw Error(what + ": " + parent.string() + " is a file, not a folder");
  }
  if (::access(parent.c_str(), W_OK | X_OK) != 0) {
    throw Error(what + ": cannot create it, " + parent.string() + " is not writable");
  }
}

void checkOutputFile(const std::string& path, const std::string& flag) {
  std::error_code ec;
  const fs::path file = fs::absolute(path, ec);
  const std::string what = flag + " " + path;
  if (fs::is_directory(file, ec)) throw Error(what + " is a folder, not a file");
  if (fs::exists(file, ec) && ::access(file.c_str(), W_OK) != 0) {
    throw Error(what + ": file not writable");
  }
  const fs::path parent = file.parent_path();
  if (!fs::is_directory(parent, ec)) {
    throw Error(what + ": folder " + parent.string() + " does not exist");
  }
  if (::access(parent.c_str(), W_OK | X_OK) != 0) {
    throw Error(what + ": folder " + parent.string() + " is not writable");
  }
}

OutputFolderLock::OutputFolderLock(const std::string& dir) {
  std::error_code ec;
  created_ = !fs::exists(dir, ec);
  fs::create_directories(dir, ec);
  if (ec) throw Error("cannot create output folder " + dir + ": " + ec.message());
  dir_ = dir;
  path_ = dir + "/.panmap.lock";
  const std::string& path = path_;
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  if (fd_ < 0) throw Error("cannot create " + path + ": " + std::strerror(errno));
  if (::flock(fd_, LOCK_EX | LOCK_NB) != 0) {
    char pid[32] = {0};
    const ssize_t n = ::pread(fd_, pid, sizeof(pid) - 1, 0);
    ::close(fd_);
    fd_ = -1;
    created_ = false;
    std::string holder = n > 0 ? std::string(pid, static_cast<size_t>(n)) : "";
    while (!holder.empty() && (holder.back() == '\n' || holder.back() == ' ')) holder.pop_back();
    throw Error("output folder " + dir + " is in use by another panmap process" +
                (holder.empty() ? "" : " (pid " + holder + ")") +
                ": give each run a folder of its own");
  }
  const std::string me = std::to_string(::getpid()) + "\n";
  if (::ftruncate(fd_, 0) == 0) {
    [[maybe_unused]] const ssize_t written = ::pwrite(fd_, me.data(), me.size(), 0);
  }
}

OutputFolderLock::~OutputFolderLock() {
  if (fd_ < 0) return;
  // Not left among the outputs of a run that ended well (a killed one leaves it: harmless, the
  // lock went with the process).
  ::unlink(path_.c_str());
  ::close(fd_);
  // A run that stopped before writing anything leaves no empty folder behind.
  std::error_code ignored;
  if (created_ && fs::is_empty(dir_, ignored)) fs::remove(dir_, ignored);
}

}  // namespace panmap

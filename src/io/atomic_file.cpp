#include "panmap/io/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>

#include "panmap/core/error.h"

namespace panmap {
namespace {

std::string systemError(const std::string& what) { return what + ": " + std::strerror(errno); }

}  // namespace

void writeFileAtomically(const std::string& path, const void* data, size_t size) {
  const std::string partial = path + ".partial";
  const int fd = ::open(partial.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw Error(systemError("cannot create " + partial));
  const auto* p = static_cast<const char*>(data);
  size_t left = size;
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      const std::string message = systemError("cannot write " + partial);
      ::close(fd);
      std::remove(partial.c_str());
      throw Error(message);
    }
    p += n;
    left -= static_cast<size_t>(n);
  }
  if (::fsync(fd) != 0) {
    const std::string message = systemError("cannot sync " + partial);
    ::close(fd);
    std::remove(partial.c_str());
    throw Error(message);
  }
  ::close(fd);
  if (std::rename(partial.c_str(), path.c_str()) != 0) {
    const std::string message = systemError("cannot rename " + partial + " to " + path);
    std::remove(partial.c_str());
    throw Error(message);
  }
  // The rename lives in the folder's entry: sync it too (best effort; some file systems refuse).
  std::string folder = std::filesystem::path(path).parent_path().string();
  if (folder.empty()) folder = ".";
  const int dir = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

}  // namespace panmap

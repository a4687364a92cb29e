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

AtomicFileWriter::AtomicFileWriter(std::string path)
    : path_(std::move(path)), partial_(path_ + ".partial") {
  fd_ = ::open(partial_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd_ < 0) throw Error(systemError("cannot create " + partial_));
}

AtomicFileWriter::~AtomicFileWriter() {
  if (fd_ >= 0) {
    ::close(fd_);
    std::remove(partial_.c_str());
  }
}

void AtomicFileWriter::append(const uint8_t* data, size_t size) {
  if (fd_ < 0) throw Error(partial_ + ": written after commit");
  while (size > 0) {
    const ssize_t n = ::write(fd_, data, size);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw Error(systemError("cannot write " + partial_));
    data += n;
    size -= static_cast<size_t>(n);
  }
}

void AtomicFileWriter::overwrite(uint64_t offset, const uint8_t* data, size_t size) {
  if (fd_ < 0) throw Error(partial_ + ": written after commit");
  while (size > 0) {
    const ssize_t n = ::pwrite(fd_, data, size, static_cast<off_t>(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) throw Error(systemError("cannot write " + partial_));
    data += n;
    size -= static_cast<size_t>(n);
    offset += static_cast<uint64_t>(n);
  }
}

void AtomicFileWriter::commit() {
  if (fd_ < 0) throw Error(partial_ + ": committed twice");
  if (::fsync(fd_) != 0) throw Error(systemError("cannot sync " + partial_));
  const int fd = fd_;
  fd_ = -1;
  if (::close(fd) != 0) {
    const std::string message = systemError("cannot close " + partial_);
    std::remove(partial_.c_str());
    throw Error(message);
  }
  if (std::rename(partial_.c_str(), path_.c_str()) != 0) {
    const std::string message = systemError("cannot rename " + partial_ + " to " + path_);
    std::remove(partial_.c_str());
    throw Error(message);
  }
  // The rename lives in the folder's entry: sync it too (best effort; some file systems refuse).
  std::string folder = std::filesystem::path(path_).parent_path().string();
  if (folder.empty()) folder = ".";
  const int dir = ::open(folder.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dir >= 0) {
    ::fsync(dir);
    ::close(dir);
  }
}

void writeFileAtomically(const std::string& path, const void* data, size_t size) {
  try {
    AtomicFileWriter file(path);
    file.append(static_cast<const uint8_t*>(data), size);
    file.commit();
  } catch (const Error& e) {
    throw Error("cannot write " + path + ": " + e.what());
  }
}

void writeFileAtomically(const std::string& path, const std::string& bytes) {
  writeFileAtomically(path, bytes.data(), bytes.size());
}

}  // namespace panmap

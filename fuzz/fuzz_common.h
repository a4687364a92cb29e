// Helpers shared by the fuzz targets: a scratch folder per process for readers that take a
// path, and a small container format that turns one fuzz input into several named files.
#pragma once

#include <unistd.h>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

namespace panmap {
namespace fuzz {

/// <tmp>/panmap-fuzz-<pid>: one per process, since libFuzzer's -jobs/-fork run several
/// processes side by side. In /dev/shm when there is one: the readers take paths, and file
/// system calls are most of a run's time on disk. Removed at exit.
inline const std::string& scratchDir() {
  // Never destroyed: the exit handler runs after static destructors may have.
  static const std::string* dir = [] {
    const char* base = std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : "/tmp";
    auto* d = new std::string(std::string(base) + "/panmap-fuzz-" + std::to_string(getpid()));
    std::filesystem::create_directories(*d);
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(scratchDir(), ec);
    });
    return d;
  }();
  return *dir;
}

/// Writes bytes to a file, creating its parent folders.
inline void writeFile(const std::string& path, const uint8_t* data, size_t size) {
  std::filesystem::create_directories(std::filesystem::path(path).parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

/// Writes the input to <scratch>/<name> and returns the path (one fixed file per target, so
/// no input leaves files behind).
inline std::string writeScratchFile(const std::string& name, const uint8_t* data, size_t size) {
  const std::string path = scratchDir() + "/" + name;
  writeFile(path, data, size);
  return path;
}

/// An empty folder <scratch>/<name>, its previous contents removed.
inline std::string freshScratchFolder(const std::string& name) {
  const std::string dir = scratchDir() + "/" + name;
  std::error_code ec;
  std::filesystem::remove_all(dir, ec);
  std::filesystem::create_directories(dir);
  return dir;
}

/// One file of a container: an index into the target's list of names, and the bytes.
struct Entry {
  uint8_t name = 0;
  std::vector<uint8_t> bytes;
};

/// The container: repeated [name index: 1 byte][length: 2 bytes little-endian][bytes]. A
/// length past the end takes what is left, so every input means something.
inline std::vector<Entry> unpack(const uint8_t* data, size_t size) {
  std::vector<Entry> out;
  size_t pos = 0;
  while (pos < size) {
    Entry e;
    e.name = data[pos++];
    size_t len = 0;
    if (pos < size) len = data[pos++];
    if (pos < size) len |= static_cast<size_t>(data[pos++]) << 8;
    len = std::min(len, size - pos);
    e.bytes.assign(data + pos, data + pos + len);
    pos += len;
    out.push_back(std::move(e));
  }
  return out;
}

/// The inverse of unpack (the seed generator writes corpora with it).
inline std::vector<uint8_t> pack(const std::vector<Entry>& entries) {
  std::vector<uint8_t> out;
  for (const Entry& e : entries) {
    const size_t len = std::min<size_t>(e.bytes.size(), 0xFFFF);
    out.push_back(e.name);
    out.push_back(static_cast<uint8_t>(len & 0xFF));
    out.push_back(static_cast<uint8_t>(len >> 8));
    out.insert(out.end(), e.bytes.begin(), e.bytes.begin() + static_cast<long>(len));
  }
  return out;
}

/// Writes every entry of a container into `dir` under names[index % names.size()]; later
/// entries with the same name replace earlier ones.
inline void writeEntries(const std::string& dir, const std::vector<Entry>& entries,
                         const std::vector<std::string>& names) {
  for (const Entry& e : entries) {
    writeFile(dir + "/" + names[e.name % names.size()], e.bytes.data(), e.bytes.size());
  }
}

}  // namespace fuzz
}  // namespace panmap

#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "panmap/core/byte_sink.h"

namespace panmap {

/// Writes a file so that a crash or power cut at any moment leaves either the previous file or
/// the complete new one: the bytes go to PATH.partial, and commit() fsyncs it, renames it over
/// PATH and fsyncs the folder so the rename itself is durable. Destroyed without commit(), it
/// removes the partial file. Errors throw Error naming the file and the failing step.
class AtomicFileWriter : public ByteSink {
 public:
  /// Creates PATH.partial.
  explicit AtomicFileWriter(std::string path);
  /// Removes the partial file unless committed.
  ~AtomicFileWriter() override;
  AtomicFileWriter(const AtomicFileWriter&) = delete;
  AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;

  /// Appends bytes.
  void append(const uint8_t* data, size_t size) override;
  /// Replaces bytes written earlier.
  void overwrite(uint64_t offset, const uint8_t* data, size_t size) override;
  /// Makes the file durable and puts it in place of PATH.
  void commit();
  /// The final path.
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::string partial_;
  int fd_ = -1;
};

/// Writes SIZE bytes to PATH through an AtomicFileWriter, so a reader polling PATH (a planner
/// reading objects.json or occupancy.bt while the mapper writes them) sees the old file or the
/// whole new one, never a part. Throws Error "cannot write PATH: why"; PATH is then untouched.
void writeFileAtomically(const std::string& path, const void* data, size_t size);

/// writeFileAtomically of a string's bytes.
void writeFileAtomically(const std::string& path, const std::string& bytes);

}  // namespace panmap

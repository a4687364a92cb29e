#pragma once

#include <string>

namespace panmap {

/// Throws Error (naming `flag` and `dir`) unless `dir` is a folder this process can write
/// into, or one it can create. For CLIs to call before long work, so that hours of mapping do
/// not end in "cannot write". Creates nothing.
void checkOutputFolder(const std::string& dir, const std::string& flag);

/// Throws Error (naming `flag` and `path`) unless a file can be written at `path`: its folder
/// exists and is writable, and `path` is not a folder or a read-only file. Creates nothing.
void checkOutputFile(const std::string& path, const std::string& flag);

/// Holds `dir`/.panmap.lock (flock, released when the process ends however it ends) so that
/// two processes do not write one output folder: their autosaves and journals would mix and a
/// resume would take the other's snapshot. Creates `dir` when missing.
class OutputFolderLock {
 public:
  /// Throws Error naming the folder (and the holder's pid) when another process holds it.
  explicit OutputFolderLock(const std::string& dir);
  ~OutputFolderLock();
  OutputFolderLock(const OutputFolderLock&) = delete;
  OutputFolderLock& operator=(const OutputFolderLock&) = delete;

 private:
  std::string dir_;
  std::string path_;
  bool created_ = false;  ///< the folder did not exist before: removed again when left empty
  int fd_ = -1;
};

}  // namespace panmap

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

}  // namespace panmap

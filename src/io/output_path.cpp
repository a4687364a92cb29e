#include "panmap/io/output_path.h"

#include <filesystem>

#include <unistd.h>

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

}  // namespace panmap

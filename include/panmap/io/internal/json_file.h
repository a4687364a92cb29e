#pragma once

#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "panmap/core/error.h"

namespace panmap {
namespace internal {

/// Parses a JSON file; throws Error naming the file when it is missing or malformed.
inline nlohmann::json readJsonFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("cannot read " + path);
  try {
    return nlohmann::json::parse(in);
  } catch (const nlohmann::json::exception& e) {
    throw Error(path + ": malformed JSON (" + std::string(e.what()) + ")");
  }
}

}  // namespace internal
}  // namespace panmap

#pragma once

#include <cstddef>
#include <string>

namespace panmap {

/// Writes `size` bytes to `path` so that a crash or power cut at any moment leaves either the
/// previous file or the complete new one: the bytes go to a temporary file beside it, which is
/// fsync'ed and renamed over `path`, and the folder is fsync'ed so the rename itself is
/// durable. Throws Error naming the path and the failing step.
void writeFileAtomically(const std::string& path, const void* data, size_t size);

}  // namespace panmap

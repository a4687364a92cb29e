#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "panmap/core/labelled_mesh.h"

namespace panmap {

/// Replaces a mesh's labels with a ScanNet benchmark ground-truth file's ids (one per vertex,
/// class * 1000 + instance, 0 = none): semantic = id / 1000, instance = id (unique across
/// classes, as the benchmark's); vertices with id 0 get instance 0 and keep the mesh's
/// semantic label (0 when it has none). Throws Error naming `ids_source` and `mesh_source` when the
/// counts differ or an id is negative.
void applyScanNetInstanceIds(const std::vector<int32_t>& ids, const std::string& ids_source,
                             const std::string& mesh_source, LabelledMesh* mesh);

/// Classes from a comma-separated list of NYU40 ids or names ("3,5,chair"; names as
/// nyu40IdFromName). Throws Error naming the entry when one is unknown, outside 1..40, or
/// repeated; returns them ascending.
std::vector<int32_t> parseClassList(const std::string& text);

}  // namespace panmap

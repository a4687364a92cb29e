#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "panmap/core/labelled_mesh.h"

namespace panmap {

/// The ground-truth files of one ScanNet scene folder.
struct ScanNetSceneFiles {
  std::string scene;             ///< e.g. "scene0000_00"
  std::string mesh_ply;          ///< <scene>_vh_clean_2.ply
  std::string aggregation_json;  ///< <scene>.aggregation.json (segGroups of the vh_clean_2 mesh)
  std::string segs_json;         ///< <scene>_vh_clean_2.0.010000.segs.json
};

/// Finds a ScanNet scene's ground-truth files in `scene_dir`: the scene name is the folder's
/// name when <name>_vh_clean_2.ply exists there, else the prefix of the only *_vh_clean_2.ply
/// in it. Throws Error naming the folder or the missing file.
ScanNetSceneFiles findScanNetSceneFiles(const std::string& scene_dir);

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

#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "panmap/core/labelled_mesh.h"

namespace panmap {

/// ScanNet's label table (scannetv2-labels.combined.tsv): raw category names and ScanNet
/// label ids -> NYU40 ids.
class ScanNetLabelTable {
 public:
  /// Loads the tab-separated table (columns found by their header names). Throws Error naming
  /// the file when it is missing or lacks the raw_category / id / nyu40id columns.
  static ScanNetLabelTable load(const std::string& tsv_path);

  /// NYU40 id of a segGroup's raw label: exact raw_category match first, then a case- and
  /// punctuation-insensitive match (normaliseName), else 0.
  int32_t nyu40FromRawCategory(const std::string& raw_label) const;

  /// NYU40 id of a ScanNet label id (the `label` property of *_vh_clean_2.labels.ply), or 0.
  /// Three ids of the v2 table name two rows with different NYU40 ids (107, 188, 385); the
  /// last row wins, as in ScanNet's own util.read_label_mapping.
  int32_t nyu40FromScanNetId(int32_t scannet_id) const;

 private:
  std::map<std::string, int32_t> raw_to_nyu40_;
  std::map<std::string, int32_t> normalised_to_nyu40_;
  std::map<int32_t, int32_t> id_to_nyu40_;
};

/// A ScanNet scene's ground truth as a labelled mesh.
struct ScanNetGroundTruth {
  LabelledMesh mesh;      ///< vh_clean_2 mesh; semantic = NYU40 id, instance = objectId + 1
  int num_instances = 0;  ///< segGroups with at least one vertex
  /// Raw labels that matched no table row even forgivingly, unique and sorted. Their vertices
  /// keep semantic 0 but still get the group's instance id (ScanNet's numbering).
  std::vector<std::string> unknown_labels;
};

/// Loads <scene>_vh_clean_2.ply, <scene>.aggregation.json (segGroups: objectId, label,
/// segments), <scene>_vh_clean_2.0.010000.segs.json (segIndices per vertex) and the label
/// table. A vertex takes the class and instance of the segGroup containing its segment; the
/// instance id is objectId + 1 (ScanNet's benchmark numbering); vertices in no group get 0.
/// A segment listed by two groups (rare in ScanNet) stays with the first. The mesh's
/// superpoint array is left as the PLY file has it (ScanNet's has none). Throws Error naming
/// the file at fault (both files when segIndices and the mesh disagree in length).
ScanNetGroundTruth loadScanNetGroundTruth(const std::string& mesh_ply,
                                          const std::string& aggregation_json,
                                          const std::string& segs_json,
                                          const ScanNetLabelTable& table);

/// The ground-truth files of one ScanNet scene folder.
struct ScanNetSceneFiles {
  std::string scene;             ///< e.g. "scene0000_00"
  std::string mesh_ply;          ///< <scene>_vh_clean_2.ply
  std::string aggregation_json;  ///< <scene>.aggregation.json (segGroups of the vh_clean_2 mesh)
  std::string segs_json;         ///< <scene>_vh_clean_2.0.010000.segs.json
};

/// Finds a ScanNet scene's ground-truth files in `scene_dir`: the scene name is the folder's
/// name when <name>_vh_clean_2.ply exists there, else the prefix of the only *_vh_clean_2.ply
/// in it; the files beside it that annotate the high-resolution mesh (a full download's
/// *_vh_clean.aggregation.json, *_vh_clean.segs.json) are not taken. Throws Error naming the
/// folder or the missing file.
ScanNetSceneFiles findScanNetSceneFiles(const std::string& scene_dir);

/// ScanNet's label table for a scene when none is given: scannetv2-labels.combined.tsv in
/// `scene_dir`, its parent or its grandparent (ScanNet's download script puts it above
/// scans/<scene>/), or in a scannet-meta/ folder in one of them. "" when none has it.
std::string findScanNetLabelTable(const std::string& scene_dir);

/// Per-vertex NYU40 ids of ScanNet's *_vh_clean_2.labels.ply: its `label` property (ScanNet
/// label ids) mapped through the table. Throws Error naming the file.
std::vector<int32_t> readScanNetLabelsPly(const std::string& labels_ply,
                                          const ScanNetLabelTable& table);

/// Writes the ScanNet benchmark ground-truth file of a labelled mesh: one line per vertex,
/// semantic * 1000 + instance for vertices with an instance and a class (both > 0), 0
/// otherwise. Throws Error naming the file when it cannot be written.
void writeScanNetInstanceFile(const std::string& path, const LabelledMesh& mesh);

/// Reads such a file back (one integer per line). Throws Error naming the file.
std::vector<int32_t> readScanNetInstanceFile(const std::string& path);

}  // namespace panmap

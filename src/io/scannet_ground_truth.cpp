#include "panmap/io/scannet_ground_truth.h"

#include <algorithm>
#include <charconv>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>
#include <unordered_map>

#include <nlohmann/json.hpp>

#include "panmap/io/internal/json_file.h"

#include "panmap/core/classes.h"
#include "panmap/core/error.h"
#include "panmap/io/ply.h"
#include "panmap/io/text_files.h"

namespace panmap {
namespace {

using nlohmann::json;

constexpr char kScanNetMeshSuffix[] = "_vh_clean_2.ply";

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::vector<std::string> splitTabs(const std::string& line) {
  std::vector<std::string> fields;
  size_t start = 0;
  while (true) {
    const size_t tab = line.find('\t', start);
    fields.push_back(
        line.substr(start, tab == std::string::npos ? std::string::npos : tab - start));
    if (tab == std::string::npos) return fields;
    start = tab + 1;
  }
}

bool parseInt(const std::string& text, int32_t* value) {
  const char* end = text.data() + text.size();
  const auto result = std::from_chars(text.data(), end, *value);
  return result.ec == std::errc() && result.ptr == end;
}

}  // namespace

ScanNetLabelTable ScanNetLabelTable::load(const std::string& tsv_path) {
  if (!isRegularFile(tsv_path)) throw Error("cannot read " + tsv_path + " (no such file)");
  std::ifstream in(tsv_path);
  if (!in) throw Error("cannot read " + tsv_path);
  std::string line;
  if (!std::getline(in, line)) throw Error(tsv_path + ": empty label table");
  if (!line.empty() && line.back() == '\r') line.pop_back();
  const std::vector<std::string> header = splitTabs(line);
  auto column = [&](const std::string& name) {
    for (size_t i = 0; i < header.size(); ++i) {
      if (header[i] == name) return i;
    }
    throw Error(tsv_path + ": header has no column '" + name + "'");
  };
  const size_t id_col = column("id");
  const size_t raw_col = column("raw_category");
  const size_t nyu_col = column("nyu40id");
  const size_t needed = std::max({id_col, raw_col, nyu_col}) + 1;

  ScanNetLabelTable table;
  int line_number = 1;
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    const std::vector<std::string> fields = splitTabs(line);
    const std::string where = tsv_path + ": line " + std::to_string(line_number) + ": ";
    if (fields.size() < needed) throw Error(where + "too few columns");
    int32_t id = 0;
    int32_t nyu40 = 0;
    if (!parseInt(fields[id_col], &id)) throw Error(where + "id '" + fields[id_col] + "'");
    if (!parseInt(fields[nyu_col], &nyu40) || nyu40 < 0 || nyu40 > kMaxNyu40Class) {
      throw Error(where + "nyu40id '" + fields[nyu_col] + "' is not in 0..40");
    }
    const std::string& raw = fields[raw_col];
    table.raw_to_nyu40_.emplace(raw, nyu40);
    const std::string key = normaliseName(raw);
    if (!key.empty()) table.normalised_to_nyu40_.emplace(key, nyu40);
    // Assignment, not emplace: the last row wins like ScanNet's util.read_label_mapping.
    table.id_to_nyu40_[id] = nyu40;
  }
  if (table.raw_to_nyu40_.empty()) throw Error(tsv_path + ": label table has no rows");
  return table;
}

int32_t ScanNetLabelTable::nyu40FromRawCategory(const std::string& raw_label) const {
  const auto exact = raw_to_nyu40_.find(raw_label);
  if (exact != raw_to_nyu40_.end()) return exact->second;
  const std::string key = normaliseName(raw_label);
  if (key.empty()) return kUnknownClass;
  const auto loose = normalised_to_nyu40_.find(key);
  return loose != normalised_to_nyu40_.end() ? loose->second : kUnknownClass;
}

int32_t ScanNetLabelTable::nyu40FromScanNetId(int32_t scannet_id) const {
  const auto it = id_to_nyu40_.find(scannet_id);
  return it != id_to_nyu40_.end() ? it->second : kUnknownClass;
}

ScanNetGroundTruth loadScanNetGroundTruth(const std::string& mesh_ply,
                                          const std::string& aggregation_json,
                                          const std::string& segs_json,
                                          const ScanNetLabelTable& table) {
  ScanNetGroundTruth gt;
  gt.mesh = readPly(mesh_ply);
  const size_t n = gt.mesh.numVertices();

  const json segs = internal::readJsonFile(segs_json);
  if (!segs.is_object() || !segs.contains("segIndices") || !segs["segIndices"].is_array()) {
    throw Error(segs_json + ": no segIndices list");
  }
  const json& seg_indices = segs["segIndices"];
  if (seg_indices.size() != n) {
    throw Error(segs_json + ": " + std::to_string(seg_indices.size()) + " segIndices but " +
                mesh_ply + " has " + std::to_string(n) + " vertices");
  }

  const json aggregation = internal::readJsonFile(aggregation_json);
  if (!aggregation.is_object() || !aggregation.contains("segGroups") ||
      !aggregation["segGroups"].is_array()) {
    throw Error(aggregation_json + ": no segGroups list");
  }
  struct Group {
    int32_t instance = 0;
    int32_t semantic = 0;
    size_t vertices = 0;
  };
  std::vector<Group> groups;
  std::unordered_map<int64_t, size_t> segment_to_group;
  std::set<int32_t> object_ids;
  std::set<std::string> unknown;
  for (const json& g : aggregation["segGroups"]) {
    const std::string where =
        aggregation_json + ": segGroup " + std::to_string(groups.size()) + ": ";
    if (!g.is_object() || !g.contains("objectId") || !g["objectId"].is_number_integer() ||
        !g.contains("label") || !g["label"].is_string() || !g.contains("segments") ||
        !g["segments"].is_array()) {
      throw Error(where + "needs integer objectId, string label and a segments list");
    }
    const int64_t object_id = g["objectId"].get<int64_t>();
    if (object_id < 0 || object_id >= std::numeric_limits<int32_t>::max()) {
      throw Error(where + "objectId " + std::to_string(object_id) + " out of range");
    }
    if (!object_ids.insert(static_cast<int32_t>(object_id)).second) {
      throw Error(where + "objectId " + std::to_string(object_id) + " appears twice");
    }
    Group group;
    group.instance = static_cast<int32_t>(object_id) + 1;
    const std::string label = g["label"].get<std::string>();
    group.semantic = table.nyu40FromRawCategory(label);
    if (group.semantic == kUnknownClass) unknown.insert(label);
    for (const json& s : g["segments"]) {
      if (!s.is_number_integer()) throw Error(where + "a segment id is not an integer");
      // emplace keeps the first group of a segment that two groups list.
      segment_to_group.emplace(s.get<int64_t>(), groups.size());
    }
    groups.push_back(group);
  }

  gt.mesh.semantic.assign(n, kUnknownClass);
  gt.mesh.instance.assign(n, 0);
  for (size_t v = 0; v < n; ++v) {
    const json& s = seg_indices[v];
    if (!s.is_number_integer()) {
      throw Error(segs_json + ": segIndices[" + std::to_string(v) + "] is not an integer");
    }
    const auto it = segment_to_group.find(s.get<int64_t>());
    if (it == segment_to_group.end()) continue;
    Group& group = groups[it->second];
    gt.mesh.semantic[v] = group.semantic;
    gt.mesh.instance[v] = group.instance;
    ++group.vertices;
  }
  for (const Group& group : groups) gt.num_instances += group.vertices > 0;
  gt.unknown_labels.assign(unknown.begin(), unknown.end());
  return gt;
}

std::string findScanNetLabelTable(const std::string& scene_dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::path dir = fs::absolute(scene_dir, ec);
  if (ec) return "";
  if (!dir.has_filename()) dir = dir.parent_path();  // "scene0000_00/"
  for (int up = 0; up < 3 && !dir.empty(); ++up) {
    // In the folder itself (ScanNet's download), or in a scannet-meta/ folder beside it (the
    // shared data's layout: scannet-gt/<scene> and scannet-meta/ side by side).
    for (const fs::path& table : {dir / "scannetv2-labels.combined.tsv",
                                  dir / "scannet-meta" / "scannetv2-labels.combined.tsv"}) {
      if (fs::is_regular_file(table, ec)) return table.string();
    }
    if (dir == dir.parent_path()) break;
    dir = dir.parent_path();
  }
  return "";
}

ScanNetSceneFiles findScanNetSceneFiles(const std::string& scene_dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::is_directory(scene_dir, ec)) throw Error(scene_dir + ": not a folder");
  const fs::path dir(scene_dir);
  // "scene0000_00/" has an empty filename: its parent_path's is the name.
  std::string scene = (dir.has_filename() ? dir : dir.parent_path()).filename().string();
  if (!fs::is_regular_file(dir / (scene + kScanNetMeshSuffix), ec)) {
    std::vector<std::string> found;
    for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
      const std::string name = e.path().filename().string();
      if (endsWith(name, kScanNetMeshSuffix)) found.push_back(name);
    }
    if (found.size() != 1) {
      throw Error(scene_dir + ": expected one *" + kScanNetMeshSuffix + " mesh, found " +
                  std::to_string(found.size()));
    }
    scene = found[0].substr(0, found[0].size() - std::string(kScanNetMeshSuffix).size());
  }
  ScanNetSceneFiles files;
  files.scene = scene;
  files.mesh_ply = (dir / (scene + kScanNetMeshSuffix)).string();
  files.aggregation_json = (dir / (scene + ".aggregation.json")).string();
  files.segs_json = (dir / (scene + "_vh_clean_2.0.010000.segs.json")).string();
  for (const std::string* f : {&files.aggregation_json, &files.segs_json}) {
    if (!fs::is_regular_file(*f, ec)) {
      throw Error(*f + ": missing (ScanNet scene " + scene + ")" +
                  (f == &files.aggregation_json
                       ? "; a *_vh_clean.aggregation.json annotates the high-resolution mesh"
                       : ""));
    }
  }
  return files;
}

std::vector<int32_t> readScanNetLabelsPly(const std::string& labels_ply,
                                          const ScanNetLabelTable& table) {
  std::vector<int32_t> classes = readPlyVertexIntProperty(labels_ply, "label");
  for (int32_t& c : classes) c = table.nyu40FromScanNetId(c);
  return classes;
}

void writeScanNetInstanceFile(const std::string& path, const LabelledMesh& mesh) {
  const std::string problem = mesh.check();
  if (!problem.empty()) throw Error(path + ": cannot write an inconsistent mesh: " + problem);
  std::string text;
  text.reserve(mesh.numVertices() * 6);
  for (size_t v = 0; v < mesh.numVertices(); ++v) {
    const int32_t semantic = mesh.semantic.empty() ? 0 : mesh.semantic[v];
    const int32_t instance = mesh.instance.empty() ? 0 : mesh.instance[v];
    const int64_t value = semantic > 0 && instance > 0 ? int64_t{semantic} * 1000 + instance : 0;
    text += std::to_string(value);
    text += '\n';
  }
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw Error("cannot write " + path);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  out.close();
  if (!out) throw Error("cannot write " + path + " (disk full?)");
}

std::vector<int32_t> readScanNetInstanceFile(const std::string& path) {
  if (!isRegularFile(path)) throw Error("cannot read " + path + " (no such file)");
  std::ifstream in(path);
  if (!in) throw Error("cannot read " + path);
  std::vector<int32_t> values;
  std::string line;
  int line_number = 0, blank_lines = 0;
  while (std::getline(in, line)) {
    ++line_number;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    // Blank lines at the end (np.savetxt and editors leave one) are no vertex; a blank line
    // followed by more ids would shift every later vertex, so it stays an error.
    if (line.find_first_not_of(" \t") == std::string::npos) {
      ++blank_lines;
      continue;
    }
    if (blank_lines > 0) {
      throw Error(path + ": line " + std::to_string(line_number - blank_lines) +
                  ": a blank line among the ids");
    }
    int32_t value = 0;
    if (!parseInt(line, &value)) {
      throw Error(path + ": line " + std::to_string(line_number) + ": '" + line +
                  "' is not an integer");
    }
    values.push_back(value);
  }
  return values;
}

}  // namespace panmap

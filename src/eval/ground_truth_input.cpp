#include "panmap/eval/ground_truth_input.h"

#include <algorithm>
#include <filesystem>
#include <set>
#include <sstream>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"

namespace panmap {
namespace {

namespace fs = std::filesystem;

constexpr char kMeshSuffix[] = "_vh_clean_2.ply";

bool endsWith(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() &&
         s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t") - a + 1);
}

}  // namespace

ScanNetSceneFiles findScanNetSceneFiles(const std::string& scene_dir) {
  std::error_code ec;
  if (!fs::is_directory(scene_dir, ec)) throw Error(scene_dir + ": not a folder");
  const fs::path dir(scene_dir);
  // "scene0000_00/" has an empty filename: its parent_path's is the name.
  std::string scene = (dir.has_filename() ? dir : dir.parent_path()).filename().string();
  if (!fs::is_regular_file(dir / (scene + kMeshSuffix), ec)) {
    std::vector<std::string> found;
    for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
      const std::string name = e.path().filename().string();
      if (endsWith(name, kMeshSuffix)) found.push_back(name);
    }
    if (found.size() != 1) {
      throw Error(scene_dir + ": expected one *" + kMeshSuffix + " mesh, found " +
                  std::to_string(found.size()));
    }
    scene = found[0].substr(0, found[0].size() - std::string(kMeshSuffix).size());
  }
  ScanNetSceneFiles files;
  files.scene = scene;
  files.mesh_ply = (dir / (scene + kMeshSuffix)).string();
  files.aggregation_json = (dir / (scene + ".aggregation.json")).string();
  files.segs_json = (dir / (scene + "_vh_clean_2.0.010000.segs.json")).string();
  for (const std::string* f : {&files.aggregation_json, &files.segs_json}) {
    if (!fs::is_regular_file(*f, ec)) throw Error(*f + ": missing (ScanNet scene " + scene + ")");
  }
  return files;
}

void applyScanNetInstanceIds(const std::vector<int32_t>& ids, const std::string& ids_source,
                             const std::string& mesh_source, LabelledMesh* mesh) {
  if (ids.size() != mesh->numVertices()) {
    throw Error(ids_source + ": " + std::to_string(ids.size()) + " lines but " + mesh_source +
                " has " + std::to_string(mesh->numVertices()) + " vertices");
  }
  // Vertices without an id keep the mesh's class, so stuff still counts for semantic IoU.
  if (mesh->semantic.size() != ids.size()) mesh->semantic.assign(ids.size(), 0);
  mesh->instance.assign(ids.size(), 0);
  for (size_t v = 0; v < ids.size(); ++v) {
    if (ids[v] < 0) {
      throw Error(ids_source + ": line " + std::to_string(v + 1) + ": negative id " +
                  std::to_string(ids[v]));
    }
    if (ids[v] == 0) continue;
    mesh->semantic[v] = ids[v] / 1000;
    mesh->instance[v] = ids[v];
  }
}

std::vector<int32_t> parseClassList(const std::string& text) {
  std::set<int32_t> classes;
  std::stringstream list(text);
  std::string entry;
  while (std::getline(list, entry, ',')) {
    entry = trim(entry);
    int32_t id = 0;
    if (!entry.empty() && std::all_of(entry.begin(), entry.end(), ::isdigit)) {
      id = entry.size() <= 3 ? std::stoi(entry) : 0;
    } else {
      id = nyu40IdFromName(entry);
    }
    if (id < 1 || id > kMaxNyu40Class) {
      throw Error("classes: '" + entry + "' is not an NYU40 id (1..40) or name");
    }
    if (!classes.insert(id).second) throw Error("classes: '" + entry + "' listed twice");
  }
  if (classes.empty()) throw Error("classes: empty list");
  return {classes.begin(), classes.end()};
}

}  // namespace panmap

#include "panmap/eval/ground_truth_input.h"

#include <algorithm>
#include <set>
#include <sstream>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"

namespace panmap {
namespace {

std::string trim(const std::string& s) {
  const size_t a = s.find_first_not_of(" \t");
  if (a == std::string::npos) return "";
  return s.substr(a, s.find_last_not_of(" \t") - a + 1);
}

}  // namespace

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
    if (ids[v] / 1000 > kMaxNyu40Class) {
      throw Error(ids_source + ": line " + std::to_string(v + 1) + ": id " +
                  std::to_string(ids[v]) + " names class " + std::to_string(ids[v] / 1000) +
                  ", not an NYU40 id (1..40; a ScanNet label id maps to one through "
                  "scannetv2-labels.combined.tsv)");
    }
    mesh->semantic[v] = ids[v] / 1000;
    mesh->instance[v] = ids[v];
  }
  // Class ids alone (ScanNet's semantic benchmark format) leave every vertex without a class
  // here, and every score of the instance evaluation empty with exit 0.
  const bool any_id = std::any_of(ids.begin(), ids.end(), [](int32_t id) { return id != 0; });
  const bool any_class = std::any_of(ids.begin(), ids.end(), [](int32_t id) { return id >= 1000; });
  if (any_id && !any_class) {
    throw Error(ids_source +
                ": every id is below 1000, so no vertex has a class: the file holds class * "
                "1000 + instance per vertex (ScanNet's instance format), not class ids alone");
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

#include "panmap/sim/instance_parts.h"

#include <cmath>
#include <map>
#include <set>
#include <string>
#include <tuple>
#include <utility>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"

namespace panmap {

void PartJoinConfig::check() const {
  if (!(cell_m > 0.0f && std::isfinite(cell_m))) throw Error("part join: cell_m must be > 0");
  if (!(min_share > 0.0 && min_share <= 1.0)) {
    throw Error("part join: min_share must be in (0, 1]");
  }
}

namespace {

struct Instance {
  int32_t class_id = 0;
  size_t vertices = 0;
  std::set<std::pair<int64_t, int64_t>> cells;  // footprint: (x, y) cell indices
};

// The strict order in which an instance is "larger": more footprint cells, then more
// vertices, then the lower id. Joining only into larger instances leaves no cycle.
bool larger(const std::pair<const int32_t, Instance>& a,
            const std::pair<const int32_t, Instance>& b) {
  return std::make_tuple(a.second.cells.size(), a.second.vertices, -a.first) >
         std::make_tuple(b.second.cells.size(), b.second.vertices, -b.first);
}

size_t sharedCells(const Instance& a, const Instance& b) {
  size_t shared = 0;
  for (const auto& cell : a.cells) shared += b.cells.count(cell);
  return shared;
}

}  // namespace

std::vector<PartJoin> joinStackedParts(LabelledMesh* mesh, const PartJoinConfig& config) {
  config.check();
  const size_t n = mesh->numVertices();
  if (mesh->semantic.size() != n || mesh->instance.size() != n) {
    throw Error("part join: the mesh needs semantic and instance labels per vertex");
  }
  std::map<int32_t, Instance> instances;
  for (size_t v = 0; v < n; ++v) {
    const int32_t id = mesh->instance[v], cls = mesh->semantic[v];
    if (id <= 0 || cls <= 0 || isStuffClass(cls)) continue;
    Instance& instance = instances[id];
    if (instance.vertices > 0 && instance.class_id != cls) {
      throw Error("part join: instance " + std::to_string(id) + " has vertices of two classes");
    }
    instance.class_id = cls;
    ++instance.vertices;
    const Eigen::Vector3f& p = mesh->vertices[v];
    instance.cells.emplace(static_cast<int64_t>(std::floor(p.x() / config.cell_m)),
                           static_cast<int64_t>(std::floor(p.y() / config.cell_m)));
  }
  // Each instance's direct parent: the larger instance of its class covering most of it.
  std::map<int32_t, std::pair<int32_t, double>> parent;
  for (const auto& part : instances) {
    int32_t best = 0;
    double best_share = 0.0;
    for (const auto& other : instances) {
      if (other.second.class_id != part.second.class_id || !larger(other, part)) continue;
      const double share = static_cast<double>(sharedCells(part.second, other.second)) /
                           static_cast<double>(part.second.cells.size());
      if (share >= config.min_share && share > best_share) {
        best = other.first;
        best_share = share;
      }
    }
    if (best > 0) parent[part.first] = {best, best_share};
  }
  std::vector<PartJoin> joins;
  std::map<int32_t, int32_t> root_of;
  for (const auto& [id, link] : parent) {
    int32_t root = link.first;
    for (auto it = parent.find(root); it != parent.end(); it = parent.find(root)) {
      root = it->second.first;
    }
    root_of[id] = root;
    joins.push_back(PartJoin{id, root, instances.at(id).class_id, link.second});
  }
  for (size_t v = 0; v < n; ++v) {
    const auto it = root_of.find(mesh->instance[v]);
    if (it != root_of.end()) mesh->instance[v] = it->second;
  }
  return joins;
}

}  // namespace panmap

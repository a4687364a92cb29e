#include "panmap/mapper/graph_json.h"

#include <nlohmann/json.hpp>

#include "panmap/core/error.h"
#include "panmap/io/atomic_file.h"

namespace panmap {
namespace {

nlohmann::json classMap(const ClassValues& m) {
  nlohmann::json out = nlohmann::json::object();
  for (const auto& [cls, value] : m) out[std::to_string(cls)] = value;
  return out;
}

template <typename T>
T lookup(const std::map<int32_t, T>& m, int32_t key) {
  const auto it = m.find(key);
  return it == m.end() ? T() : it->second;
}

}  // namespace

void writeGraphJson(const std::string& path, const SuperpointGraph& graph,
                    const GraphLabels& labels) {
  nlohmann::json vertices = nlohmann::json::array();
  for (const GraphVertex& v : graph.vertices) {
    vertices.push_back({{"id", v.id},
                        {"voxels", v.num_voxels},
                        {"centroid", {v.centroid.x(), v.centroid.y(), v.centroid.z()}},
                        {"initial_class", v.semantic},
                        {"void_share", v.void_share},
                        {"initial_instance", v.instance},
                        {"class", lookup(labels.semantic, v.id)},
                        {"instance", lookup(labels.instance, v.id)},
                        {"scores", classMap(v.scores)}});
  }
  nlohmann::json edges = nlohmann::json::array();
  for (const GraphEdge& e : graph.edges) {
    edges.push_back({{"a", e.a},
                     {"b", e.b},
                     {"confidences", classMap(e.confidences)},
                     {"separations", classMap(e.separations)},
                     {"apart", e.apart}});
  }
  const nlohmann::json root = {
      {"voxel_size_m", graph.voxel_size_m}, {"vertices", vertices}, {"edges", edges}};
  writeFileAtomically(path, root.dump() + "\n");
}

}  // namespace panmap

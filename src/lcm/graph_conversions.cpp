#include "panmap/lcm/graph_conversions.h"

#include <set>
#include <string>

#include "panmap/core/error.h"

namespace panmap {
namespace {

template <typename Keys, typename Values>
void putClassMap(const ClassValues& m, int32_t* count, Keys* keys, Values* values) {
  *count = static_cast<int32_t>(m.size());
  for (const auto& [cls, value] : m) {
    keys->push_back(cls);
    values->push_back(value);
  }
}

ClassValues getClassMap(int32_t count, const std::vector<int32_t>& keys,
                        const std::vector<double>& values, const std::string& what) {
  if (count < 0 || keys.size() != static_cast<size_t>(count) || values.size() != keys.size()) {
    throw Error(what + ": class arrays disagree with their count");
  }
  ClassValues m;
  m.reserve(keys.size());
  for (size_t i = 0; i < keys.size(); ++i) {
    if (!m.emplace(keys[i], values[i]).second) throw Error(what + ": class listed twice");
  }
  return m;
}

}  // namespace

superpoint_graph_t toMessage(const SuperpointGraph& graph, int64_t utime, int64_t request_id) {
  superpoint_graph_t msg;
  msg.utime = utime;
  msg.request_id = request_id;
  msg.voxel_size_m = graph.voxel_size_m;
  msg.num_classes = static_cast<int32_t>(graph.classes.size());
  msg.classes = graph.classes;
  msg.num_background = static_cast<int32_t>(graph.background.size());
  msg.background = graph.background;
  msg.num_vertices = static_cast<int32_t>(graph.vertices.size());
  for (const GraphVertex& v : graph.vertices) {
    superpoint_t m;
    m.id = v.id;
    m.num_voxels = v.num_voxels;
    for (int k = 0; k < 3; ++k) m.centroid[k] = v.centroid[k];
    m.instance = v.instance;
    m.semantic = v.semantic;
    m.void_share = v.void_share;
    putClassMap(v.scores, &m.num_scores, &m.score_classes, &m.scores);
    msg.vertices.push_back(m);
  }
  msg.num_edges = static_cast<int32_t>(graph.edges.size());
  for (const GraphEdge& e : graph.edges) {
    superpoint_edge_t m;
    m.a = e.a;
    m.b = e.b;
    putClassMap(e.confidences, &m.num_confidences, &m.classes, &m.confidences);
    putClassMap(e.separations, &m.num_separations, &m.separation_classes, &m.separations);
    m.apart = e.apart;
    msg.edges.push_back(m);
  }
  return msg;
}

SuperpointGraph fromMessage(const superpoint_graph_t& msg) {
  if (msg.classes.size() != static_cast<size_t>(msg.num_classes) ||
      msg.background.size() != static_cast<size_t>(msg.num_background) ||
      msg.vertices.size() != static_cast<size_t>(msg.num_vertices) ||
      msg.edges.size() != static_cast<size_t>(msg.num_edges)) {
    throw Error("graph message: arrays disagree with their counts");
  }
  SuperpointGraph g;
  g.classes = msg.classes;
  g.background = msg.background;
  g.voxel_size_m = msg.voxel_size_m;
  std::set<int32_t> ids;
  for (const superpoint_t& m : msg.vertices) {
    if (m.id <= 0 || (!g.vertices.empty() && m.id <= g.vertices.back().id)) {
      throw Error("graph message: vertex ids must be positive and ascending");
    }
    GraphVertex v;
    v.id = m.id;
    v.num_voxels = m.num_voxels;
    v.centroid = Eigen::Vector3d(m.centroid[0], m.centroid[1], m.centroid[2]);
    v.instance = m.instance;
    v.semantic = m.semantic;
    v.void_share = m.void_share;
    v.scores = getClassMap(m.num_scores, m.score_classes, m.scores,
                           "graph message vertex " + std::to_string(m.id));
    ids.insert(v.id);
    g.vertices.push_back(std::move(v));
  }
  for (const superpoint_edge_t& m : msg.edges) {
    if (m.a >= m.b || !ids.count(m.a) || !ids.count(m.b)) {
      throw Error("graph message: edge " + std::to_string(m.a) + "-" + std::to_string(m.b) +
                  " names unknown vertices or is not ordered");
    }
    GraphEdge e;
    e.a = m.a;
    e.b = m.b;
    e.confidences = getClassMap(m.num_confidences, m.classes, m.confidences, "graph message edge");
    e.separations = getClassMap(m.num_separations, m.separation_classes, m.separations,
                                "graph message edge separations");
    e.apart = m.apart;
    g.edges.push_back(std::move(e));
  }
  return g;
}

graph_labels_t toMessage(const GraphLabels& labels, int64_t utime, int64_t request_id) {
  graph_labels_t msg;
  msg.utime = utime;
  msg.request_id = request_id;
  for (const auto& [id, cls] : labels.semantic) {
    msg.superpoints.push_back(id);
    msg.semantic.push_back(cls);
    const auto it = labels.instance.find(id);
    msg.instance.push_back(it == labels.instance.end() ? 0 : it->second);
  }
  msg.num_superpoints = static_cast<int32_t>(msg.superpoints.size());
  for (const auto& [id, conf] : labels.instance_confidence) {
    msg.instance_ids.push_back(id);
    msg.instance_confidence.push_back(conf);
    const auto e = labels.instance_evidence.find(id);
    const ObjectEvidence evidence =
        e == labels.instance_evidence.end() ? ObjectEvidence() : e->second;
    msg.instance_area_m2.push_back(evidence.area_m2);
    msg.instance_support.push_back(evidence.support);
    msg.instance_class_share.push_back(evidence.class_share);
  }
  msg.num_instances = static_cast<int32_t>(msg.instance_ids.size());
  msg.fragments_folded = labels.fragments_folded;
  msg.fragments_dropped = labels.fragments_dropped;
  msg.solve_ms = labels.solve_ms;
  return msg;
}

GraphLabels fromMessage(const graph_labels_t& msg) {
  const auto n = static_cast<size_t>(msg.num_superpoints);
  if (msg.num_superpoints < 0 || msg.superpoints.size() != n || msg.semantic.size() != n ||
      msg.instance.size() != n || msg.num_instances < 0 ||
      msg.instance_ids.size() != static_cast<size_t>(msg.num_instances) ||
      msg.instance_confidence.size() != msg.instance_ids.size() ||
      msg.instance_area_m2.size() != msg.instance_ids.size() ||
      msg.instance_support.size() != msg.instance_ids.size() ||
      msg.instance_class_share.size() != msg.instance_ids.size()) {
    throw Error("labels message: arrays disagree with their counts");
  }
  GraphLabels labels;
  for (size_t i = 0; i < n; ++i) {
    labels.semantic[msg.superpoints[i]] = msg.semantic[i];
    labels.instance[msg.superpoints[i]] = msg.instance[i];
  }
  for (size_t i = 0; i < msg.instance_ids.size(); ++i) {
    labels.instance_confidence[msg.instance_ids[i]] = msg.instance_confidence[i];
    labels.instance_evidence[msg.instance_ids[i]] = {
        msg.instance_area_m2[i], msg.instance_support[i], msg.instance_class_share[i]};
  }
  labels.fragments_folded = msg.fragments_folded;
  labels.fragments_dropped = msg.fragments_dropped;
  labels.solve_ms = msg.solve_ms;
  return labels;
}

}  // namespace panmap

#include "panmap/mapper/final_labels.h"

#include <algorithm>

#include "panmap/core/classes.h"

namespace panmap {

SuperpointLabels finalLabels(int32_t superpoint, const SuperpointTracker& tracker,
                             const GraphLabels* labels) {
  SuperpointLabels out;
  if (const SuperpointState* state = tracker.state(superpoint)) {
    out.semantic = state->semanticClass();
    out.instance = state->instance();
  }
  if (labels) {
    const auto s = labels->semantic.find(superpoint);
    if (s != labels->semantic.end()) out.semantic = s->second;
    const auto i = labels->instance.find(superpoint);
    if (i != labels->instance.end()) out.instance = i->second;
  }
  // An instance is an object of a thing class, as the optimiser makes them: a super-point
  // whose frame counts say unlabelled or wall joined a frame-count instance through one
  // thing mask, and live objects of class 0 or "wall" came of it.
  if (out.semantic <= 0 || isStuffClass(out.semantic)) out.instance = 0;
  return out;
}

int32_t largestInitialInstance(const SuperpointGraph& graph) {
  int32_t largest = 0;
  for (const GraphVertex& v : graph.vertices) largest = std::max(largest, v.instance);
  return largest;
}

GraphLabels fitLabelsToMap(const GraphLabels& labels, int32_t graph_largest_instance,
                           const SuperpointTracker& tracker) {
  bool clash = false;
  for (const auto& [superpoint, state] : tracker.states()) {
    if (labels.instance.count(superpoint)) continue;
    if (state.instance() > graph_largest_instance) {
      clash = true;
      break;
    }
  }
  if (!clash) return labels;
  // Above every id the tracker has given, so no frame-count instance can have it.
  const int32_t shift = std::max(0, tracker.numInstances() - graph_largest_instance);
  const auto moved = [&](int32_t id) { return id > graph_largest_instance ? id + shift : id; };
  GraphLabels out = labels;
  for (auto& [superpoint, instance] : out.instance) instance = moved(instance);
  out.instance_confidence.clear();
  for (const auto& [id, confidence] : labels.instance_confidence) {
    out.instance_confidence[moved(id)] = confidence;
  }
  out.instance_evidence.clear();
  for (const auto& [id, evidence] : labels.instance_evidence) {
    out.instance_evidence[moved(id)] = evidence;
  }
  return out;
}

}  // namespace panmap

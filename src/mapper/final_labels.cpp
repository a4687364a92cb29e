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
  // The frame-count ids given since the graph was taken move above every id of the answer, by
  // an offset fixed by the answer alone. Moving the answer's ids above the tracker's instead
  // renumbered the optimiser's objects at every publish (the tracker keeps giving ids), and the
  // ids they left were given to other objects: a planner's object changed its identity.
  int32_t answer_largest = graph_largest_instance;
  for (const auto& [superpoint, instance] : labels.instance) {
    answer_largest = std::max(answer_largest, instance);
  }
  for (const auto& [id, confidence] : labels.instance_confidence) {
    answer_largest = std::max(answer_largest, id);
  }
  for (const auto& [id, evidence] : labels.instance_evidence) {
    answer_largest = std::max(answer_largest, id);
  }
  const int32_t shift = answer_largest - graph_largest_instance;
  GraphLabels out = labels;
  if (shift == 0) return out;
  for (const auto& [superpoint, state] : tracker.states()) {
    if (labels.instance.count(superpoint)) continue;
    const int32_t id = state.instance();
    if (id > graph_largest_instance) out.instance[superpoint] = id + shift;
  }
  return out;
}

}  // namespace panmap

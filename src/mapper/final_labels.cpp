#include "panmap/mapper/final_labels.h"

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
  return out;
}

}  // namespace panmap

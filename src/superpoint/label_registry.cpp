#include "panmap/superpoint/label_registry.h"

#include "panmap/core/error.h"

namespace panmap {

int32_t LabelRegistry::create() {
  parent_.push_back(static_cast<int32_t>(parent_.size()));
  return parent_.back();
}

int32_t LabelRegistry::resolveDeep(int32_t label) const {
  int32_t root = label;
  while (parent_[root] != root) root = parent_[root];
  while (parent_[label] != root) {  // path compression
    const int32_t next = parent_[label];
    parent_[label] = root;
    label = next;
  }
  return root;
}

void LabelRegistry::flatten() const {
  // Parents never exceed their label, so one pass in increasing order finds every root.
  for (size_t i = 1; i < parent_.size(); ++i) parent_[i] = parent_[parent_[i]];
}

int32_t LabelRegistry::merge(int32_t a, int32_t b) {
  const int32_t ra = resolve(a), rb = resolve(b);
  if (ra == 0 || rb == 0) throw Error("cannot merge unknown super-point labels");
  if (ra == rb) return ra;
  const int32_t keep = std::min(ra, rb), gone = std::max(ra, rb);
  parent_[gone] = keep;
  return keep;
}

void LabelRegistry::restore(std::vector<int32_t> parents) {
  if (parents.empty() || parents[0] != 0) throw Error("super-point labels: bad parent array");
  for (size_t i = 1; i < parents.size(); ++i) {
    if (parents[i] < 0 || parents[i] > static_cast<int32_t>(i)) {
      throw Error("super-point labels: parent of " + std::to_string(i) + " is invalid");
    }
  }
  parent_ = std::move(parents);
}

void LabelRegistry::renumber(const std::vector<int32_t>& roots, int32_t size) {
  if (size < 0) throw Error("super-point labels: negative size");
  std::vector<int32_t> parents(static_cast<size_t>(size) + 1, 0);
  for (const int32_t root : roots) {
    if (root <= 0 || root > size) {
      throw Error("super-point labels: root " + std::to_string(root) + " outside 1.." +
                  std::to_string(size));
    }
    parents[root] = root;
  }
  parent_ = std::move(parents);
}

}  // namespace panmap

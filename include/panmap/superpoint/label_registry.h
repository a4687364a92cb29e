#pragma once

#include <cstdint>
#include <map>
#include <vector>

namespace panmap {

/// Super-point labels L_S: integer ids from 1, merged through a union-find so that every id
/// ever handed out stays resolvable to the super-point it belongs to now, or to 0 once it is
/// retired (renumber(): a repair gave its super-point another id).
class LabelRegistry {
 public:
  /// A new label (ids are consecutive from 1).
  int32_t create();
  /// The label a (possibly merged-away) label belongs to now; 0 stays 0.
  int32_t resolve(int32_t label) const {
    if (label <= 0 || label >= static_cast<int32_t>(parent_.size())) return 0;
    // Inline for the common case, a root or a root's child (always after flatten()): the
    // scans, graph update and meshing call it per voxel.
    const int32_t parent = parent_[label];
    if (parent_[parent] == parent) return parent;
    return resolveDeep(label);
  }
  /// Points every label straight at its root. Until the next merge or create, resolve() then
  /// only reads, so several threads may call it at once.
  void flatten() const;
  /// Merges two super-points; the smaller (older) root survives. Returns the survivor.
  int32_t merge(int32_t a, int32_t b);
  /// Number of labels ever created.
  int32_t size() const { return static_cast<int32_t>(parent_.size()) - 1; }
  /// True when a label is its own root (a live super-point).
  bool isRoot(int32_t label) const {
    return label > 0 && label < static_cast<int32_t>(parent_.size()) && parent_[label] == label;
  }
  /// Parent array (index = label; parent_[0] = 0; 0 for a retired label) for saving.
  const std::vector<int32_t>& parents() const { return parent_; }
  /// Restores from a saved parent array (validated: every parent <= its label; 0 = retired).
  void restore(std::vector<int32_t> parents);
  /// Replaces the registry by one in which `roots` (each in 1..size) are live super-points and
  /// every other label up to `size` is retired: it resolves to 0 and is never handed out again.
  /// New labels start at size + 1. Throws Error, changing nothing, on a root outside 1..size.
  void renumber(const std::vector<int32_t>& roots, int32_t size);

 private:
  // resolve() of a label two or more links below its root; compresses the path.
  int32_t resolveDeep(int32_t label) const;

  // Mutable: resolve() compresses paths (the result never changes, only the speed).
  mutable std::vector<int32_t> parent_ = {0};
};

}  // namespace panmap

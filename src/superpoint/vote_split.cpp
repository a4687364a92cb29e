#include "panmap/superpoint/vote_split.h"

#include <string>
#include <vector>

#include "panmap/core/error.h"
#include "panmap/map/voxel.h"
#include "panmap/map/voxel_lookup.h"

namespace panmap {

namespace {

// Moves the votes of `from` (after resolving) in `voxel` to `to`; true when any moved.
bool moveVotes(Voxel* voxel, int32_t from, int32_t to, const LabelRegistry& labels) {
  uint64_t moved = 0;
  for (LabelVote& vote : voxel->votes) {
    if (vote.count == 0 || labels.resolve(vote.label) != from) continue;
    moved += vote.count;
    vote = LabelVote{};
  }
  if (moved == 0) return false;
  // The slot just emptied takes the new label, so nothing is evicted.
  addVotes(voxel, to, moved > UINT32_MAX ? UINT32_MAX : static_cast<uint32_t>(moved));
  return true;
}

}  // namespace

size_t applySplits(FrameAssociation* association, const FrameSegmentation& segmentation,
                   const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C,
                   const LabelRegistry& labels, TsdfMap* map) {
  std::vector<SuperpointSplit>& splits = association->splits;
  if (splits.empty()) return 0;
  const PinholeCamera& cam = frame.camera;
  const int w = cam.width, h = cam.height;
  if (segmentation.surfaces.width() != w || segmentation.surfaces.height() != h ||
      frame.depth.width() != w || frame.depth.height() != h) {
    throw Error("super-point splits: segmentation or depth size differs from the camera's");
  }
  const size_t n = segmentation.surface_list.size();
  if (association->surface_labels.size() != n) {
    throw Error("super-point splits: association and segmentation disagree on the surfaces");
  }
  // Per surface id: the split it starts (index + 1), and the split whose super-point it kept.
  std::vector<size_t> split_of(n + 1, 0), kept_of(n + 1, 0);
  for (size_t i = 0; i < splits.size(); ++i) {
    const int32_t id = splits[i].surface_id;
    if (id <= 0 || static_cast<size_t>(id) > n) {
      throw Error("super-point splits: unknown surface " + std::to_string(id));
    }
    split_of[id] = i + 1;
    const int32_t from = labels.resolve(splits[i].from);
    for (size_t s = 0; s < n; ++s) {
      if (labels.resolve(association->surface_labels[s]) == from) kept_of[s + 1] = i + 1;
    }
  }
  const Eigen::Isometry3f T = T_W_C.cast<float>();
  const float scale = static_cast<float>(frame.depth_scale_m);
  const float fx = static_cast<float>(cam.fx), fy = static_cast<float>(cam.fy);
  const float cx = static_cast<float>(cam.cx), cy = static_cast<float>(cam.cy);
  // Point sums and counts of each split's two sides: [2 i] the split surface, [2 i + 1] the
  // surface that kept the super-point.
  std::vector<Eigen::Vector3d> sums(2 * splits.size(), Eigen::Vector3d::Zero());
  std::vector<size_t> counts(2 * splits.size(), 0);
  MutableVoxelLookup lookup(*map);
  size_t changed = 0;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const int32_t sid = segmentation.surfaces(u, v);
      if (sid <= 0 || static_cast<size_t>(sid) > n) continue;
      if (split_of[sid] == 0 && kept_of[sid] == 0) continue;
      const float d = frame.depth(u, v) * scale;
      if (!(d > 0.0f)) continue;
      const Eigen::Vector3f p_W = T * Eigen::Vector3f((u - cx) * d / fx, (v - cy) * d / fy, d);
      if (kept_of[sid] != 0) {
        sums[2 * (kept_of[sid] - 1) + 1] += p_W.cast<double>();
        ++counts[2 * (kept_of[sid] - 1) + 1];
      }
      if (split_of[sid] == 0) continue;
      const size_t i = split_of[sid] - 1;
      sums[2 * i] += p_W.cast<double>();
      ++counts[2 * i];
      Voxel* voxel = lookup.find(p_W);
      if (voxel) changed += moveVotes(voxel, labels.resolve(splits[i].from), splits[i].to, labels);
    }
  }
  for (size_t i = 0; i < splits.size(); ++i) {
    splits[i].distance_m = counts[2 * i] > 0 && counts[2 * i + 1] > 0
                               ? (sums[2 * i] / static_cast<double>(counts[2 * i]) -
                                  sums[2 * i + 1] / static_cast<double>(counts[2 * i + 1]))
                                     .norm()
                               : -1.0;
  }
  return changed;
}

}  // namespace panmap

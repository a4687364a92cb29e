#include "panmap/superpoint/vote_split.h"

#include <string>
#include <vector>

#include "panmap/core/error.h"
#include "panmap/map/row_grid.h"
#include "panmap/map/voxel.h"
#include "panmap/map/voxel_lookup.h"

namespace panmap {

namespace {

// Moves the votes of `from` (after resolving) in a voxel's `votes` to `to`; true when any
// moved.
bool moveVotes(VoxelVotes* votes, int32_t from, int32_t to, const LabelRegistry& labels) {
  uint64_t moved = 0;
  for (LabelVote& vote : *votes) {
    if (vote.count == 0 || labels.resolve(vote.label) != from) continue;
    moved += vote.count;
    vote = LabelVote{};
  }
  if (moved == 0) return false;
  // The slot just emptied takes the new label, so nothing is evicted.
  addVotes(votes, to, moved > kMaxVoteCount ? kMaxVoteCount : static_cast<uint32_t>(moved));
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
  // Per surface id: the split it starts (index + 1), and the super-point it kept when another
  // surface split from it (index + 1 into `kept`; several surfaces may split from one).
  std::vector<size_t> split_of(n + 1, 0), kept_of(n + 1, 0);
  std::vector<int32_t> from(splits.size()), kept;
  std::vector<size_t> kept_index(splits.size());
  for (size_t i = 0; i < splits.size(); ++i) {
    const int32_t id = splits[i].surface_id;
    if (id <= 0 || static_cast<size_t>(id) > n) {
      throw Error("super-point splits: unknown surface " + std::to_string(id));
    }
    split_of[id] = i + 1;
    from[i] = labels.resolve(splits[i].from);
    size_t k = 0;
    while (k < kept.size() && kept[k] != from[i]) ++k;
    if (k == kept.size()) kept.push_back(from[i]);
    kept_index[i] = k;
  }
  for (size_t s = 0; s < n; ++s) {
    const int32_t label = labels.resolve(association->surface_labels[s]);
    for (size_t k = 0; k < kept.size(); ++k) {
      if (kept[k] == label) kept_of[s + 1] = k + 1;
    }
  }
  const Eigen::Isometry3f T = T_W_C.cast<float>();
  const float scale = static_cast<float>(frame.depth_scale_m);
  const float fx = static_cast<float>(cam.fx), fy = static_cast<float>(cam.fy);
  const float cx = static_cast<float>(cam.cx), cy = static_cast<float>(cam.cy);
  // Point sums and counts of each split surface, and of each surface that kept a super-point.
  std::vector<Eigen::Vector3d> split_sum(splits.size(), Eigen::Vector3d::Zero());
  std::vector<Eigen::Vector3d> kept_sum(kept.size(), Eigen::Vector3d::Zero());
  std::vector<size_t> split_count(splits.size(), 0), kept_count(kept.size(), 0);
  MutableVoxelLookup lookup(*map);
  size_t changed = 0;
  const RowCamera row_cam = RowCamera::of(cam);
  for (int v = 0; v < h; ++v) {
    // The voxels the pixels voted in, found as the votes were cast.
    const RowGrid grid(T, row_cam, lookup.inverseVoxelSize(), v);
    for (int u = 0; u < w; ++u) {
      const int32_t sid = segmentation.surfaces(u, v);
      if (sid <= 0 || static_cast<size_t>(sid) > n) continue;
      if (split_of[sid] == 0 && kept_of[sid] == 0) continue;
      const float d = frame.depth(u, v) * scale;
      if (!(d > 0.0f)) continue;
      const Eigen::Vector3f p_W = T * Eigen::Vector3f((u - cx) * d / fx, (v - cy) * d / fy, d);
      if (kept_of[sid] != 0) {
        kept_sum[kept_of[sid] - 1] += p_W.cast<double>();
        ++kept_count[kept_of[sid] - 1];
      }
      if (split_of[sid] == 0) continue;
      const size_t i = split_of[sid] - 1;
      split_sum[i] += p_W.cast<double>();
      ++split_count[i];
      VoxelVotes* votes = lookup.findGridVotes(grid.voxel(u, d));
      if (votes) changed += moveVotes(votes, from[i], splits[i].to, labels);
    }
  }
  for (size_t i = 0; i < splits.size(); ++i) {
    const size_t k = kept_index[i];
    splits[i].distance_m = split_count[i] > 0 && kept_count[k] > 0
                               ? (split_sum[i] / static_cast<double>(split_count[i]) -
                                  kept_sum[k] / static_cast<double>(kept_count[k]))
                                     .norm()
                               : -1.0;
  }
  return changed;
}

}  // namespace panmap

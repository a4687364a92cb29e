#include "panmap/superpoint/vote_split.h"

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

size_t applySplits(const FrameAssociation& association, const FrameSegmentation& segmentation,
                   const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C,
                   const LabelRegistry& labels, TsdfMap* map) {
  if (association.splits.empty()) return 0;
  const PinholeCamera& cam = frame.camera;
  const int w = cam.width, h = cam.height;
  if (segmentation.surfaces.width() != w || segmentation.surfaces.height() != h ||
      frame.depth.width() != w || frame.depth.height() != h) {
    throw Error("super-point splits: segmentation or depth size differs from the camera's");
  }
  // Split index + 1 per surface id, 0 for the surfaces that did not split.
  std::vector<size_t> split_of(segmentation.surface_list.size() + 1, 0);
  for (size_t i = 0; i < association.splits.size(); ++i) {
    const int32_t id = association.splits[i].surface_id;
    if (id <= 0 || static_cast<size_t>(id) >= split_of.size()) {
      throw Error("super-point splits: unknown surface " + std::to_string(id));
    }
    split_of[id] = i + 1;
  }
  const Eigen::Isometry3f T = T_W_C.cast<float>();
  const float scale = static_cast<float>(frame.depth_scale_m);
  const float fx = static_cast<float>(cam.fx), fy = static_cast<float>(cam.fy);
  const float cx = static_cast<float>(cam.cx), cy = static_cast<float>(cam.cy);
  MutableVoxelLookup lookup(*map);
  size_t changed = 0;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const int32_t sid = segmentation.surfaces(u, v);
      if (sid <= 0 || static_cast<size_t>(sid) >= split_of.size() || split_of[sid] == 0) continue;
      const float d = frame.depth(u, v) * scale;
      if (!(d > 0.0f)) continue;
      Voxel* voxel = lookup.find(T * Eigen::Vector3f((u - cx) * d / fx, (v - cy) * d / fy, d));
      if (!voxel) continue;
      const SuperpointSplit& split = association.splits[split_of[sid] - 1];
      changed += moveVotes(voxel, labels.resolve(split.from), split.to, labels);
    }
  }
  return changed;
}

}  // namespace panmap

#pragma once

#include <cstddef>

#include <Eigen/Geometry>

#include "panmap/core/frame.h"
#include "panmap/map/tsdf_map.h"
#include "panmap/segmentation/panoptic_geometric.h"
#include "panmap/superpoint/label_registry.h"
#include "panmap/superpoint/superpoint_tracker.h"

namespace panmap {

/// Carries out a frame's super-point splits (FrameAssociation::splits): in every voxel a
/// split surface's pixels fall in, the votes for the super-point it split from (any label
/// resolving to it) become votes for its new one, so the voxels change super-point at once.
/// Also measures each split's SuperpointSplit::distance_m. Call after
/// SuperpointTracker::associate() and before integrating the frame.
/// @return the number of voxels whose votes moved
size_t applySplits(FrameAssociation* association, const FrameSegmentation& segmentation,
                   const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C,
                   const LabelRegistry& labels, TsdfMap* map);

}  // namespace panmap

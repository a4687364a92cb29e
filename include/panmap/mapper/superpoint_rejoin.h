#pragma once

#include <cstddef>

#include "panmap/map/tsdf_map.h"
#include "panmap/superpoint/superpoint_tracker.h"

namespace panmap {

/// A super-point holds at least this share of another's votes (counting each voxel's votes of
/// the two up to the smaller of them) for the two to count as one surface: more than half of
/// the smaller one's surface is also the larger one's, so it cannot be a neighbour touching it
/// along an edge.
constexpr double kRejoinMinShare = 0.5;

/// Joins the super-points a re-integration laid over one another (docs/LOOP_CLOSURE.md).
/// Under drift, association failed to find a surface seen again and gave it a second
/// super-point (and often a second object); once the frames vote again at their corrected
/// poses, both super-points vote for the same voxels and split the surface between them. Each
/// pair whose shared votes (per voxel the smaller of the two's) reach `min_share` of the
/// smaller one's votes in `map`, and did not in `before` (the map the re-integration replaces:
/// there association left them apart with the frames it had, and a repair that moves nothing
/// changes nothing), is offered to SuperpointTracker::rejoin(), where III-B's rule decides;
/// the pairs sharing most votes first, each super-point in one merge at most (a super-point
/// over two neighbours would otherwise join them). The graph follows the tracker's merge log
/// (GraphAccumulator::applyMerges()).
/// @return the number of merges
size_t rejoinCoincidingSuperpoints(const TsdfMap& map, const TsdfMap* before,
                                   SuperpointTracker* tracker, double min_share = kRejoinMinShare);

}  // namespace panmap

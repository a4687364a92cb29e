#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "panmap/loop/frame_store.h"
#include "panmap/loop/pose_correction.h"
#include "panmap/mapper/mapper.h"

namespace panmap {

/// How a correction is turned into a repair.
struct MapRepairConfig {
  /// A corrected utime matches the mapped frame nearest in time within this, microseconds
  /// (0: exactly). A back-end that keeps stamps as seconds in a double, or in another clock's
  /// ticks, gives them back a few microseconds off; 1 ms is far below any camera's frame period.
  int64_t match_tolerance_us = 1000;
  /// When the store holds panoptic segmentations, map the frames again (Mapper::remap:
  /// super-points, graph and objects made anew; a frame stored without one is mapped without,
  /// as it was) instead of re-integrating them with the super-points association gave them
  /// under the old poses. Costs the whole pipeline per frame instead of integration alone
  /// (docs/LOOP_CLOSURE.md). Once a repair has mapped the frames again, the pixel labels in
  /// the store name super-points that are gone: only a remap repairs such a map correctly.
  bool reassociate = true;
  /// A repair on its own thread (BackgroundRepair) that maps the frames again first rebuilds
  /// the occupancy tree alone and swaps it in (OccupancyRebuild: a planner's phantom obstacles
  /// go after about 2 ms a frame instead of the whole pipeline's 10-20), then maps the frames
  /// again as before; the tree the repair commits is the same.
  bool occupancy_first = true;
  /// A repair on its own thread that maps the frames again first re-integrates them (each
  /// frame votes again for the super-points it voted for, as with reassociate off: about a
  /// third of mapping them again) and swaps that map in, occupancy tree included, then maps the
  /// frames again and swaps the result in at the end. The map is repaired in geometry, labels
  /// and objects long before the association is done again; pixel labels naming super-points a
  /// former repair retired vote for nothing until then. With occupancy_first too, the tree
  /// comes first and this map after it (a second pass over the frames).
  bool reintegrate_first = false;
  /// A correction that moves no camera farther than these (metres, radians) leaves the map as
  /// it is, counted as applied: resending the poses the map holds cost a whole repair and
  /// renumbered objects and super-points.
  double min_move_m = 1e-4;
  double min_turn_rad = 1e-4;
  /// Throws Error naming the bad field.
  void check() const;
};

/// A FrameLoader that gives back the frames of `store` (FrameStore::load without the
/// segmentation, which a re-integration does not use; callable from any
/// thread). Throws Error when `store` is null.
FrameLoader storeLoader(const FrameStore* store);

/// A PanopticFrameLoader that gives back the frames of `store` with their segmentations
/// (callable from any thread). Throws Error when `store` is null.
PanopticFrameLoader storePanopticLoader(const FrameStore* store);

/// What one repair did.
struct MapRepairResult {
  int64_t correction_id = 0;
  int matched = 0;                      ///< corrected utimes that matched a mapped frame
  std::vector<int64_t> unknown_utimes;  ///< corrected utimes of no mapped frame: not used
  double max_translation_m = 0.0;       ///< largest move of a camera centre
  double max_rotation_rad = 0.0;        ///< largest turn of a camera
  ReintegrationStats reintegration;     ///< completed = false: abandoned, map unchanged
  std::string failure;                  ///< why a background repair gave up (empty: it did not)
  /// Seconds after the correction at which a background repair's early pass first swapped in
  /// a repaired occupancy tree: the tree it built first (MapRepairConfig::occupancy_first), or,
  /// with the re-integrated map alone, the map's own tree (then equal to map_swapped_s);
  /// negative: neither was swapped in early.
  double occupancy_swapped_s = -1.0;
  /// Seconds after the correction at which a background repair swapped in the re-integrated
  /// map it built first (MapRepairConfig::reintegrate_first); negative: it did not.
  double map_swapped_s = -1.0;
  /// Super-points that joined another at that swap (ReintegrationStats::superpoints_rejoined).
  size_t map_swapped_rejoined = 0;
  double map_swapped_rejoin_s = 0.0;  ///< and the time that took
  /// No frame moved more than MapRepairConfig::min_move_m / min_turn_rad: nothing was
  /// repaired, and reintegration.completed is set (the correction counts as applied).
  bool nothing_moved = false;
};

/// A repair's result as far as matching goes: the correction's id, the utimes it matched and
/// did not, and the largest move and turn it makes (the repair's own fields left empty).
MapRepairResult matchedResult(const PoseCorrection& correction,
                              const CorrectedTrajectory& corrected);

/// True when the corrected trajectory moves no camera beyond config's min_move_m and
/// min_turn_rad: a correction with nothing to repair.
bool negligible(const CorrectedTrajectory& corrected, const MapRepairConfig& config);

/// The repair after a loop closure (docs/LOOP_CLOSURE.md): spreads the correction over every
/// mapped frame (applyCorrection), maps the frames from the store again at their new poses
/// (Mapper::remap when config.reassociate and the store holds segmentations, else
/// Mapper::reintegrate) and records the new poses in the store, so that the next correction
/// starts from them. Throws Error, changing nothing, when the correction is invalid, when none
/// of its utimes is a mapped frame (named), or when a mapped frame is missing from the store.
/// Corrected utimes that match no frame are returned, never guessed.
/// @param progress optional; returning false abandons the repair (map and store unchanged)
MapRepairResult repairMap(Mapper* mapper, FrameStore* store, const PoseCorrection& correction,
                          const MapRepairConfig& config = {},
                          const ReintegrationProgress& progress = {});

/// One line for logs and the status channel: "correction 7: 12 of 13 poses matched (unknown
/// utime 123), 600 frames re-integrated in 4.1 s, largest move 0.21 m / 3.2 deg".
std::string describe(const MapRepairResult& result);

}  // namespace panmap

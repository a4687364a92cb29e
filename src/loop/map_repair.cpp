#include "panmap/loop/map_repair.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "panmap/core/error.h"

namespace panmap {

void MapRepairConfig::check() const {
  if (match_tolerance_us < 0) throw Error("map repair match_tolerance_us must be >= 0");
  if (!(min_move_m >= 0.0) || !(min_turn_rad >= 0.0)) {
    throw Error("map repair min_move_m and min_turn_rad must be >= 0");
  }
}

FrameLoader storeLoader(const FrameStore* store) {
  if (!store) throw Error("frame loader: no frame store");
  return [store](int64_t utime, RgbdFrame* frame, LabelImage* labels) {
    // A re-integration votes with the stored labels: the segmentation is not decoded.
    StoredFrame stored = store->load(utime, FrameStore::Parts::kWithoutSegmentation);
    *frame = std::move(stored.rgbd);
    *labels = std::move(stored.labels);
  };
}

PanopticFrameLoader storePanopticLoader(const FrameStore* store) {
  if (!store) throw Error("frame loader: no frame store");
  return
      [store](int64_t utime, RgbdFrame* frame, PanopticFrame* panoptic, GeometricSegments* kept) {
        StoredFrame stored = store->load(utime);
        *frame = std::move(stored.rgbd);
        *panoptic = std::move(stored.panoptic);
        *kept = std::move(stored.geometric);
        return stored.has_panoptic;
      };
}

MapRepairResult matchedResult(const PoseCorrection& correction,
                              const CorrectedTrajectory& corrected) {
  MapRepairResult result;
  result.correction_id = correction.correction_id;
  result.matched = corrected.matched;
  result.unknown_utimes = corrected.unknown_utimes;
  result.max_translation_m = corrected.max_translation_m;
  result.max_rotation_rad = corrected.max_rotation_rad;
  return result;
}

bool negligible(const CorrectedTrajectory& corrected, const MapRepairConfig& config) {
  return corrected.max_translation_m <= config.min_move_m &&
         corrected.max_rotation_rad <= config.min_turn_rad;
}

MapRepairResult repairMap(Mapper* mapper, FrameStore* store, const PoseCorrection& correction,
                          const MapRepairConfig& config, const ReintegrationProgress& progress) {
  config.check();
  const std::string name = "correction " + std::to_string(correction.correction_id);
  try {
    correction.check();
  } catch (const Error& e) {
    throw Error(name + ": " + e.what());
  }
  const CorrectedTrajectory corrected =
      applyCorrection(mapper->trajectory(), correction, config.match_tolerance_us);
  MapRepairResult result = matchedResult(correction, corrected);
  if (corrected.matched == 0) {
    throw Error(
        name + ": " +
        unmatchedCorrectionReason(mapper->trajectory(), correction, config.match_tolerance_us));
  }
  if (negligible(corrected, config)) {
    result.nothing_moved = true;
    result.reintegration.completed = true;
    return result;
  }
  // Association under the old poses may have joined surfaces to the wrong super-points;
  // with the segmentations stored, the frames are associated again. A store that holds some
  // keeps every frame's: one stored without was mapped without (and is mapped so again).
  if (config.reassociate && store->sizeWithPanoptic() > 0) {
    result.reintegration = mapper->remap(corrected.poses, storePanopticLoader(store), progress);
  } else {
    result.reintegration = mapper->reintegrate(corrected.poses, storeLoader(store), progress);
  }
  if (result.reintegration.completed) {
    // Only what moved: the store's poses are the ones the frames are now integrated with.
    for (size_t i = 0; i < corrected.poses.size(); ++i) {
      if (corrected.translation_m[i] > 0.0 || corrected.rotation_rad[i] > 0.0) {
        store->updatePose(corrected.poses[i].utime, corrected.poses[i].T_W_C);
      }
    }
  }
  return result;
}

std::string describe(const MapRepairResult& r) {
  char line[256];
  std::string unknown;
  if (!r.unknown_utimes.empty()) {
    unknown = " (unknown utime" + std::string(r.unknown_utimes.size() > 1 ? "s " : " ") +
              std::to_string(r.unknown_utimes.front()) +
              (r.unknown_utimes.size() > 1 ? ", ..." : "") + ")";
  }
  const int total = r.matched + static_cast<int>(r.unknown_utimes.size());
  if (r.nothing_moved) {
    std::snprintf(line, sizeof(line),
                  "correction %lld: %d of %d poses matched%s, no camera moved (largest move "
                  "%.5f m / %.4f deg): the map stays as it is",
                  static_cast<long long>(r.correction_id), r.matched, total, unknown.c_str(),
                  r.max_translation_m, r.max_rotation_rad * 180.0 / M_PI);
    return line;
  }
  if (!r.reintegration.completed) {
    std::snprintf(line, sizeof(line), "correction %lld: %d of %d poses matched%s, abandoned",
                  static_cast<long long>(r.correction_id), r.matched, total, unknown.c_str());
    return r.failure.empty() ? std::string(line) : line + (": " + r.failure);
  }
  std::snprintf(line, sizeof(line),
                "correction %lld: %d of %d poses matched%s, %zu frames %s (%zu moved) "
                "in %.2f s, largest move %.3f m / %.2f deg",
                static_cast<long long>(r.correction_id), r.matched, total, unknown.c_str(),
                r.reintegration.frames,
                r.reintegration.reassociated ? "mapped again" : "re-integrated",
                r.reintegration.frames_moved, r.reintegration.seconds, r.max_translation_m,
                r.max_rotation_rad * 180.0 / M_PI);
  std::string out = line;
  if (r.reintegration.frames_with_kept_segments > 0) {
    out += "; kept geometric segments of " +
           std::to_string(r.reintegration.frames_with_kept_segments) + " frames";
  }
  if (r.occupancy_swapped_s >= 0.0 &&
      (r.map_swapped_s < 0.0 || r.occupancy_swapped_s < r.map_swapped_s)) {
    char occupancy[80];
    std::snprintf(occupancy, sizeof(occupancy), "; occupancy swapped in after %.2f s",
                  r.occupancy_swapped_s);
    out += occupancy;
  }
  if (r.map_swapped_s >= 0.0) {
    char early[160];
    std::snprintf(early, sizeof(early),
                  "; re-integrated map swapped in after %.2f s (%zu super-points rejoined in "
                  "%.2f s)",
                  r.map_swapped_s, r.map_swapped_rejoined, r.map_swapped_rejoin_s);
    out += early;
  }
  if (r.reintegration.reassociated) {
    char ids[160];
    std::snprintf(ids, sizeof(ids),
                  "; ids kept: %zu of %zu instances (%.0f %% of the surface), %zu of %zu "
                  "super-points (%.0f %%)",
                  r.reintegration.instances_kept, r.reintegration.instances,
                  100.0 * r.reintegration.instance_surface_kept, r.reintegration.superpoints_kept,
                  r.reintegration.superpoints, 100.0 * r.reintegration.superpoint_surface_kept);
    out += ids;
  } else if (r.reintegration.superpoints_rejoined > 0) {
    char rejoined[120];
    std::snprintf(rejoined, sizeof(rejoined),
                  "; %zu super-points rejoined the one they coincide with (%.2f s)",
                  r.reintegration.superpoints_rejoined, r.reintegration.rejoin_s);
    out += rejoined;
  }
  return out;
}

}  // namespace panmap

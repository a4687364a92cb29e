#pragma once

#include <cstdint>
#include <vector>

#include <absl/container/flat_hash_set.h>
#include <Eigen/Geometry>

#include "panmap/core/frame.h"
#include "panmap/core/image.h"
#include "panmap/core/thread_pool.h"
#include "panmap/map/internal/vote_rows.h"
#include "panmap/map/tsdf_map.h"

namespace panmap {

/// Parameters of label-TSDF integration.
struct IntegratorConfig {
  float truncation_voxels = 4.0f;  ///< truncation distance, voxels
  float max_weight = 100.0f;       ///< weights saturate here, so the map can still change
  float min_depth_m = 0.1f;        ///< depth outside [min, max] is ignored, metres
  float max_depth_m = 3.5f;        // noise grows as z^2: 4 cm sigma at 5 m, the truncation band
  bool weight_dropoff = true;      ///< behind the surface, weight falls linearly to 0 at -trunc
  /// Also allocate blocks between camera and surface and record free space there (voxels
  /// farther than the truncation in front of the surface); off: only the truncation band.
  bool space_carving = false;
  /// Pixels between label votes (1 = every labelled pixel votes in its point's voxel); 0 =
  /// automatic: the largest stride whose samples, at max_depth_m, still fall at most half a
  /// voxel apart (1 at 1-2 cm voxels and a 525-585 px focal length, 3-4 at 5 cm; see
  /// voteStride()). Not the default: at 5 cm it changes which objects merge or take a wrong
  /// class, beyond issue 23's bar of 0.5 mAP50 per scene (docs/VOTE_STRIDE.md).
  int vote_stride_px = 1;
  /// Throws Error naming the bad field.
  void check() const;
};

/// The vote stride `config` gives for voxels of `voxel_size_m` seen by a camera of focal length
/// `fx_px`: config.vote_stride_px when set, else max(1, floor(voxel * fx / (2 max_depth))).
/// Neighbouring votes then land at most half a voxel apart at every depth used, so each surface
/// voxel a frame sees still gets votes; coarse voxels stop paying for hundreds of equal votes.
int voteStride(const IntegratorConfig& config, float voxel_size_m, double fx_px);

/// What one integration did.
struct IntegrationStats {
  size_t blocks_in_view = 0;    ///< blocks near the observed surface
  size_t blocks_allocated = 0;  ///< of those, new
  size_t voxels_updated = 0;
  size_t votes_added = 0;
  size_t votes_evicted = 0;  ///< votes that pushed out a weaker label (never silent)
};

/// Projective TSDF integration of depth, colour and per-pixel super-point labels into a
/// TsdfMap: each voxel near the surface projects into the image and fuses the pixel it hits.
/// Multi-threaded over blocks; deterministic (every voxel is touched by exactly one thread and
/// new blocks are allocated in sorted order).
class ProjectiveIntegrator {
 public:
  /// @param pool threads to use (shared with the caller; not owned)
  ProjectiveIntegrator(const IntegratorConfig& config, ThreadPool* pool);

  /// Integrates one frame seen from T_W_C (camera to world, optical frame).
  /// @param labels super-point label per pixel (0 = none), or null for geometry only
  IntegrationStats integrate(const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C,
                             const LabelImage* labels, TsdfMap* map);

  /// The config in use.
  const IntegratorConfig& config() const { return config_; }

 private:
  void voteLabels(const RgbdFrame& frame, const Eigen::Isometry3f& T_W_C, const LabelImage& labels,
                  TsdfMap* map, IntegrationStats* stats);

  IntegratorConfig config_;
  ThreadPool* pool_;
  Image<float> depth_m_;                                 // scratch: depth in metres, 0 = invalid
  std::vector<absl::flat_hash_set<uint64_t>> key_sets_;  // scratch: block keys seen, per thread
  std::vector<uint64_t> keys_;                           // scratch: the same, sorted
  std::vector<Block*> blocks_;                           // scratch: blocks in view
  // scratch: each band of rows' summed votes, `cols * kVoteBandRows` apart
  std::vector<VoteRun> vote_runs_;
  // scratch: where each owner's runs start in each band's slot (owners + 1 entries per band)
  std::vector<size_t> owner_begin_;
  /// Per-thread scratch of the vote lookup: one band's runs before they are grouped by owner.
  struct BandScratch {
    std::vector<VoteRun> runs;
    std::vector<uint32_t> owner;  // of each run
    std::vector<size_t> next;     // next free place of each owner in the band's slot
    internal::VoteSumTable sums;  // which run holds each voxel and label's sum
  };
  std::vector<BandScratch> band_scratch_;
};

}  // namespace panmap

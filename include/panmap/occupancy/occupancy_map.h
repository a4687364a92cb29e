#pragma once

#include <cstddef>
#include <memory>
#include <string>

#include <octomap/OcTree.h>
#include <Eigen/Geometry>

#include "panmap/core/binary_io.h"
#include "panmap/core/camera.h"
#include "panmap/core/frame.h"
#include "panmap/core/image.h"
#include "panmap/occupancy/internal/depth_tile_max.h"
#include "panmap/occupancy/occupancy_grid.h"
#include "panmap/occupancy/occupancy_query.h"

namespace panmap {

/// What one frame's update did.
struct OccupancyUpdateStats {
  size_t depth_samples = 0;     ///< sampled pixels with depth in [min, max]: hit candidates
  size_t cells_tested = 0;      ///< cells projected into the image for the free test
  size_t blocks_skipped = 0;    ///< 8^3-cell blocks skipped untested: behind the surface
  size_t occupied_updates = 0;  ///< distinct cells updated as occupied (a hit)
  size_t free_updates = 0;      ///< distinct cells updated as free (a miss)
};

/// Occupancy for planners: free, occupied and unknown space at a configurable resolution,
/// exported as an OctoMap OcTree (occupancy.bt, the PANMAP_OCTOMAP message).
///
/// Where free space comes from: the label-TSDF observes only a truncation band of a few voxels
/// around surfaces (space carving is off by default), so it cannot say that the middle of a
/// room is free. Free space comes from the depth images directly, with the TSDF's notion of
/// it: space in front of the measured surface. Per frame, with OctoMap's sensor model and
/// its rule that a cell hit in a frame is not also missed in that frame:
///  - hit: the cell containing the point of every pixel_stride-th pixel whose depth lies in
///    [min_depth_m, max_depth_m] (the integrator's range, so surfaces land where the TSDF
///    puts its zero crossing);
///  - miss: every cell whose centre projects into the image, that ends before max_depth_m, and
///    for which the depth at that pixel and at the four corners of the cell's projected face
///    lies beyond the depth where the ray through the cell's centre leaves the cell (a pixel
///    without depth, or nearer than min_depth_m, vetoes); and the cell holding the camera;
///  - cells never hit or missed are unknown.
///
/// Why projective and not OctoMap's insertPointCloud: on 640x480 frames of a procedural room
/// at 5 cm, insertPointCloud (discretised) takes 12-16 ms median per frame at pixel strides
/// of 8-4, most of it in OcTree updates of the free cells of the frustum, which a coarser
/// stride barely reduces. Here each frustum cell is tested once per frame against the depth
/// image and updated in a flat grid of 8^3-cell blocks with the same float log-odds
/// arithmetic as OctoMap: about 2 ms per frame on the same frames (both measured by
/// bench/bench_occupancy.cpp, figures in docs/PERFORMANCE.md). The OcTree is built with OctoMap's
/// API when exported (toOcTree(), ~0.1 s for a room). The corner samples keep grazing surfaces (a
/// floor seen at a shallow angle) from being carved, the classic failure of ray casting.
///
/// Deterministic: single-threaded, cells change by at most one hit or one miss per frame, and
/// exports serialise the pruned maximum-likelihood tree, so the same frames give byte-identical
/// .bt files. Not thread-safe: one thread updates, and queries must not run alongside.
class OccupancyMap {
 public:
  /// Parameters; the probabilities are OctoMap's defaults.
  struct Config {
    double resolution_m = 0.05;  ///< cell edge length, metres
    double min_depth_m = 0.1;    ///< depth outside [min, max] is not a hit, metres (as the
    double max_depth_m = 3.5;    ///< integrator); free space reaches up to max_depth_m
    /// Pixels between hit samples, both directions. 4 at 640x480: 19200 samples, 2.7 cm
    /// apart on a surface facing the camera 3.5 m away, so its 5 cm cells are all hit. (2
    /// observes 2 % more surface cells over a walk for 0.6 ms more per frame; the free test
    /// does not depend on it.)
    int pixel_stride = 4;
    double prob_hit = 0.7;             ///< occupancy probability after one hit
    double prob_miss = 0.4;            ///< after one miss
    double clamping_min = 0.1192;      ///< log-odds clamp, as probabilities: keeps cells able
    double clamping_max = 0.971;       ///< to change with new evidence
    double occupancy_threshold = 0.5;  ///< at or above: occupied
    /// Skip the free test for blocks that lie behind the surface wherever they project (their
    /// cells would all fail it). Exact: the map is the same either way, only faster with it.
    bool skip_hidden_blocks = true;
    /// Throws Error naming the bad field.
    void check() const;
  };

  /// An empty map (everything unknown). Throws Error when the config is invalid.
  explicit OccupancyMap(const Config& config);
  /// An empty map with the default config.
  OccupancyMap() : OccupancyMap(Config()) {}

  /// Updates the map with one depth image. Throws Error, leaving the map untouched, when the
  /// pose is not a rigid transform, the intrinsics are invalid, the depth image's size differs
  /// from the intrinsics, the depth scale is not positive, or the view leaves the tree's range.
  /// @param depth depth along the optical axis in units of depth_scale_m, 0 = no return
  /// @param T_W_C camera to world (optical frame: x right, y down, z forward)
  OccupancyUpdateStats integrate(const DepthImage& depth, double depth_scale_m,
                                 const PinholeCamera& camera, const Eigen::Isometry3d& T_W_C);

  /// Updates the map with a frame's depth image (colour is not used); see the overload above.
  /// @param T_W_C camera to world (optical frame)
  OccupancyUpdateStats integrate(const RgbdFrame& frame, const Eigen::Isometry3d& T_W_C);

  /// Throws the Error integrate() would throw for these inputs, and changes nothing: for a
  /// caller that checks a frame now and integrates it later, on another thread. Reads only the
  /// configuration, so it may run while another thread integrates (OccupancyLane).
  void validate(const DepthImage& depth, double depth_scale_m, const PinholeCamera& camera,
                const Eigen::Isometry3d& T_W_C) const;

  /// State at a world point (metres); the exported tree answers the same. Throws Error when
  /// the point is not finite.
  Occupancy occupancyAt(const Eigen::Vector3d& p_W) const;

  /// Is the straight segment A-B known free (world, metres)? The same walk and answer as
  /// panmap::checkSegment on the exported tree.
  SegmentCheck checkSegment(const Eigen::Vector3d& a_W, const Eigen::Vector3d& b_W) const;

  /// The map as an OcTree: every observed cell at its maximum-likelihood value (OctoMap's
  /// clamping thresholds), pruned. What the exports serialise.
  std::unique_ptr<octomap::OcTree> toOcTree() const;

  /// The data of a PANMAP_OCTOMAP message (binary = true, tree_type "OcTree"): OctoMap's
  /// writeBinaryData stream; decode with treeFromBinaryData or OcTree::readBinaryData.
  std::string toBinaryData() const;

  /// The bytes of occupancy.bt.
  std::string toBtBytes() const;

  /// Writes occupancy.bt (octovis, OctoMap's tools). Throws Error naming the path on failure.
  void writeBt(const std::string& path) const;

  /// Cell edge length, metres.
  double resolution() const { return config_.resolution_m; }
  /// The config the map was built with.
  const Config& config() const { return config_; }
  /// The live cells.
  const OccupancyGrid& grid() const { return grid_; }
  /// OctoMap's sensor model as used here.
  const LogOddsModel& model() const { return model_; }
  /// Frames integrated so far.
  size_t numFrames() const { return frames_; }

  /// Appends the cells and frame count (not the config) to a map file payload.
  void writeState(BinaryWriter* out) const;
  /// Replaces the cells and frame count with those written by writeState. Throws Error (from
  /// the reader) on truncated or inconsistent data; the map is then left empty.
  void readState(BinaryReader* in);

 private:
  void addHits(const DepthImage& depth, double depth_scale_m, const PinholeCamera& camera,
               const Eigen::Isometry3d& T_W_C, OccupancyUpdateStats* stats);
  void addMisses(const DepthImage& depth, double depth_scale_m, const PinholeCamera& camera,
                 const Eigen::Isometry3d& T_W_C, OccupancyUpdateStats* stats);

  Occupancy stateOf(const octomap::OcTreeKey& key) const;

  Config config_;
  LogOddsModel model_;
  OccupancyGrid grid_;
  // An empty tree at the map's resolution: OctoMap's key arithmetic and DDA for queries.
  std::unique_ptr<octomap::OcTree> geometry_;
  uint32_t frames_ = 0;
  internal::DepthTileMax depth_tiles_;  // scratch of addMisses()
};

}  // namespace panmap

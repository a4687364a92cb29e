#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "panmap/core/frame.h"
#include "panmap/core/image.h"

namespace panmap {

/// Geometric segmentation of a depth image into convex patches (paper III-A, after Furrer et
/// al.'s depth segmentation). Defaults are those of the paper's released code.
struct DepthSegmentationConfig {
  int normals_window_px = 13;       ///< neighbourhood for surface normals, pixels (odd, <= 127)
  int min_convexity_window_px = 5;  ///< neighbourhood of the concavity test, pixels (odd, <= 127)
  float min_convexity_threshold = 0.97f;    ///< concave edge where min convexity falls below
  float depth_discontinuity_ratio = 0.01f;  ///< edge where |dz| > ratio * z to a neighbour
  int min_segment_px = 100;                 ///< smaller segments are dropped (pixels -> 0)
  float max_depth_m = 10.0f;                ///< farther depth is treated as invalid
  /// Threads sharing the per-pixel stages (rows split in bands), the caller included. The
  /// result does not depend on it.
  int num_threads = 1;
  /// Throws Error naming the bad field.
  void check() const;
  /// Fingerprint of every field that shapes the segments (not num_threads): segments kept from
  /// a run with another key are not reused (GeometricSegments).
  uint64_t key() const;
};

/// How geometric segments and panoptic masks are fused into surfaces.
struct SurfaceFusionConfig {
  /// Surfaces smaller than this (pixels) are dropped: too few points to vote with.
  int min_surface_px = 50;
  /// Eq. 1: confidence of a stuff surface (things use the segmenter's score). Background
  /// surfaces (inside no mask) get it too: the paper has no mask there to score.
  float stuff_confidence = 0.5f;
  /// Ablation "geometry only": ignore panoptic masks; every surface is background.
  bool geometry_only = false;
  /// A thing mask that holds no surface (a small or far object: every pixel of it is a
  /// geometric edge or in a segment below min_segment_px) becomes surfaces of its own: its
  /// pixels with depth outside every geometric segment, split where the depth steps, each
  /// part of at least min_surface_px. Without it such an object casts no vote at all.
  bool mask_only_surfaces = true;
  /// Neighbouring pixels of a mask-only surface differ in depth by at most this share of it.
  float mask_only_depth_step = 0.01f;
  /// Throws Error naming the bad field.
  void check() const;
};

/// One surface s_i of a frame: the pixels of one geometric segment inside one panoptic
/// segment (or inside no mask: background).
struct Surface {
  int32_t id = 0;                 ///< pixel value in FrameSegmentation::surfaces (> 0)
  int32_t geometric_segment = 0;  ///< its geometric segment id; 0: a mask-only surface
  int32_t panoptic_segment = 0;   ///< panoptic segment id o_i, 0 = background (no mask)
  int32_t category = 0;           ///< C(o_i), NYU40 id; 0 = background / unknown class
  bool is_thing = false;          ///< o_i is a countable object
  float confidence = 0.0f;        ///< P_o (Eq. 1): score for things, stuff_confidence for stuff
  int32_t num_pixels = 0;
};

/// The 2D panoptic-geometric segmentation of one frame.
struct FrameSegmentation {
  LabelImage geometric;  ///< geometric segment id per pixel, 0 = edge / invalid / small
  LabelImage surfaces;   ///< surface id per pixel, 0 = none
  std::vector<Surface> surface_list;  ///< indexed by id - 1
  /// Made with the frame's panoptic segmentation (the segmenter sets it). Without one (a
  /// network slower than the camera, or no network) every surface has class 0 but the frame
  /// says nothing about classes: its surfaces are not counted as unlabelled
  /// (SuperpointState::class_counts).
  bool panoptic = true;
};

/// A frame's geometric segments (FrameSegmentation::geometric) kept from an earlier
/// segmentation of the same depth image and intrinsics, with the key of the config that made
/// them. Mapping a stored frame again can take them instead of running the depth stages, the
/// costliest part of a frame (docs/LOOP_CLOSURE.md).
struct GeometricSegments {
  LabelImage ids;           ///< empty: none kept
  uint64_t config_key = 0;  ///< DepthSegmentationConfig::key() of the run that made them
};

/// Why a pixel is an edge of the geometric segmentation (bit flags of
/// PanopticGeometricSegmenter::edgeFlags()); 0 = inside a segment candidate.
enum DepthEdge : uint8_t {
  kEdgeInvalidDepth = 1,   ///< no depth, or beyond max_depth_m
  kEdgeNoNormal = 2,       ///< no normal: holes or depth steps on too many sides
  kEdgeDiscontinuity = 4,  ///< an 8-neighbour's depth jumps by more than the ratio
  kEdgeConcave = 8,        ///< min convexity below the threshold
};

/// Computes geometric segments of the depth image and fuses them with the panoptic masks.
/// Holds scratch buffers (and DepthSegmentationConfig::num_threads - 1 worker threads): one
/// instance per calling thread.
class PanopticGeometricSegmenter {
 public:
  /// Throws Error when a config is invalid.
  PanopticGeometricSegmenter(const DepthSegmentationConfig& depth_config,
                             const SurfaceFusionConfig& fusion_config);
  ~PanopticGeometricSegmenter();
  PanopticGeometricSegmenter(const PanopticGeometricSegmenter&) = delete;
  PanopticGeometricSegmenter& operator=(const PanopticGeometricSegmenter&) = delete;

  /// Segments a frame. `panoptic` may be null (geometry only). Throws Error when the panoptic
  /// image's size differs from the depth image's (unless geometry_only), when the depth image
  /// does not match the camera, or when a panoptic segment id is not positive or repeated.
  FrameSegmentation segment(const RgbdFrame& frame, const PanopticFrame* panoptic);

  /// The same into `out`, reusing its buffers: once the image size is stable, a frame
  /// allocates nothing (but inside OpenCV's connected components).
  /// @param kept the frame's geometric segments from an earlier run, or null: taken as they
  ///        are when their key is this segmenter's config key and their size the depth
  ///        image's (normal(), minConvexity() and edgeFlags() then keep the previous frame's),
  ///        computed from the depth otherwise
  void segment(const RgbdFrame& frame, const PanopticFrame* panoptic, FrameSegmentation* out,
               const GeometricSegments* kept = nullptr);

  /// Whether the last segment() took kept geometric segments instead of computing them.
  bool keptLast() const;

  /// Unit surface normal at pixel (u, v) of the last segmented frame, camera frame, pointing
  /// toward the camera; zero where the pixel has none.
  Eigen::Vector3f normal(int u, int v) const;

  /// Per pixel of the last segmented frame: the minimum convexity over its window (1 = flat or
  /// convex everywhere around it).
  const Image<float>& minConvexity() const;

  /// Per pixel of the last segmented frame: DepthEdge bit flags, 0 where not an edge.
  const Image<uint8_t>& edgeFlags() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace panmap

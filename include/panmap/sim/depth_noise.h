#pragma once

#include <cstdint>

#include "panmap/core/image.h"
#include "panmap/render/renderer.h"

namespace panmap {

/// Structured-light depth sensor noise after Nguyen, Izadi and Lovell (3DIMPVT 2012), plus
/// the dropouts real Kinect / Structure sensors show.
struct DepthNoiseConfig {
  bool enabled = true;              ///< false: exact depth, only quantised
  double axial_sigma_a_m = 0.0012;  ///< axial sigma(z) = a + b (z - z0)^2, metres
  double axial_sigma_b_m = 0.0019;  ///< per square metre
  double axial_z0_m = 0.4;
  double lateral_sigma_px = 0.8;  ///< lateral jitter of depth edges, pixels
  /// Share of the axial variance that is spatially correlated (structured-light sensors match
  /// windows of pixels, so neighbouring errors move together); the rest is white.
  double correlated_share = 0.8;
  int correlation_px = 8;           ///< spacing of the correlated field's control points
  double quantization_m = 0.001;    ///< output step (uint16 millimetres)
  double min_range_m = 0.3;         ///< nearer returns are dropped
  double max_range_m = 6.0;         ///< farther returns are dropped
  double grazing_start_deg = 70.0;  ///< dropout probability rises from 0 here ...
  double grazing_full_deg = 85.0;   ///< ... to 1 here (angle between ray and normal)
  double edge_ratio = 0.05;         ///< a depth edge: neighbour depth differs by > ratio * z
  double edge_dropout = 0.5;        ///< probability of losing a pixel on a depth edge
  /// Throws Error naming the bad field.
  void check() const;
};

/// Sensor depth of a rendered view: axial Gaussian noise with Nguyen's sigma(z) (partly
/// spatially correlated), lateral jitter of depth edges, dropouts at grazing angles, depth
/// edges and range limits, quantised to depth_scale_m units (0 = no return).
/// Deterministic for a given seed.
DepthImage simulateDepth(const RenderedView& view, const DepthNoiseConfig& config, uint64_t seed,
                         double depth_scale_m = 0.001);

}  // namespace panmap

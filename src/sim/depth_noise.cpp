#include "panmap/sim/depth_noise.h"

#include <algorithm>
#include <cmath>

#include "panmap/core/error.h"
#include "panmap/core/random.h"

namespace panmap {

void DepthNoiseConfig::check() const {
  if (axial_sigma_a_m < 0 || axial_sigma_b_m < 0) throw Error("depth noise: axial sigma must be >= 0");
  if (lateral_sigma_px < 0) throw Error("depth noise: lateral_sigma_px must be >= 0");
  if (!(quantization_m > 0)) throw Error("depth noise: quantization_m must be > 0");
  if (!(min_range_m >= 0 && max_range_m > min_range_m)) {
    throw Error("depth noise: need 0 <= min_range_m < max_range_m");
  }
  if (!(grazing_start_deg < grazing_full_deg && grazing_full_deg <= 90.0)) {
    throw Error("depth noise: need grazing_start_deg < grazing_full_deg <= 90");
  }
  if (!(edge_dropout >= 0 && edge_dropout <= 1)) throw Error("depth noise: edge_dropout in [0, 1]");
  if (!(edge_ratio > 0)) throw Error("depth noise: edge_ratio must be > 0");
}

DepthImage simulateDepth(const RenderedView& view, const DepthNoiseConfig& config, uint64_t seed,
                         double depth_scale_m) {
  config.check();
  const Image<float>& clean = view.depth_m;
  const int w = clean.width(), h = clean.height();
  DepthImage out(w, h, 0);
  const double max_units = 65535.0;
  if (!config.enabled) {
    for (size_t i = 0; i < clean.size(); ++i) {
      const double z = clean.data()[i];
      out.data()[i] = z > 0 ? static_cast<uint16_t>(std::min(max_units, std::round(z / depth_scale_m))) : 0;
    }
    return out;
  }
  Rng rng(seed);
  const double cos_start = std::cos(config.grazing_start_deg * M_PI / 180.0);
  const double cos_full = std::cos(config.grazing_full_deg * M_PI / 180.0);
  const double step = std::max(config.quantization_m, depth_scale_m);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      // Lateral noise: the pixel measures a point a fraction of a pixel off, which at depth
      // edges moves the outline by a pixel or two.
      const int su = std::clamp(u + static_cast<int>(std::lround(rng.normal() * config.lateral_sigma_px)), 0, w - 1);
      const int sv = std::clamp(v + static_cast<int>(std::lround(rng.normal() * config.lateral_sigma_px)), 0, h - 1);
      const double z = clean(su, sv);
      const double noise = rng.normal();
      const double drop = rng.uniform();
      if (z <= 0.0 || z < config.min_range_m || z > config.max_range_m) continue;
      // Grazing angles return little light.
      const double c = view.cos_incidence(su, sv);
      if (c < cos_start) {
        const double p = std::clamp((cos_start - c) / (cos_start - cos_full), 0.0, 1.0);
        if (drop < p) continue;
      }
      // Mixed pixels on depth edges are often invalidated by the sensor.
      bool edge = false;
      for (int k = 0; k < 4 && !edge; ++k) {
        const int nu = std::clamp(su + (k == 0) - (k == 1), 0, w - 1);
        const int nv = std::clamp(sv + (k == 2) - (k == 3), 0, h - 1);
        const double zn = clean(nu, nv);
        edge = zn <= 0.0 || std::abs(zn - z) > config.edge_ratio * z;
      }
      if (edge && drop < config.edge_dropout) continue;
      const double sigma = config.axial_sigma_a_m + config.axial_sigma_b_m *
                                                        (z - config.axial_z0_m) * (z - config.axial_z0_m);
      const double measured = std::round((z + sigma * noise) / step) * step;
      const double units = std::round(measured / depth_scale_m);
      if (units >= 1.0) out(u, v) = static_cast<uint16_t>(std::min(max_units, units));
    }
  }
  return out;
}

}  // namespace panmap

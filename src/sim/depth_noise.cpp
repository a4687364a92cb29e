#include "panmap/sim/depth_noise.h"

#include <algorithm>
#include <cmath>

#include "panmap/core/error.h"
#include "panmap/core/random.h"

namespace panmap {

void DepthNoiseConfig::check() const {
  if (axial_sigma_a_m < 0 || axial_sigma_b_m < 0)
    throw Error("depth noise: axial sigma must be >= 0");
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
  if (!(correlated_share >= 0 && correlated_share <= 1)) {
    throw Error("depth noise: correlated_share must be in [0, 1]");
  }
  if (correlation_px < 1) throw Error("depth noise: correlation_px must be >= 1");
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
      out.data()[i] =
          z > 0 ? static_cast<uint16_t>(std::min(max_units, std::round(z / depth_scale_m))) : 0;
    }
    return out;
  }
  Rng rng(seed);
  // Correlated unit-variance field: Gaussian control points every correlation_px pixels,
  // bilinearly blended and renormalised by the blend's own standard deviation.
  const int g = config.correlation_px;
  const int gw = w / g + 2, gh = h / g + 2;
  std::vector<double> grid(static_cast<size_t>(gw) * gh);
  for (double& x : grid) x = rng.normal();
  const double a_corr = std::sqrt(config.correlated_share);
  const double a_white = std::sqrt(1.0 - config.correlated_share);
  auto correlated = [&](int u, int v) {
    const int i = u / g, j = v / g;
    const double s = static_cast<double>(u % g) / g, t = static_cast<double>(v % g) / g;
    const double w00 = (1 - s) * (1 - t), w10 = s * (1 - t), w01 = (1 - s) * t, w11 = s * t;
    const double value = w00 * grid[j * gw + i] + w10 * grid[j * gw + i + 1] +
                         w01 * grid[(j + 1) * gw + i] + w11 * grid[(j + 1) * gw + i + 1];
    return value / std::sqrt(w00 * w00 + w10 * w10 + w01 * w01 + w11 * w11);
  };
  auto isEdge = [&](int su, int sv, double z) {
    for (int k = 0; k < 4; ++k) {
      const int nu = std::clamp(su + (k == 0) - (k == 1), 0, w - 1);
      const int nv = std::clamp(sv + (k == 2) - (k == 3), 0, h - 1);
      const double zn = clean(nu, nv);
      if (zn <= 0.0 || std::abs(zn - z) > config.edge_ratio * z) return true;
    }
    return false;
  };
  const double cos_start = std::cos(config.grazing_start_deg * M_PI / 180.0);
  const double cos_full = std::cos(config.grazing_full_deg * M_PI / 180.0);
  const double step = std::max(config.quantization_m, depth_scale_m);
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const double jitter_u = rng.normal(), jitter_v = rng.normal();
      const double white = rng.normal();
      const double drop = rng.uniform();
      int su = u, sv = v;
      double z = clean(u, v);
      // Lateral noise moves depth edges by a pixel or two (on smooth surfaces it only shifts
      // the sample along the surface, which the axial term already covers).
      const bool edge = z > 0.0 && isEdge(u, v, z);
      if (edge || z <= 0.0) {
        su = std::clamp(u + static_cast<int>(std::lround(jitter_u * config.lateral_sigma_px)), 0,
                        w - 1);
        sv = std::clamp(v + static_cast<int>(std::lround(jitter_v * config.lateral_sigma_px)), 0,
                        h - 1);
        z = clean(su, sv);
      }
      if (z <= 0.0 || z < config.min_range_m || z > config.max_range_m) continue;
      // Grazing angles return little light.
      const double c = view.cos_incidence(su, sv);
      if (c < cos_start) {
        const double p = std::clamp((cos_start - c) / (cos_start - cos_full), 0.0, 1.0);
        if (drop < p) continue;
      }
      // Mixed pixels on depth edges are often invalidated by the sensor.
      if (isEdge(su, sv, z) && drop < config.edge_dropout) continue;
      const double sigma = config.axial_sigma_a_m + config.axial_sigma_b_m *
                                                        (z - config.axial_z0_m) *
                                                        (z - config.axial_z0_m);
      const double noise = a_corr * correlated(u, v) + a_white * white;
      const double measured = std::round((z + sigma * noise) / step) * step;
      const double units = std::round(measured / depth_scale_m);
      if (units >= 1.0) out(u, v) = static_cast<uint16_t>(std::min(max_units, units));
    }
  }
  return out;
}

}  // namespace panmap

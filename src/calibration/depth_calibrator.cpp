#include "panmap/calibration/depth_calibrator.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "panmap/calibration/internal/grid_lerp.h"
#include "panmap/core/error.h"
#include "panmap/map/projective_integrator.h"
#include "panmap/tracking/sdf_sampler.h"

namespace panmap {
namespace {

// Frames per block of the measurement: each block's sums are kept apart and added in block
// order, so the result does not depend on which thread measured which block.
constexpr size_t kBlockFrames = 8;

// Weighted sums of the depth disagreement per grid value.
struct Sums {
  std::vector<double> error, weight;
  double squares = 0.0;
  int64_t points = 0;
  explicit Sums(size_t n) : error(n, 0.0), weight(n, 0.0) {}
  void add(const Sums& o) {
    for (size_t k = 0; k < error.size(); ++k) {
      error[k] += o.error[k];
      weight[k] += o.weight[k];
    }
    squares += o.squares;
    points += o.points;
  }
};

// Calls f(index, weight) for the grid values around (u, v, z), as DepthCalibration::offsetM
// interpolates them.
template <class F>
void visitGrid(const DepthCalibrator::Config& c, int width, int height, double u, double v,
               double z_m, F&& f) {
  const internal::GridLerp x = internal::cellLerp(u, width, c.cells_x);
  const internal::GridLerp y = internal::cellLerp(v, height, c.cells_y);
  const internal::GridLerp z = internal::knotLerp(z_m, 1.0 / c.knot_spacing_m, c.knots);
  const size_t layer = static_cast<size_t>(c.cells_x) * c.cells_y;
  const int xs[2] = {x.i0, x.i1}, ys[2] = {y.i0, y.i1}, zs[2] = {z.i0, z.i1};
  const double wx[2] = {1.0 - x.t, x.t}, wy[2] = {1.0 - y.t, y.t}, wz[2] = {1.0 - z.t, z.t};
  for (int a = 0; a < 2; ++a) {
    for (int b = 0; b < 2; ++b) {
      for (int d = 0; d < 2; ++d) {
        const double w = wz[a] * wy[b] * wx[d];
        if (w > 0.0) f(zs[a] * layer + static_cast<size_t>(ys[b]) * c.cells_x + xs[d], w);
      }
    }
  }
}

}  // namespace

void DepthCalibrator::Config::check() const {
  if (cells_x < 1 || cells_y < 1) throw Error("calibration cells_x and cells_y must be >= 1");
  if (knots < 2) throw Error("calibration knots must be >= 2");
  if (!(knot_spacing_m > 0.0)) throw Error("calibration knot_spacing_m must be positive");
  if (!(voxel_size_m > 0.0f)) throw Error("calibration voxel_size_m must be positive");
  if (!(max_depth_m > 0.0)) throw Error("calibration max_depth_m must be positive");
  if (pixel_stride < 1) throw Error("calibration pixel_stride must be >= 1");
  if (!(max_residual_m > 0.0)) throw Error("calibration max_residual_m must be positive");
  if (!(min_cos > 0.0 && min_cos <= 1.0)) throw Error("calibration min_cos must be in (0, 1]");
  if (!(min_weight >= 0.0)) throw Error("calibration min_weight must be >= 0");
  if (!(prior_weight >= 0.0)) throw Error("calibration prior_weight must be >= 0");
  if (passes < 1) throw Error("calibration passes must be >= 1");
}

DepthCalibrator::DepthCalibrator(const Config& config) : config_(config) { config_.check(); }

DepthCalibration DepthCalibrator::calibrate(const std::vector<CalibrationFrame>& frames,
                                            ThreadPool* pool, std::vector<CalibrationPass>* passes,
                                            const std::function<void(int, int)>& progress) const {
  if (frames.empty()) throw Error("calibration needs at least one frame");
  const int width = frames.front().camera.width, height = frames.front().camera.height;
  for (const CalibrationFrame& f : frames) {
    std::string why;
    if (!f.camera.isValid(&why)) throw Error("calibration frame camera: " + why);
    if (f.camera.width != width || f.camera.height != height || f.depth.width() != width ||
        f.depth.height() != height) {
      throw Error("calibration frames must all be " + std::to_string(width) + "x" +
                  std::to_string(height));
    }
  }
  if (config_.cells_x > width || config_.cells_y > height) {
    throw Error("calibration has more cells than the image has pixels");
  }
  const Config& c = config_;
  const size_t n = static_cast<size_t>(c.cells_x) * c.cells_y * c.knots;
  const size_t layer = static_cast<size_t>(c.cells_x) * c.cells_y;
  std::vector<double> offsets(n, 0.0);
  IntegratorConfig integrator_config;
  integrator_config.max_depth_m = static_cast<float>(c.max_depth_m);
  ProjectiveIntegrator integrator(integrator_config, pool);
  const size_t blocks = (frames.size() + kBlockFrames - 1) / kBlockFrames;
  if (passes) passes->clear();

  for (int pass = 0; pass < c.passes; ++pass) {
    const DepthCalibration current(width, height, c.cells_x, c.cells_y, c.knots, c.knot_spacing_m,
                                   std::vector<float>(offsets.begin(), offsets.end()));
    // The map of the frames' corrected depth (one frame corrected at a time: the measurement
    // below corrects only the pixels it reads, so no frame is held twice).
    TsdfMap map(TsdfMap::Config{c.voxel_size_m});
    RgbdFrame scratch;
    for (const CalibrationFrame& f : frames) {
      scratch.camera = f.camera;
      scratch.depth_scale_m = f.depth_scale_m;
      current.apply(f.depth, f.depth_scale_m, &scratch.depth, pool);
      integrator.integrate(scratch, f.T_W_C, nullptr, &map);
    }
    // Each corrected point's disagreement with the map along its ray.
    std::vector<Sums> block_sums(blocks, Sums(n));
    pool->parallelForDynamic(blocks, 1, [&](size_t begin, size_t end, int) {
      SdfSampler sampler(map);
      for (size_t b = begin; b < end; ++b) {
        Sums& sums = block_sums[b];
        for (size_t i = b * kBlockFrames; i < std::min(frames.size(), (b + 1) * kBlockFrames);
             ++i) {
          const CalibrationFrame& f = frames[i];
          const Eigen::Isometry3f T = f.T_W_C.cast<float>();
          for (int v = c.pixel_stride / 2; v < height; v += c.pixel_stride) {
            for (int u = c.pixel_stride / 2; u < width; u += c.pixel_stride) {
              const uint16_t d = current.correctedReading(u, v, f.depth(u, v), f.depth_scale_m);
              if (d == 0) continue;
              const double z_m = d * f.depth_scale_m;
              if (z_m > c.max_depth_m) continue;
              const Eigen::Vector3f p_C = f.camera.backProject(u, v, z_m).cast<float>();
              float sdf_m = 0.0f;
              Eigen::Vector3f gradient_W;
              if (!sampler.sample(T * p_C, &sdf_m, &gradient_W)) continue;
              const float gradient_norm = gradient_W.norm();
              if (std::abs(sdf_m) > c.max_residual_m || !(gradient_norm > 0.5f)) continue;
              const float range = p_C.norm();
              const float cos_angle =
                  std::abs((T.linear() * p_C).dot(gradient_W)) / (range * gradient_norm);
              if (cos_angle < c.min_cos) continue;
              // sdf > 0: the point lies in front of the surface, so the depth reads short; the
              // distance along the ray, then along the optical axis.
              const double error_m = sdf_m / cos_angle * (z_m / range);
              visitGrid(c, width, height, u, v, z_m, [&](size_t k, double w) {
                sums.error[k] += w * error_m;
                sums.weight[k] += w;
              });
              sums.squares += error_m * error_m;
              ++sums.points;
            }
          }
        }
      }
    });
    Sums total(n);
    for (const Sums& s : block_sums) total.add(s);
    if (total.points == 0) throw Error("calibration: no depth point lies on the map's surface");
    for (size_t k = 0; k < n; ++k) {
      // The map holds part of each frame's error (it averages the frames), so one pass
      // measures only part of it: each pass adds what is left, shrunk where few points count.
      if (total.weight[k] >= c.min_weight) {
        offsets[k] += total.error[k] / (total.weight[k] + c.prior_weight);
      }
    }
    // A depth knot's mean offset is a scale every frame shares with the map: not observable.
    for (int z = 0; z < c.knots; ++z) {
      double num = 0.0, den = 0.0;
      for (size_t k = z * layer; k < (z + 1) * layer; ++k) {
        if (total.weight[k] < c.min_weight) continue;
        num += total.weight[k] * offsets[k];
        den += total.weight[k];
      }
      const double mean = den > 0.0 ? num / den : 0.0;
      for (size_t k = z * layer; k < (z + 1) * layer; ++k) {
        if (total.weight[k] >= c.min_weight) offsets[k] -= mean;
      }
    }
    if (passes) {
      passes->push_back({std::sqrt(total.squares / total.points), total.points});
    }
    if (progress) progress(pass + 1, c.passes);
  }
  std::vector<float> quantised(n);
  for (size_t k = 0; k < n; ++k) quantised[k] = quantiseOffsetM(offsets[k]);
  return DepthCalibration(width, height, c.cells_x, c.cells_y, c.knots, c.knot_spacing_m,
                          std::move(quantised));
}

}  // namespace panmap

#include "panmap/calibration/depth_calibration.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "panmap/calibration/internal/grid_lerp.h"
#include "panmap/core/error.h"
#include "panmap/io/atomic_file.h"

namespace panmap {
namespace {

constexpr char kFormat[] = "panmap-depth-calibration";
constexpr int kVersion = 1;

}  // namespace

float quantiseOffsetM(double offset_m) {
  return static_cast<float>(std::round(offset_m * 1e4) * 1e-4);
}

DepthCalibration::DepthCalibration(int width, int height, int cells_x, int cells_y, int knots,
                                   double knot_spacing_m, std::vector<float> offsets_m)
    : width_(width),
      height_(height),
      cells_x_(cells_x),
      cells_y_(cells_y),
      knots_(knots),
      knot_spacing_m_(knot_spacing_m),
      offsets_m_(std::move(offsets_m)) {
  if (width < 1 || height < 1) throw Error("depth calibration: image size must be positive");
  if (cells_x < 1 || cells_y < 1 || cells_x > width || cells_y > height) {
    throw Error("depth calibration: cells must be between 1 and the image size");
  }
  if (knots < 2) throw Error("depth calibration: at least 2 depth knots needed");
  if (!(knot_spacing_m > 0.0) || !std::isfinite(knot_spacing_m)) {
    throw Error("depth calibration: knot spacing must be positive");
  }
  const size_t expected = static_cast<size_t>(cells_x) * cells_y * knots;
  if (offsets_m_.size() != expected) {
    throw Error("depth calibration: " + std::to_string(offsets_m_.size()) + " offsets for " +
                std::to_string(expected) + " grid values");
  }
  for (float o : offsets_m_) {
    if (!std::isfinite(o)) throw Error("depth calibration: non-finite offset");
  }
}

double DepthCalibration::offsetAt(const internal::GridLerp& x, const internal::GridLerp& y,
                                  double z_m) const {
  const internal::GridLerp z = internal::knotLerp(z_m, 1.0 / knot_spacing_m_, knots_);
  auto layer = [&](int k) {
    const float* g = offsets_m_.data() + static_cast<size_t>(k) * cells_x_ * cells_y_;
    const double top = (1.0 - x.t) * g[y.i0 * cells_x_ + x.i0] + x.t * g[y.i0 * cells_x_ + x.i1];
    const double bottom = (1.0 - x.t) * g[y.i1 * cells_x_ + x.i0] + x.t * g[y.i1 * cells_x_ + x.i1];
    return (1.0 - y.t) * top + y.t * bottom;
  };
  return z.t > 0.0 ? (1.0 - z.t) * layer(z.i0) + z.t * layer(z.i1) : layer(z.i0);
}

uint16_t DepthCalibration::roundedUnits(uint16_t raw, double depth_scale_m, double units_per_m,
                                        const internal::GridLerp& x,
                                        const internal::GridLerp& y) const {
  const double z_m = raw * depth_scale_m;
  const long units = std::lround((z_m + offsetAt(x, y, z_m)) * units_per_m);
  return static_cast<uint16_t>(std::clamp(units, 1L, 65535L));
}

uint16_t DepthCalibration::correctedReading(int u, int v, uint16_t raw,
                                            double depth_scale_m) const {
  if (empty() || raw == 0) return raw;
  return roundedUnits(raw, depth_scale_m, 1.0 / depth_scale_m,
                      internal::cellLerp(u, width_, cells_x_),
                      internal::cellLerp(v, height_, cells_y_));
}

double DepthCalibration::offsetM(double u, double v, double z_m) const {
  if (empty()) return 0.0;
  return offsetAt(internal::cellLerp(u, width_, cells_x_), internal::cellLerp(v, height_, cells_y_),
                  z_m);
}

void DepthCalibration::apply(const DepthImage& raw, double depth_scale_m, DepthImage* corrected,
                             ThreadPool* pool) const {
  if (!empty() && (raw.width() != width_ || raw.height() != height_)) {
    std::ostringstream s;
    s << "depth calibration is for " << width_ << "x" << height_ << " images, the depth is "
      << raw.width() << "x" << raw.height();
    throw Error(s.str());
  }
  *corrected = raw;
  if (empty()) return;
  // The image coordinates' interpolation once per column and row: offsetM()'s arithmetic, in
  // the same order, so both give the same bits.
  std::vector<internal::GridLerp> columns(width_);
  for (int u = 0; u < width_; ++u) columns[u] = internal::cellLerp(u, width_, cells_x_);
  const double units_per_m = 1.0 / depth_scale_m;
  auto rows = [&](size_t begin, size_t end, int) {
    for (int v = static_cast<int>(begin); v < static_cast<int>(end); ++v) {
      const internal::GridLerp row = internal::cellLerp(v, height_, cells_y_);
      for (int u = 0; u < raw.width(); ++u) {
        const uint16_t d = raw(u, v);
        if (d == 0) continue;
        (*corrected)(u, v) = roundedUnits(d, depth_scale_m, units_per_m, columns[u], row);
      }
    }
  };
  if (pool) {
    pool->parallelFor(static_cast<size_t>(raw.height()), rows);
  } else {
    rows(0, static_cast<size_t>(raw.height()), 0);
  }
}

void DepthCalibration::apply(const RgbdFrame& raw, RgbdFrame* corrected, ThreadPool* pool) const {
  apply(raw.depth, raw.depth_scale_m, &corrected->depth, pool);  // first: it throws on a bad size
  corrected->utime = raw.utime;
  corrected->frame_id = raw.frame_id;
  corrected->camera_name = raw.camera_name;
  corrected->camera = raw.camera;
  corrected->depth_scale_m = raw.depth_scale_m;
  corrected->color = raw.color;
}

double DepthCalibration::rmsOffsetM() const {
  if (empty()) return 0.0;
  double sum = 0.0;
  for (float o : offsets_m_) sum += static_cast<double>(o) * o;
  return std::sqrt(sum / offsets_m_.size());
}

void DepthCalibration::save(const std::string& path) const {
  if (empty()) throw Error(path + ": an empty depth calibration is not written");
  nlohmann::json j;
  j["format"] = kFormat;
  j["version"] = kVersion;
  j["width"] = width_;
  j["height"] = height_;
  j["cells_x"] = cells_x_;
  j["cells_y"] = cells_y_;
  j["knots"] = knots_;
  j["knot_spacing_m"] = knot_spacing_m_;
  // Tenths of a millimetre: the file stays readable and small, far below the depth's own unit.
  nlohmann::json layers = nlohmann::json::array();
  const size_t layer = static_cast<size_t>(cells_x_) * cells_y_;
  for (int k = 0; k < knots_; ++k) {
    nlohmann::json values = nlohmann::json::array();
    for (size_t i = 0; i < layer; ++i) {
      values.push_back(std::round(offsets_m_[k * layer + i] * 1e4) / 10.0);
    }
    layers.push_back(std::move(values));
  }
  j["offsets_mm"] = std::move(layers);
  const std::string text = j.dump() + "\n";
  AtomicFileWriter out(path);
  out.append(reinterpret_cast<const uint8_t*>(text.data()), text.size());
  out.commit();
}

DepthCalibration DepthCalibration::load(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error("depth calibration " + path + ": cannot open");
  nlohmann::json j;
  try {
    in >> j;
    if (j.at("format").get<std::string>() != kFormat) {
      throw Error("depth calibration " + path + ": not a panmap depth calibration");
    }
    const int version = j.at("version").get<int>();
    if (version != kVersion) {
      throw Error("depth calibration " + path + ": version " + std::to_string(version) +
                  " is not supported (this build reads " + std::to_string(kVersion) + ")");
    }
    const int cells_x = j.at("cells_x").get<int>(), cells_y = j.at("cells_y").get<int>();
    const int knots = j.at("knots").get<int>();
    const auto& layers = j.at("offsets_mm");
    if (!layers.is_array() || static_cast<int>(layers.size()) != knots) {
      throw Error("depth calibration " + path + ": offsets_mm must hold " + std::to_string(knots) +
                  " knots");
    }
    std::vector<float> offsets;
    for (const auto& values : layers) {
      if (!values.is_array() || static_cast<long>(values.size()) != long{cells_x} * cells_y) {
        throw Error("depth calibration " + path + ": each knot must hold cells_x * cells_y values");
      }
      // As quantiseOffsetM() rounds: a saved calibration loads as the same floats.
      for (const auto& v : values) {
        offsets.push_back(static_cast<float>(std::round(v.get<double>() * 10.0) * 1e-4));
      }
    }
    return DepthCalibration(j.at("width").get<int>(), j.at("height").get<int>(), cells_x, cells_y,
                            knots, j.at("knot_spacing_m").get<double>(), std::move(offsets));
  } catch (const Error& e) {
    const std::string what = e.what();
    throw Error(what.rfind("depth calibration " + path, 0) == 0 ? what : path + ": " + what);
  } catch (const nlohmann::json::exception& e) {
    throw Error("depth calibration " + path + ": " + e.what());
  }
}

bool DepthCalibration::operator==(const DepthCalibration& other) const {
  return width_ == other.width_ && height_ == other.height_ && cells_x_ == other.cells_x_ &&
         cells_y_ == other.cells_y_ && knots_ == other.knots_ &&
         knot_spacing_m_ == other.knot_spacing_m_ && offsets_m_ == other.offsets_m_;
}

}  // namespace panmap

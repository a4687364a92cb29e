#include "panmap/sim/sequence.h"

#include <algorithm>
#include <cmath>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"
#include "panmap/core/random.h"

namespace panmap {

void SynthConfig::check() const {
  std::string why;
  if (!camera.isValid(&why)) throw Error("synth camera: " + why);
  if (!(depth_scale_m > 0)) throw Error("synth depth_scale_m must be > 0");
  render.check();
  depth.check();
  masks.check();
  poses.check();
  if (min_view_px < 1) throw Error("synth min_view_px must be >= 1");
  if (!(distinct_view_deg > 0)) throw Error("synth distinct_view_deg must be > 0");
  if (!depth_pattern.empty() &&
      (depth_pattern.width() != camera.width || depth_pattern.height() != camera.height)) {
    throw Error("synth depth pattern is for " + std::to_string(depth_pattern.width()) + "x" +
                std::to_string(depth_pattern.height()) + " images, the camera's are " +
                std::to_string(camera.width) + "x" + std::to_string(camera.height));
  }
}

SynthConfig scaledImage(SynthConfig config, double scale) {
  if (!(scale >= 0.25 && scale <= 4.0)) throw Error("synth image scale must be in [0.25, 4]");
  if (!config.depth_pattern.empty()) {
    throw Error("synth image scale: a depth pattern is made for one image size");
  }
  auto length = [scale](int px) { return std::max(1, static_cast<int>(std::lround(px * scale))); };
  auto area = [scale](int px) {
    return std::max(1, static_cast<int>(std::lround(px * scale * scale)));
  };
  PinholeCamera& c = config.camera;
  c.width = static_cast<int>(std::lround(c.width * scale));
  c.height = static_cast<int>(std::lround(c.height * scale));
  c.fx *= scale;
  c.fy *= scale;
  // Pixel centres: pixel u covers [u - 0.5, u + 0.5], so the image edge -0.5 stays fixed.
  c.cx = (c.cx + 0.5) * scale - 0.5;
  c.cy = (c.cy + 0.5) * scale - 0.5;
  config.depth.lateral_sigma_px *= scale;
  config.depth.correlation_px = length(config.depth.correlation_px);
  SegmenterNoiseConfig& m = config.masks;
  m.miss_small_px = area(m.miss_small_px);
  m.miss_large_px = area(m.miss_large_px);
  m.boundary_mean_px *= scale;
  m.boundary_grid_px = length(m.boundary_grid_px);
  m.merge_min_contact_px = length(m.merge_min_contact_px);
  m.false_positive_min_area_px = area(m.false_positive_min_area_px);
  m.false_positive_max_area_px = area(m.false_positive_max_area_px);
  m.stats_min_px = area(m.stats_min_px);
  config.min_view_px = area(config.min_view_px);
  return config;
}

DepthCalibration sensorDepthPattern(const DepthCalibration& calibration, double scale) {
  if (!(scale >= 0) || !std::isfinite(scale))
    throw Error("depth pattern scale must be finite and >= 0");
  if (calibration.empty()) return {};
  std::vector<float> offsets_m = calibration.offsetsM();
  for (float& o : offsets_m) o = static_cast<float>(-scale * o);
  return DepthCalibration(calibration.width(), calibration.height(), calibration.cellsX(),
                          calibration.cellsY(), calibration.knots(), calibration.knotSpacingM(),
                          std::move(offsets_m));
}

namespace {

std::vector<StampedPose> drift(const std::vector<StampedPose>& gt, const PoseDriftConfig& config,
                               uint64_t seed) {
  std::vector<Eigen::Isometry3d> poses;
  for (const StampedPose& p : gt) poses.push_back(p.T_W_C);
  const std::vector<Eigen::Isometry3d> drifted = applyPoseDrift(poses, config, seed);
  std::vector<StampedPose> out = gt;
  for (size_t k = 0; k < out.size(); ++k) out[k].T_W_C = drifted[k];
  return out;
}

}  // namespace

SequenceSynthesizer::SequenceSynthesizer(const LabelledMesh& mesh,
                                         std::vector<StampedPose> T_W_C_gt,
                                         const SynthConfig& config)
    : config_(config),
      renderer_(mesh, config.render),
      segmenter_(config.masks, hashSeed(config.seed, 0x3A5Cu)),
      gt_(std::move(T_W_C_gt)) {
  config_.check();
  if (gt_.empty()) throw Error("synth: the trajectory has no poses");
  input_ = drift(gt_, config.poses, hashSeed(config.seed, 0xD41Fu));
  // Per instance: majority class, bounding box, centroid.
  std::map<int32_t, std::map<int32_t, int>> class_votes;
  std::map<int32_t, Eigen::AlignedBox3f> boxes;
  std::map<int32_t, std::pair<Eigen::Vector3d, int>> sums;
  for (size_t v = 0; v < mesh.vertices.size() && !mesh.instance.empty(); ++v) {
    const int32_t id = mesh.instance[v];
    if (id <= 0) continue;
    ++class_votes[id][mesh.semantic.empty() ? 0 : mesh.semantic[v]];
    boxes[id].extend(mesh.vertices[v]);
    // Eigen vectors are not zero-initialised: start each sum explicitly.
    auto& sum = sums.try_emplace(id, Eigen::Vector3d::Zero(), 0).first->second;
    sum.first += mesh.vertices[v].cast<double>();
    ++sum.second;
  }
  for (const auto& [id, votes] : class_votes) {
    int32_t best = 0, best_count = -1;
    for (const auto& [cls, count] : votes) {
      if (count > best_count) best = cls, best_count = count;
    }
    InstanceInfo info;
    info.semantic = best;
    info.extent_m = boxes[id].sizes().maxCoeff();
    info.is_stuff = isStuffClass(best);
    infos_[id] = info;
    centroids_[id] = sums[id].first / sums[id].second;
  }
}

SynthFrame SequenceSynthesizer::frame(size_t k) {
  if (k >= gt_.size()) throw Error("synth: frame " + std::to_string(k) + " beyond the trajectory");
  renderer_.render(config_.camera, gt_[k].T_W_C, &view_);
  RgbdFrame rgbd;
  rgbd.camera_name = "panmap-synth";
  rgbd.camera = config_.camera;
  rgbd.depth_scale_m = config_.depth_scale_m;
  rgbd.depth =
      simulateDepth(view_, config_.depth, hashSeed(config_.seed, k, 0xDE9u), config_.depth_scale_m);
  if (!config_.depth_pattern.empty()) {
    DepthImage with_pattern;
    config_.depth_pattern.apply(rgbd.depth, config_.depth_scale_m, &with_pattern);
    rgbd.depth = std::move(with_pattern);
  }
  rgbd.color = view_.color;
  return finishFrame(k, std::move(rgbd));
}

SynthFrame SequenceSynthesizer::frameFromRecording(size_t k, RgbdFrame recorded) {
  if (k >= gt_.size()) throw Error("synth: frame " + std::to_string(k) + " beyond the trajectory");
  if (recorded.depth.empty()) {
    throw Error("synth: recorded frame " + std::to_string(recorded.frame_id) + " has no depth");
  }
  renderer_.render(recorded.camera, gt_[k].T_W_C, &view_);
  const float scale = static_cast<float>(recorded.depth_scale_m);
  for (size_t i = 0; i < recorded.depth.size(); ++i) {
    const float rendered = view_.depth_m.data()[i];
    const float measured = recorded.depth.data()[i] * scale;
    if (rendered <= 0.0f || measured <= 0.0f) continue;
    ++recorded_compared_px_;
    recorded_agreeing_px_ += std::abs(measured - rendered) <= kRecordingAgreementM;
  }
  return finishFrame(k, std::move(recorded));
}

double SequenceSynthesizer::recordingDepthAgreement() const {
  return recorded_compared_px_ ? static_cast<double>(recorded_agreeing_px_) / recorded_compared_px_
                               : 0.0;
}

SynthFrame SequenceSynthesizer::finishFrame(size_t k, RgbdFrame rgbd) {
  SynthFrame out;
  out.gt_pose = gt_[k];
  out.input_pose = input_[k];
  out.rgbd = std::move(rgbd);
  out.rgbd.utime = gt_[k].utime;
  out.rgbd.frame_id = static_cast<int64_t>(k);
  out.gt_instance = view_.instance;
  out.panoptic = segmenter_.segment(view_.instance, view_.semantic, static_cast<int>(k), infos_);
  out.panoptic.utime = out.rgbd.utime;
  out.panoptic.frame_id = out.rgbd.frame_id;

  // Coverage: an instance's viewing direction joins its distinct views when it is far enough
  // from every direction it was seen from before.
  std::map<int32_t, int> pixels;
  for (size_t i = 0; i < view_.instance.size(); ++i) {
    const int32_t id = view_.instance.data()[i];
    if (id > 0) ++pixels[id];
  }
  const double cos_distinct = std::cos(config_.distinct_view_deg * M_PI / 180.0);
  for (const auto& [id, count] : pixels) {
    const auto info = infos_.find(id);
    if (count < config_.min_view_px || info == infos_.end() || info->second.is_stuff ||
        info->second.semantic == 0) {
      continue;
    }
    const Eigen::Vector3d dir = (gt_[k].T_W_C.translation() - centroids_[id]).normalized();
    auto& seen = views_[id];
    bool distinct = true;
    for (const Eigen::Vector3d& d : seen) distinct = distinct && d.dot(dir) < cos_distinct;
    if (distinct) seen.push_back(dir);
  }
  return out;
}

CoverageStats SequenceSynthesizer::coverage() const {
  CoverageStats stats;
  for (const auto& [id, info] : infos_) {
    if (info.is_stuff || info.semantic == 0) continue;  // stuff, unannotated clutter
    ++stats.thing_instances;
    const auto it = views_.find(id);
    if (it == views_.end()) continue;
    ++stats.seen_once;
    if (it->second.size() >= 3) ++stats.seen_from_3_views;
  }
  return stats;
}

}  // namespace panmap

#include "panmap/map/projective_integrator.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "panmap/core/error.h"
#include "panmap/map/voxel_lookup.h"

namespace panmap {

void IntegratorConfig::check() const {
  if (!(truncation_voxels >= 1.0f)) throw Error("integrator truncation_voxels must be >= 1");
  if (!(max_weight > 0.0f)) throw Error("integrator max_weight must be > 0");
  if (!(min_depth_m >= 0.0f && max_depth_m > min_depth_m)) {
    throw Error("integrator needs 0 <= min_depth_m < max_depth_m");
  }
  if (vote_stride_px < 1) throw Error("integrator vote_stride_px must be >= 1");
}

ProjectiveIntegrator::ProjectiveIntegrator(const IntegratorConfig& config, ThreadPool* pool)
    : config_(config), pool_(pool) {
  config_.check();
  if (!pool_) throw Error("integrator needs a thread pool");
}

namespace {

BlockIndex unpackKey(uint64_t key) {
  auto field = [](uint64_t v) {
    const int x = static_cast<int>(v & 0x1FFFFF);
    return x >= (1 << 20) ? x - (1 << 21) : x;  // sign-extend 21 bits
  };
  return BlockIndex(field(key >> 42), field(key >> 21), field(key));
}

// Depth seen through (uf, vf): bilinear between the four surrounding pixels on a smooth
// surface (nearest-pixel depth on slanted surfaces is off by up to half a pixel's depth
// change, centimetres at grazing angles), the nearest pixel across depth edges or holes.
inline float sampleDepth(const Image<float>& depth, float uf, float vf, int u, int v) {
  const int u0 = static_cast<int>(std::floor(uf)), v0 = static_cast<int>(std::floor(vf));
  if (u0 < 0 || v0 < 0 || u0 + 1 >= depth.width() || v0 + 1 >= depth.height()) return depth(u, v);
  const float d00 = depth(u0, v0), d10 = depth(u0 + 1, v0);
  const float d01 = depth(u0, v0 + 1), d11 = depth(u0 + 1, v0 + 1);
  const float lo = std::min(std::min(d00, d10), std::min(d01, d11));
  const float hi = std::max(std::max(d00, d10), std::max(d01, d11));
  if (lo <= 0.0f || hi - lo > 0.05f * lo) return depth(u, v);
  const float a = uf - u0, b = vf - v0;
  return (1 - b) * ((1 - a) * d00 + a * d10) + b * ((1 - a) * d01 + a * d11);
}

}  // namespace

// Pi_V (Eq. 2's counts): every labelled pixel votes for its label in the voxel its measured
// point falls in, as in the paper (a vote per point, not per projected voxel: projective
// distances stretch at grazing angles and would miss the surface voxels there).
void ProjectiveIntegrator::voteLabels(const RgbdFrame& frame, const Eigen::Isometry3f& T_W_C,
                                      const LabelImage& labels, TsdfMap* map,
                                      IntegrationStats* stats) {
  const PinholeCamera& cam = frame.camera;
  const float fx = static_cast<float>(cam.fx), fy = static_cast<float>(cam.fy);
  const float cx = static_cast<float>(cam.cx), cy = static_cast<float>(cam.cy);
  const int stride = config_.vote_stride_px;
  MutableVoxelLookup lookup(*map);
  for (int v = 0; v < cam.height; v += stride) {
    for (int u = 0; u < cam.width; u += stride) {
      const int32_t label = labels(u, v);
      const float d = depth_m_(u, v);
      if (label <= 0 || d <= 0.0f) continue;
      Voxel* voxel = lookup.find(T_W_C * Eigen::Vector3f((u - cx) * d / fx, (v - cy) * d / fy, d));
      if (!voxel) continue;
      ++stats->votes_added;
      stats->votes_evicted += addVote(voxel, label);
    }
  }
}

IntegrationStats ProjectiveIntegrator::integrate(const RgbdFrame& frame,
                                                 const Eigen::Isometry3d& T_W_C,
                                                 const LabelImage* labels, TsdfMap* map) {
  IntegrationStats stats;
  const PinholeCamera& cam = frame.camera;
  const int w = cam.width, h = cam.height;
  if (frame.depth.width() != w || frame.depth.height() != h) {
    throw Error("integrate: depth image size differs from the camera's");
  }
  if (labels && (labels->width() != w || labels->height() != h)) {
    throw Error("integrate: label image size differs from the depth image's");
  }
  const bool has_color = frame.color.width() == w && frame.color.height() == h;
  const float voxel = map->voxelSize();
  const float trunc = config_.truncation_voxels * voxel;

  // Depth in metres with the range limits applied once.
  if (depth_m_.width() != w || depth_m_.height() != h) depth_m_ = Image<float>(w, h);
  const float scale = static_cast<float>(frame.depth_scale_m);
  for (size_t i = 0; i < depth_m_.size(); ++i) {
    const float d = frame.depth.data()[i] * scale;
    depth_m_.data()[i] = (d >= config_.min_depth_m && d <= config_.max_depth_m) ? d : 0.0f;
  }

  // Blocks near the surface: sample the truncation band of every few pixels' rays (the
  // stride keeps neighbouring samples well under a block apart at the far range).
  const Eigen::Isometry3f T_W_Cf = T_W_C.cast<float>();
  const int stride =
      std::clamp(static_cast<int>(map->blockSize() * cam.fx / config_.max_depth_m / 2.0), 1, 8);
  keys_.clear();
  const float inv_block = 1.0f / map->blockSize();
  auto addKey = [&](const Eigen::Vector3f& p_W) {
    keys_.push_back(TsdfMap::key(BlockIndex(static_cast<int>(std::floor(p_W.x() * inv_block)),
                                            static_cast<int>(std::floor(p_W.y() * inv_block)),
                                            static_cast<int>(std::floor(p_W.z() * inv_block)))));
  };
  for (int v = 0; v < h; v += stride) {
    for (int u = 0; u < w; u += stride) {
      const float d = depth_m_(u, v);
      if (d <= 0.0f) continue;
      const Eigen::Vector3f ray_C((u - static_cast<float>(cam.cx)) / static_cast<float>(cam.fx),
                                  (v - static_cast<float>(cam.cy)) / static_cast<float>(cam.fy),
                                  1.0f);
      const float near = config_.space_carving ? config_.min_depth_m : std::max(d - trunc, 0.0f);
      const float step = std::min(map->blockSize() * 0.5f, trunc);
      for (float z = near; z < d + trunc; z += step) addKey(T_W_Cf * (ray_C * z));
      addKey(T_W_Cf * (ray_C * (d + trunc)));
    }
  }
  // Sorted and unique: allocation order, and so the whole map, is the same on every run.
  std::sort(keys_.begin(), keys_.end());
  keys_.erase(std::unique(keys_.begin(), keys_.end()), keys_.end());
  blocks_.clear();
  const size_t before = map->numBlocks();
  for (uint64_t key : keys_) blocks_.push_back(map->allocateBlock(unpackKey(key)));
  stats.blocks_in_view = blocks_.size();
  stats.blocks_allocated = map->numBlocks() - before;

  const Eigen::Isometry3f T_C_W = T_W_Cf.inverse();
  const Eigen::Matrix3f R = T_C_W.linear();
  const float fx = static_cast<float>(cam.fx), fy = static_cast<float>(cam.fy);
  const float cx = static_cast<float>(cam.cx), cy = static_cast<float>(cam.cy);
  const float max_weight = config_.max_weight;
  const bool dropoff = config_.weight_dropoff;
  std::atomic<size_t> voxels_updated{0};

  pool_->parallelFor(blocks_.size(), [&](size_t begin, size_t end, int) {
    size_t updated = 0;
    for (size_t b = begin; b < end; ++b) {
      Block& block = *blocks_[b];
      bool changed = false;
      const Eigen::Vector3f origin_C = T_C_W * map->voxelCentre(block.index, 0, 0, 0);
      const Eigen::Vector3f dx = R.col(0) * voxel, dy = R.col(1) * voxel, dz = R.col(2) * voxel;
      for (int z = 0; z < kBlockSide; ++z) {
        for (int y = 0; y < kBlockSide; ++y) {
          Eigen::Vector3f p_C = origin_C + dy * static_cast<float>(y) + dz * static_cast<float>(z);
          Voxel* row = &block.at(0, y, z);
          for (int x = 0; x < kBlockSide; ++x, p_C += dx) {
            if (p_C.z() < config_.min_depth_m) continue;
            const float inv_z = 1.0f / p_C.z();
            const float uf = fx * p_C.x() * inv_z + cx, vf = fy * p_C.y() * inv_z + cy;
            const int u = static_cast<int>(std::lround(uf));
            const int v = static_cast<int>(std::lround(vf));
            if (u < 0 || v < 0 || u >= w || v >= h) continue;
            const float d = sampleDepth(depth_m_, uf, vf, u, v);
            if (d <= 0.0f) continue;
            // Projective distance along the optical axis.
            const float sdf = d - p_C.z();
            if (sdf < -trunc) continue;  // hidden behind the surface
            // Far in front of the surface: free space. Only carving records it; otherwise a
            // voxel inside an object near its silhouette, whose projection misses the object
            // and lands on the background, would be pulled outward.
            if (sdf > trunc && !config_.space_carving) continue;
            float weight = 1.0f;
            if (dropoff && sdf < -voxel) weight = (trunc + sdf) / (trunc - voxel);
            if (weight <= 0.0f) continue;
            Voxel& vox = row[x];
            const float s = std::min(sdf, trunc);
            const float total = vox.weight + weight;
            vox.sdf_m = (vox.sdf_m * vox.weight + s * weight) / total;
            if (has_color && sdf < trunc) {
              const Rgb8 c = frame.color(u, v);
              const float a = weight / total;
              vox.color.r = static_cast<uint8_t>(vox.color.r + a * (c.r - vox.color.r) + 0.5f);
              vox.color.g = static_cast<uint8_t>(vox.color.g + a * (c.g - vox.color.g) + 0.5f);
              vox.color.b = static_cast<uint8_t>(vox.color.b + a * (c.b - vox.color.b) + 0.5f);
            }
            vox.weight = std::min(total, max_weight);
            ++updated;
            changed = true;
          }
        }
      }
      if (changed) block.updated = true;
    }
    voxels_updated += updated;
  });
  stats.voxels_updated = voxels_updated;
  if (labels) voteLabels(frame, T_W_Cf, *labels, map, &stats);
  return stats;
}

}  // namespace panmap

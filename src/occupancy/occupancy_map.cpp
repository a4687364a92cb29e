#include "panmap/occupancy/occupancy_map.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include <octomap/octomap_utils.h>

#include "panmap/core/error.h"
#include "panmap/core/pose.h"
#include "panmap/occupancy/internal/segment_walk.h"

namespace panmap {
namespace {

bool inOpenUnit(double p) { return p > 0.0 && p < 1.0; }

// Keys of the box holding the view frustum up to max_depth_m (camera centre and the four
// image corners at that depth); false when it leaves OctoMap's key range (checked before any
// conversion to int).
bool frustumKeys(const OccupancyGrid& grid, const PinholeCamera& camera,
                 const Eigen::Isometry3d& T_W_C, double max_depth_m, CellKey* lo, CellKey* hi) {
  const double limit_m = (kOctreeKeyCentre - 1) * grid.resolution();
  Eigen::AlignedBox3d box(T_W_C.translation());
  for (double u : {-0.5, camera.width - 0.5}) {
    for (double v : {-0.5, camera.height - 0.5}) {
      box.extend(T_W_C * camera.backProject(u, v, max_depth_m));
    }
  }
  if (!(box.min().array() > -limit_m).all() || !(box.max().array() < limit_m).all()) {
    return false;
  }
  *lo = grid.keyOf(box.min());
  *hi = grid.keyOf(box.max());
  return true;
}

}  // namespace

void OccupancyMap::Config::check() const {
  if (!(resolution_m >= 0.001 && resolution_m <= 10.0)) {
    throw Error("occupancy resolution_m must be in [0.001, 10] metres");
  }
  if (!(min_depth_m >= 0.0 && std::isfinite(min_depth_m))) {
    throw Error("occupancy min_depth_m must be >= 0 and finite");
  }
  if (!(max_depth_m > min_depth_m && std::isfinite(max_depth_m))) {
    throw Error("occupancy max_depth_m must be finite and greater than min_depth_m");
  }
  if (pixel_stride < 1) throw Error("occupancy pixel_stride must be >= 1");
  if (!inOpenUnit(occupancy_threshold)) {
    throw Error("occupancy occupancy_threshold must be in (0, 1)");
  }
  // One hit must make an unknown cell occupied and one miss make it free.
  if (!(prob_hit > occupancy_threshold && prob_hit < 1.0)) {
    throw Error("occupancy prob_hit must be in (occupancy_threshold, 1)");
  }
  if (!(prob_miss > 0.0 && prob_miss < occupancy_threshold)) {
    throw Error("occupancy prob_miss must be in (0, occupancy_threshold)");
  }
  if (!(clamping_min > 0.0 && clamping_min < occupancy_threshold)) {
    throw Error("occupancy clamping_min must be in (0, occupancy_threshold)");
  }
  if (!(clamping_max > occupancy_threshold && clamping_max < 1.0)) {
    throw Error("occupancy clamping_max must be in (occupancy_threshold, 1)");
  }
}

OccupancyMap::OccupancyMap(const Config& config) : config_(config), grid_(config.resolution_m) {
  config_.check();
  // OctoMap's conversions (octomap::logodds rounds to float), so values match an OcTree's.
  model_.hit = octomap::logodds(config_.prob_hit);
  model_.miss = octomap::logodds(config_.prob_miss);
  model_.clamp_min = octomap::logodds(config_.clamping_min);
  model_.clamp_max = octomap::logodds(config_.clamping_max);
  model_.threshold = octomap::logodds(config_.occupancy_threshold);
  geometry_ = std::make_unique<octomap::OcTree>(config_.resolution_m);
}

void OccupancyMap::validate(const DepthImage& depth, double depth_scale_m,
                            const PinholeCamera& camera, const Eigen::Isometry3d& T_W_C) const {
  std::string why;
  if (!isRigidTransform(T_W_C.matrix(), 1e-4, &why)) throw Error("pose: " + why);
  if (!camera.isValid(&why)) throw Error("intrinsics: " + why);
  if (!(depth_scale_m > 0.0 && std::isfinite(depth_scale_m))) {
    throw Error("depth scale must be > 0");
  }
  if (depth.empty()) throw Error("empty depth image");
  if (depth.width() != camera.width || depth.height() != camera.height) {
    std::ostringstream s;
    s << "depth is " << depth.width() << "x" << depth.height() << " but the intrinsics say "
      << camera.width << "x" << camera.height;
    throw Error(s.str());
  }
  CellKey lo, hi;
  if (!frustumKeys(grid_, camera, T_W_C, config_.max_depth_m, &lo, &hi)) {
    const Eigen::Vector3d t = T_W_C.translation();
    std::ostringstream s;
    s << "pose: the view from (" << t.x() << ", " << t.y() << ", " << t.z()
      << ") leaves the occupancy tree's range (+-" << kOctreeKeyCentre * config_.resolution_m
      << " m)";
    throw Error(s.str());
  }
}

OccupancyUpdateStats OccupancyMap::integrate(const DepthImage& depth, double depth_scale_m,
                                             const PinholeCamera& camera,
                                             const Eigen::Isometry3d& T_W_C) {
  validate(depth, depth_scale_m, camera, T_W_C);
  OccupancyUpdateStats stats;
  ++frames_;
  // Hits first: a cell hit in this frame is then skipped by the free pass.
  addHits(depth, depth_scale_m, camera, T_W_C, &stats);
  addMisses(depth, depth_scale_m, camera, T_W_C, &stats);
  return stats;
}

OccupancyUpdateStats OccupancyMap::integrate(const RgbdFrame& frame,
                                             const Eigen::Isometry3d& T_W_C) {
  return integrate(frame.depth, frame.depth_scale_m, frame.camera, T_W_C);
}

void OccupancyMap::addHits(const DepthImage& depth, double depth_scale_m,
                           const PinholeCamera& camera, const Eigen::Isometry3d& T_W_C,
                           OccupancyUpdateStats* stats) {
  const int stride = config_.pixel_stride;
  const int offset = (stride - 1) / 2;  // the sample nearest the centre of each tile
  CellKey block_key(-1, -1, -1);        // the last block used: neighbouring pixels share blocks
  OccupancyBlock* block = nullptr;
  for (int v = offset; v < camera.height; v += stride) {
    const uint16_t* row = depth.row(v);
    for (int u = offset; u < camera.width; u += stride) {
      const double z_m = row[u] * depth_scale_m;
      if (row[u] == 0 || z_m < config_.min_depth_m || z_m > config_.max_depth_m) continue;
      ++stats->depth_samples;
      const CellKey key = grid_.keyOf(T_W_C * camera.backProject(u, v, z_m));
      const CellKey this_block(key.x() >> 3, key.y() >> 3, key.z() >> 3);
      if (!block || this_block != block_key) {
        block = grid_.allocateBlock(key);
        block_key = this_block;
      }
      OccupancyCell& cell = block->at(key.x() & 7, key.y() & 7, key.z() & 7);
      if (cell.last_frame == frames_) continue;
      model_.update(&cell, true);
      cell.last_frame = frames_;
      ++stats->occupied_updates;
    }
  }
}

void OccupancyMap::addMisses(const DepthImage& depth, double depth_scale_m,
                             const PinholeCamera& camera, const Eigen::Isometry3d& T_W_C,
                             OccupancyUpdateStats* stats) {
  const double res = config_.resolution_m;
  const double half_diagonal_m = 0.5 * std::sqrt(3.0) * res;
  const double block_radius_m = half_diagonal_m * kOccupancyBlockSide;
  const double max_z_m = config_.max_depth_m - 0.5 * res;  // farther cells end past it
  const int w = camera.width, h = camera.height;
  const Eigen::Isometry3d T_C_W = T_W_C.inverse();
  const Eigen::Vector3d t_W_C = T_W_C.translation();
  // Inward unit normals of the frustum's side planes through the camera centre (a pixel
  // centre u lies in [-0.5, w - 0.5) when fx x + (cx + 0.5) z >= 0 and so on).
  const Eigen::Vector3d planes[4] = {
      Eigen::Vector3d(camera.fx, 0.0, camera.cx + 0.5).normalized(),
      Eigen::Vector3d(-camera.fx, 0.0, w - 0.5 - camera.cx).normalized(),
      Eigen::Vector3d(0.0, camera.fy, camera.cy + 0.5).normalized(),
      Eigen::Vector3d(0.0, -camera.fy, h - 0.5 - camera.cy).normalized()};
  // One cell step along each world axis, in the camera frame.
  const Eigen::Matrix3d steps_C = T_C_W.linear() * res;
  const double inv_scale = 1.0 / depth_scale_m;
  // Nearest pixel, clamped into the image (truncation equals floor wherever the result is not
  // clamped to 0 anyway).
  auto depthAt = [&](double u, double v) {
    const int ui = std::clamp(static_cast<int>(u + 0.5), 0, w - 1);
    const int vi = std::clamp(static_cast<int>(v + 0.5), 0, h - 1);
    return static_cast<double>(depth(ui, vi));
  };

  // True when every cell of the block whose first cell centre is first_C fails the centre
  // test below: the depth wherever the block projects is nearer than its nearest cell centre,
  // and so nearer than any cell's far_m. Such blocks (behind walls, inside furniture) are
  // most of a room's frustum and are skipped whole.
  if (config_.skip_hidden_blocks) depth_tiles_.build(depth);
  auto behindSurface = [&](const Eigen::Vector3d& first_C) {
    double z_min = std::numeric_limits<double>::infinity();
    double u_min = z_min, v_min = z_min, u_max = -z_min, v_max = -z_min;
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d p_C =
          first_C +
          steps_C * Eigen::Vector3d((c & 1) ? 7.0 : 0.0, (c & 2) ? 7.0 : 0.0, (c & 4) ? 7.0 : 0.0);
      if (p_C.z() <= 0.0) return false;
      z_min = std::min(z_min, p_C.z());
      const double u = camera.fx * p_C.x() / p_C.z() + camera.cx;
      const double v = camera.fy * p_C.y() / p_C.z() + camera.cy;
      u_min = std::min(u_min, u);
      u_max = std::max(u_max, u);
      v_min = std::min(v_min, v);
      v_max = std::max(v_max, v);
    }
    // The cells' centres project inside the corners' hull; one pixel of margin each side
    // absorbs rounding, and clamping matches depthAt's.
    auto pixel = [](double x, int size) {
      return static_cast<int>(std::clamp(std::floor(x + 0.5), 0.0, size - 1.0));
    };
    const uint16_t deepest = depth_tiles_.maxOver(pixel(u_min - 1.0, w), pixel(v_min - 1.0, h),
                                                  pixel(u_max + 1.0, w), pixel(v_max + 1.0, h));
    return deepest <= z_min * inv_scale;
  };

  CellKey lo, hi;
  frustumKeys(grid_, camera, T_W_C, config_.max_depth_m, &lo, &hi);  // in range: validated
  for (int bz = lo.z() >> 3; bz <= hi.z() >> 3; ++bz) {
    for (int by = lo.y() >> 3; by <= hi.y() >> 3; ++by) {
      for (int bx = lo.x() >> 3; bx <= hi.x() >> 3; ++bx) {
        const CellKey corner(bx * 8, by * 8, bz * 8);
        const Eigen::Vector3d first_W = grid_.centreOf(corner) - t_W_C;  // from the camera
        const Eigen::Vector3d first_C = T_C_W.linear() * first_W;
        const Eigen::Vector3d centre_C = first_C + steps_C * Eigen::Vector3d::Constant(3.5);
        if (centre_C.z() < -block_radius_m || centre_C.z() - block_radius_m > max_z_m) continue;
        bool outside = false;
        for (const Eigen::Vector3d& n : planes) outside |= n.dot(centre_C) < -block_radius_m;
        if (outside) continue;
        if (config_.skip_hidden_blocks && behindSurface(first_C)) {
          ++stats->blocks_skipped;
          continue;
        }
        OccupancyBlock* block = nullptr;  // allocated on its first free cell
        for (int k = 0; k < 8; ++k) {
          const double dz_W = std::abs(first_W.z() + k * res);
          for (int j = 0; j < 8; ++j) {
            const double dyz_W = std::max(dz_W, std::abs(first_W.y() + j * res));
            Eigen::Vector3d p_C = first_C + steps_C.col(2) * k + steps_C.col(1) * j;
            for (int i = 0; i < 8; ++i, p_C += steps_C.col(0)) {
              const double z = p_C.z();
              if (z <= 0.0 || z > max_z_m) continue;
              const double inv_z = 1.0 / z;
              const double u = camera.fx * p_C.x() * inv_z + camera.cx;
              const double v = camera.fy * p_C.y() * inv_z + camera.cy;
              if (u < -0.5 || u >= w - 0.5 || v < -0.5 || v >= h - 0.5) continue;
              ++stats->cells_tested;
              // Depth at which the ray through the centre leaves the cube: half a cell along
              // the ray's dominant world axis (t = 0.5 res / |d|_inf for a unit direction d).
              const double far_m =
                  z * (1.0 + 0.5 * res / std::max(dyz_W, std::abs(first_W.x() + i * res)));
              if (far_m > config_.max_depth_m) continue;  // free space ends at max depth
              // Free when the surface lies beyond that depth at the centre pixel and at the
              // corners of the cell's projected face (a depth beyond max_depth_m passes).
              const double need = std::max(far_m, config_.min_depth_m) * inv_scale;
              const double du = 0.5 * res * camera.fx * inv_z, dv = 0.5 * res * camera.fy * inv_z;
              if (!(depthAt(u, v) > need && depthAt(u - du, v - dv) > need &&
                    depthAt(u + du, v - dv) > need && depthAt(u - du, v + dv) > need &&
                    depthAt(u + du, v + dv) > need)) {
                continue;
              }
              if (!block) block = grid_.allocateBlock(corner);
              OccupancyCell& cell = block->at(i, j, k);
              if (cell.last_frame == frames_) continue;
              model_.update(&cell, false);
              cell.last_frame = frames_;
              ++stats->free_updates;
            }
          }
        }
      }
    }
  }
  // The camera stands in free space.
  const CellKey key = grid_.keyOf(T_W_C.translation());
  OccupancyCell& cell = grid_.allocateBlock(key)->at(key.x() & 7, key.y() & 7, key.z() & 7);
  if (cell.last_frame != frames_) {
    model_.update(&cell, false);
    cell.last_frame = frames_;
    ++stats->free_updates;
  }
}

Occupancy OccupancyMap::stateOf(const octomap::OcTreeKey& key) const {
  const OccupancyCell* cell = grid_.findCell(CellKey(key[0], key[1], key[2]));
  if (!cell || cell->last_frame == 0) return Occupancy::kUnknown;
  return model_.occupied(*cell) ? Occupancy::kOccupied : Occupancy::kFree;
}

Occupancy OccupancyMap::occupancyAt(const Eigen::Vector3d& p_W) const {
  if (!p_W.allFinite()) throw Error("occupancy query point must be finite");
  octomap::OcTreeKey key;
  if (!geometry_->coordToKeyChecked(internal::toOctomapPoint(p_W), key)) {
    return Occupancy::kUnknown;
  }
  return stateOf(key);
}

SegmentCheck OccupancyMap::checkSegment(const Eigen::Vector3d& a_W,
                                        const Eigen::Vector3d& b_W) const {
  return internal::walkSegment(*geometry_, a_W, b_W,
                               [this](const octomap::OcTreeKey& key) { return stateOf(key); });
}

}  // namespace panmap

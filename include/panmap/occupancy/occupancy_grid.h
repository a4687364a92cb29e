#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include <absl/container/flat_hash_map.h>
#include <Eigen/Core>

namespace panmap {

/// Cells per block side: a block is one OctoMap node three levels above the leaves.
constexpr int kOccupancyBlockSide = 8;
/// Cells per block.
constexpr int kOccupancyBlockCells =
    kOccupancyBlockSide * kOccupancyBlockSide * kOccupancyBlockSide;
/// OctoMap's key of the cell at coordinate 0 (keys are 16 bits per axis centred here).
constexpr int kOctreeKeyCentre = 32768;

/// Integer cell coordinates in OctoMap's key space: cell k spans
/// [(k - 32768) res, (k - 32767) res) on each axis, so a key here is an octomap::OcTreeKey.
using CellKey = Eigen::Vector3i;

/// One cell: OctoMap's log-odds, and the frame that last changed it.
struct OccupancyCell {
  float log_odds = 0.0f;
  uint32_t last_frame = 0;  ///< 1-based frame number of the last update; 0 = never observed
};

/// An 8^3 cube of cells aligned with the octree (its corner key is a multiple of 8), x fastest.
struct OccupancyBlock {
  CellKey corner = CellKey::Zero();  ///< key of cell (0, 0, 0)
  OccupancyCell cells[kOccupancyBlockCells];

  /// Cell at local coordinates (x, y, z), each in [0, 8).
  OccupancyCell& at(int x, int y, int z) { return cells[x + 8 * (y + 8 * z)]; }
  /// Cell at local coordinates (x, y, z), each in [0, 8).
  const OccupancyCell& at(int x, int y, int z) const { return cells[x + 8 * (y + 8 * z)]; }
};

/// OctoMap's sensor model in its own float log-odds arithmetic, so that a cell here holds
/// exactly the value an OcTree given the same hits and misses would hold.
struct LogOddsModel {
  float hit = 0.0f;        ///< added on a hit
  float miss = 0.0f;       ///< added on a miss (negative)
  float clamp_min = 0.0f;  ///< values are clamped to [clamp_min, clamp_max]
  float clamp_max = 0.0f;
  float threshold = 0.0f;  ///< at or above: occupied

  /// OctoMap's updateNodeLogOdds: add, then clamp.
  void update(OccupancyCell* cell, bool hit_not_miss) const {
    cell->log_odds += hit_not_miss ? hit : miss;
    if (cell->log_odds < clamp_min) cell->log_odds = clamp_min;
    if (cell->log_odds > clamp_max) cell->log_odds = clamp_max;
  }
  /// True when an observed cell counts as occupied.
  bool occupied(const OccupancyCell& cell) const { return cell.log_odds >= threshold; }
};

/// Hashed blocks of occupancy cells, the live store of an OccupancyMap. Blocks are created on
/// demand, never move, and are kept in creation order (deterministic for a deterministic input).
class OccupancyGrid {
 public:
  /// @param resolution_m cell edge length, metres
  explicit OccupancyGrid(double resolution_m)
      : resolution_m_(resolution_m), inv_resolution_(1.0 / resolution_m) {}

  /// Cell edge length, metres.
  double resolution() const { return resolution_m_; }

  /// Key of the cell containing a coordinate, as OctoMap's coordToKey computes it.
  int keyOf(double coordinate_m) const {
    return static_cast<int>(std::floor(inv_resolution_ * coordinate_m)) + kOctreeKeyCentre;
  }
  /// Key of the cell containing a world point.
  CellKey keyOf(const Eigen::Vector3d& p_W) const {
    return CellKey(keyOf(p_W.x()), keyOf(p_W.y()), keyOf(p_W.z()));
  }
  /// Centre of a cell, world frame, metres (OctoMap's keyToCoord).
  Eigen::Vector3d centreOf(const CellKey& key) const {
    return ((key.array() - kOctreeKeyCentre).cast<double>() + 0.5) * resolution_m_;
  }

  /// The block holding a cell key, or null when not allocated.
  OccupancyBlock* findBlock(const CellKey& key);
  /// @copydoc findBlock
  const OccupancyBlock* findBlock(const CellKey& key) const;
  /// The block holding a cell key, allocated (every cell unobserved) when missing.
  OccupancyBlock* allocateBlock(const CellKey& key);
  /// The cell at a key, or null when its block is not allocated.
  const OccupancyCell* findCell(const CellKey& key) const;

  /// Allocated blocks in creation order.
  const std::vector<std::unique_ptr<OccupancyBlock>>& blocks() const { return blocks_; }
  /// Bytes used by cells and the index.
  size_t memoryBytes() const;

 private:
  static uint64_t hashKey(const CellKey& key) {
    return static_cast<uint64_t>(key.x() >> 3) | static_cast<uint64_t>(key.y() >> 3) << 13 |
           static_cast<uint64_t>(key.z() >> 3) << 26;
  }

  double resolution_m_;
  double inv_resolution_;
  absl::flat_hash_map<uint64_t, OccupancyBlock*> index_;
  std::vector<std::unique_ptr<OccupancyBlock>> blocks_;
};

}  // namespace panmap

// OccupancyMap -> OctoMap OcTree and its binary forms (octree_io.h writes them).
#include <algorithm>
#include <vector>

#include "panmap/occupancy/occupancy_map.h"
#include "panmap/occupancy/octree_io.h"

namespace panmap {

namespace {

// Octants (2^6 = 64 cells a side, up to 512 blocks) pruned as soon as their last block is in:
// a building's unpruned leaves alone would be 700 MB, its pruned tree is under 2 MB.
constexpr int kPruneOctantBits = 6;

// Collapses every uniform octant below `node`, deepest first (what prune() does for the whole
// tree; pruneNode() only merges children that are equal leaves).
void pruneBelow(octomap::OcTree* tree, octomap::OcTreeNode* node) {
  if (!tree->nodeHasChildren(node)) return;
  for (unsigned int i = 0; i < 8; ++i) {
    if (tree->nodeChildExists(node, i)) pruneBelow(tree, tree->getNodeChild(node, i));
  }
  tree->pruneNode(node);
}

}  // namespace

std::unique_ptr<octomap::OcTree> OccupancyMap::toOcTree() const {
  auto tree = std::make_unique<octomap::OcTree>(config_.resolution_m);
  tree->setProbHit(config_.prob_hit);
  tree->setProbMiss(config_.prob_miss);
  tree->setClampingThresMin(config_.clamping_min);
  tree->setClampingThresMax(config_.clamping_max);
  tree->setOccupancyThres(config_.occupancy_threshold);
  const float occupied = tree->getClampingThresMaxLog(), free = tree->getClampingThresMinLog();
  // Blocks in octree (Morton) order: consecutive insertions share most of their path from the
  // root, which keeps the descent in cache.
  std::vector<const OccupancyBlock*> blocks;
  blocks.reserve(grid_.blocks().size());
  for (const auto& block : grid_.blocks()) blocks.push_back(block.get());
  auto morton = [](const CellKey& corner) {
    uint64_t code = 0;
    for (int bit = 15; bit >= 3; --bit) {
      for (int axis = 2; axis >= 0; --axis) code = code << 1 | ((corner[axis] >> bit) & 1);
    }
    return code;
  };
  std::sort(blocks.begin(), blocks.end(), [&](const OccupancyBlock* a, const OccupancyBlock* b) {
    return morton(a->corner) < morton(b->corner);
  });
  // Maximum-likelihood leaves, as OctoMap's own writeBinary() would make them; lazy: inner
  // nodes are computed once at the end. In Morton order an octant's blocks are consecutive, so
  // it is pruned when the next block lies outside it.
  const int octant_shift = 3 * (kPruneOctantBits - 3);
  const unsigned int octant_depth = tree->getTreeDepth() - kPruneOctantBits;
  auto pruneOctantOf = [&](const OccupancyBlock* block) {
    const octomap::OcTreeKey key(block->corner.x(), block->corner.y(), block->corner.z());
    if (octomap::OcTreeNode* node = tree->search(key, octant_depth)) pruneBelow(tree.get(), node);
  };
  for (size_t b = 0; b < blocks.size(); ++b) {
    const OccupancyBlock* block = blocks[b];
    if (b > 0 &&
        morton(block->corner) >> octant_shift != morton(blocks[b - 1]->corner) >> octant_shift) {
      pruneOctantOf(blocks[b - 1]);
    }
    for (int k = 0; k < 8; ++k) {
      for (int j = 0; j < 8; ++j) {
        for (int i = 0; i < 8; ++i) {
          const OccupancyCell& cell = block->at(i, j, k);
          if (cell.last_frame == 0) continue;
          const octomap::OcTreeKey key(block->corner.x() + i, block->corner.y() + j,
                                       block->corner.z() + k);
          tree->setNodeValue(key, model_.occupied(cell) ? occupied : free, true);
        }
      }
    }
  }
  // Leaves only take the two clamped values, so pruning collapses every uniform octant: the
  // result depends on the cells' states alone, not on the order they were set in.
  tree->prune();
  tree->updateInnerOccupancy();
  return tree;
}

std::string OccupancyMap::toBinaryData() const { return panmap::toBinaryData(*toOcTree()); }

std::string OccupancyMap::toBtBytes() const { return panmap::toBtBytes(*toOcTree()); }

void OccupancyMap::writeBt(const std::string& path) const { writeBtFile(*toOcTree(), path); }

}  // namespace panmap

#include "panmap/occupancy/occupancy_grid.h"

namespace panmap {

OccupancyBlock* OccupancyGrid::findBlock(const CellKey& key) {
  const auto it = index_.find(hashKey(key));
  return it == index_.end() ? nullptr : it->second;
}

const OccupancyBlock* OccupancyGrid::findBlock(const CellKey& key) const {
  const auto it = index_.find(hashKey(key));
  return it == index_.end() ? nullptr : it->second;
}

OccupancyBlock* OccupancyGrid::allocateBlock(const CellKey& key) {
  auto [it, inserted] = index_.try_emplace(hashKey(key), nullptr);
  if (inserted) {
    blocks_.push_back(std::make_unique<OccupancyBlock>());
    blocks_.back()->corner = CellKey(key.x() & ~7, key.y() & ~7, key.z() & ~7);
    it->second = blocks_.back().get();
  }
  return it->second;
}

const OccupancyCell* OccupancyGrid::findCell(const CellKey& key) const {
  const OccupancyBlock* block = findBlock(key);
  return block ? &block->at(key.x() & 7, key.y() & 7, key.z() & 7) : nullptr;
}

size_t OccupancyGrid::memoryBytes() const {
  return blocks_.size() * sizeof(OccupancyBlock) +
         index_.capacity() * (sizeof(uint64_t) + sizeof(OccupancyBlock*) + 1);
}

}  // namespace panmap

// Occupancy cells in map files, so that a resumed map keeps its free and occupied space.
#include "panmap/core/error.h"
#include "panmap/occupancy/occupancy_map.h"

namespace panmap {

void OccupancyMap::writeState(BinaryWriter* out) const {
  out->put<uint32_t>(frames_);
  out->put<uint64_t>(grid_.blocks().size());
  for (const auto& block : grid_.blocks()) {
    out->put<int32_t>(block->corner.x());
    out->put<int32_t>(block->corner.y());
    out->put<int32_t>(block->corner.z());
    out->putBytes(block->cells, sizeof(block->cells));
  }
}

void OccupancyMap::readState(BinaryReader* in) {
  grid_ = OccupancyGrid(config_.resolution_m);
  frames_ = 0;
  const uint32_t frames = in->get<uint32_t>();
  const uint64_t blocks = in->getCount(12 + sizeof(OccupancyBlock::cells));
  for (uint64_t i = 0; i < blocks; ++i) {
    CellKey corner;
    corner.x() = in->get<int32_t>();
    corner.y() = in->get<int32_t>();
    corner.z() = in->get<int32_t>();
    if (corner.x() % kOccupancyBlockSide != 0 || corner.y() % kOccupancyBlockSide != 0 ||
        corner.z() % kOccupancyBlockSide != 0 || grid_.findBlock(corner)) {
      grid_ = OccupancyGrid(config_.resolution_m);
      throw Error("occupancy: block corner not on the block grid, or repeated");
    }
    OccupancyBlock* block = grid_.allocateBlock(corner);
    in->getBytes(block->cells, sizeof(block->cells));
  }
  frames_ = frames;
}

}  // namespace panmap

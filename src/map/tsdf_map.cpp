#include "panmap/map/tsdf_map.h"

#include <cmath>
#include <string>

#include "panmap/core/error.h"

namespace panmap {

void TsdfMap::Config::check() const {
  // Below 1 mm no RGB-D sensor resolves anything, and a room's map grows without bound (0.1 mm
  // filled 5.8 GB in 40 s; 1e-9 m refused every frame as "extent").
  if (!(voxel_size_m >= 0.001f && voxel_size_m < 1.0f)) {
    throw Error("map voxel_size_m must be in [0.001, 1) metres");
  }
}

namespace {

uint64_t newMapId() {
  static std::atomic<uint64_t> next_id{0};
  return ++next_id;
}

}  // namespace

TsdfMap::TsdfMap(const Config& config) : config_(config), id_(newMapId()) { config_.check(); }

TsdfMap::TsdfMap(TsdfMap&& other) noexcept
    : config_(other.config_),
      id_(other.id_),
      change_stamp_(other.change_stamp_.load()),
      index_(std::move(other.index_)),
      blocks_(std::move(other.blocks_)) {
  other.id_ = newMapId();
  other.index_.clear();
  other.blocks_.clear();
}

TsdfMap& TsdfMap::operator=(TsdfMap&& other) noexcept {
  if (this == &other) return *this;
  config_ = other.config_;
  id_ = other.id_;
  change_stamp_ = other.change_stamp_.load();
  index_ = std::move(other.index_);
  blocks_ = std::move(other.blocks_);
  other.id_ = newMapId();
  other.index_.clear();
  other.blocks_.clear();
  return *this;
}

BlockIndex TsdfMap::blockIndexOf(const Eigen::Vector3f& p_W) const {
  const float inv = 1.0f / blockSize();
  return BlockIndex(static_cast<int>(std::floor(p_W.x() * inv)),
                    static_cast<int>(std::floor(p_W.y() * inv)),
                    static_cast<int>(std::floor(p_W.z() * inv)));
}

Block* TsdfMap::findBlock(const BlockIndex& index) {
  const auto it = index_.find(key(index));
  return it == index_.end() ? nullptr : it->second;
}

const Block* TsdfMap::findBlock(const BlockIndex& index) const {
  const auto it = index_.find(key(index));
  return it == index_.end() ? nullptr : it->second;
}

Block* TsdfMap::allocateBlock(const BlockIndex& index) {
  auto [it, inserted] = index_.try_emplace(key(index), nullptr);
  if (inserted) {
    blocks_.push_back(std::make_unique<Block>());
    blocks_.back()->index = index;
    it->second = blocks_.back().get();
  }
  return it->second;
}

const Block* TsdfMap::findBlockOfPoint(const Eigen::Vector3f& p_W, int* voxel) const {
  const float inv = 1.0f / config_.voxel_size_m;
  const int gx = static_cast<int>(std::floor(p_W.x() * inv));
  const int gy = static_cast<int>(std::floor(p_W.y() * inv));
  const int gz = static_cast<int>(std::floor(p_W.z() * inv));
  // Floor division by the block side (works for negative coordinates).
  static_assert(kBlockSide == 8, "shift by 3 assumes 8 voxels per block side");
  *voxel = Block::linear(gx & 7, gy & 7, gz & 7);
  return findBlock(BlockIndex(gx >> 3, gy >> 3, gz >> 3));
}

const Voxel* TsdfMap::findVoxel(const Eigen::Vector3f& p_W) const {
  int i = 0;
  const Block* block = findBlockOfPoint(p_W, &i);
  return block ? &block->voxels[i] : nullptr;
}

const VoxelVotes* TsdfMap::findVotes(const Eigen::Vector3f& p_W) const {
  int i = 0;
  const Block* block = findBlockOfPoint(p_W, &i);
  return block ? block->votes(i) : nullptr;
}

Eigen::Vector3f TsdfMap::voxelCentre(const BlockIndex& block, int x, int y, int z) const {
  const float v = config_.voxel_size_m;
  return Eigen::Vector3f((block.x() * kBlockSide + x + 0.5f) * v,
                         (block.y() * kBlockSide + y + 0.5f) * v,
                         (block.z() * kBlockSide + z + 0.5f) * v);
}

size_t TsdfMap::numVotedVoxels() const {
  size_t n = 0;
  for (const auto& block : blocks_) n += block->vote_sets.size();
  return n;
}

void TsdfMap::renameVotes(const std::vector<int32_t>& to) {
  for (const auto& block : blocks_) {
    for (const VoxelVotes& votes : block->vote_sets) {
      for (const LabelVote& v : votes.slots) {
        if (v.count == 0) continue;
        const int32_t label = v.label;
        if (label < 0 || static_cast<size_t>(label) >= to.size() || to[label] <= 0) {
          throw Error("renameVotes: no new label for label " + std::to_string(label));
        }
      }
    }
  }
  const auto rename = [&to](int32_t label) { return to[label]; };
  for (const auto& block : blocks_) {
    if (block->vote_sets.empty()) continue;
    for (VoxelVotes& votes : block->vote_sets) panmap::renameVotes(&votes, rename);
    markChanged(block.get());
  }
}

size_t TsdfMap::memoryBytes() const {
  size_t votes = 0;
  for (const auto& block : blocks_) votes += block->vote_sets.capacity() * sizeof(VoxelVotes);
  return blocks_.size() * sizeof(Block) + votes +
         index_.capacity() * (sizeof(uint64_t) + sizeof(Block*) + 1);
}

}  // namespace panmap

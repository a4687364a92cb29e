#include "panmap/graph/surface_scan.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include "panmap/core/container_memory.h"
#include "panmap/core/error.h"
#include "panmap/graph/internal/touching_voxels.h"
#include "panmap/map/voxel.h"

namespace panmap {

namespace {

/// Runs fn(begin, end, thread) over [0, n) on the pool (blocks cost unevenly), or inline.
void forRange(ThreadPool* pool, size_t n, const std::function<void(size_t, size_t, int)>& fn) {
  if (pool && pool->size() > 1) {
    pool->parallelForDynamic(n, 64, fn);
  } else {
    fn(0, n, 0);
  }
}

/// Whether a label of the summary (a root, an owner or an end of a pair) is no root any more.
bool namesMergedLabel(const SurfaceScan::Summary& s, const std::vector<int32_t>& roots) {
  auto merged = [&roots](int32_t l) { return l > 0 && roots[static_cast<size_t>(l)] != l; };
  for (int32_t r : s.roots) {
    if (merged(r)) return true;
  }
  for (const SurfaceScan::Owner& o : s.owners) {
    if (merged(o.label)) return true;
  }
  for (uint64_t pair : s.pairs) {
    if (merged(static_cast<int32_t>(pair >> 32)) ||
        merged(static_cast<int32_t>(pair & 0xFFFFFFFFu))) {
      return true;
    }
  }
  return false;
}

/// A block read again: its summary and its surface owners (empty when it owns none).
struct Reading {
  SurfaceScan::Summary summary;
  std::vector<int32_t> owners;
};

}  // namespace

void SurfaceScan::reset(const TsdfMap& map, float band_voxels) {
  map_id_ = map.id();
  band_voxels_ = band_voxels;
  registry_size_ = -1;
  summaries_.clear();
  position_.clear();
  voxels_.clear();
  surface_.clear();
  vote_blocks_.clear();
  index_sum_.clear();
  pair_blocks_.clear();
}

void SurfaceScan::add(const Summary& s, const BlockIndex& index, int sign) {
  const Eigen::Matrix<int64_t, 3, 1> origin = index.cast<int64_t>() * kBlockSide;
  for (int32_t root : s.roots) vote_blocks_[static_cast<size_t>(root)] += sign;
  for (const Owner& o : s.owners) {
    const auto l = static_cast<size_t>(o.label);
    voxels_[l] += sign * o.voxels;
    surface_[l] += sign * o.surface;
    const Eigen::Matrix<int64_t, 3, 1> sum(o.index_sum[0], o.index_sum[1], o.index_sum[2]);
    index_sum_[l] += sign * (origin * o.voxels + sum);
  }
  for (uint64_t pair : s.pairs) {
    const int count = pair_blocks_[pair] += sign;
    if (count == 0) pair_blocks_.erase(pair);
  }
}

SurfaceScan::Summary SurfaceScan::renamed(const Summary& s, const std::vector<int32_t>& roots) {
  auto root = [&roots](int32_t l) { return l > 0 ? roots[static_cast<size_t>(l)] : l; };
  Summary out;
  out.changed = s.changed;
  out.read = s.read;
  out.tied = s.tied;  // renamed blocks keep their tied roots (refresh checks)
  out.roots.reserve(s.roots.size());
  for (int32_t r : s.roots) out.roots.push_back(root(r));
  std::sort(out.roots.begin(), out.roots.end());
  out.owners = s.owners;
  for (Owner& o : out.owners) o.label = root(o.label);
  // Distinct: a renamed block's roots stayed distinct (refresh checks), so its owners did.
  std::sort(out.owners.begin(), out.owners.end(),
            [](const Owner& a, const Owner& b) { return a.label < b.label; });
  out.pairs.reserve(s.pairs.size());
  for (uint64_t pair : s.pairs) {
    const int32_t a = root(static_cast<int32_t>(pair >> 32));
    const int32_t b = root(static_cast<int32_t>(pair & 0xFFFFFFFFu));
    if (a != b) out.pairs.push_back(SurfaceAdjacency::key(a, b));
  }
  std::sort(out.pairs.begin(), out.pairs.end());
  out.pairs.erase(std::unique(out.pairs.begin(), out.pairs.end()), out.pairs.end());
  out.pairs.shrink_to_fit();
  return out;
}

void SurfaceScan::refresh(const TsdfMap& map, const LabelRegistry& registry, float band_voxels,
                          ThreadPool* pool) {
  if (!(band_voxels > 0.0f)) throw Error("surface scan band_voxels must be > 0");
  const auto& blocks = map.blocks();
  if (map.id() != map_id_ || band_voxels != band_voxels_ || registry.size() < registry_size_ ||
      blocks.size() < summaries_.size()) {
    reset(map, band_voxels);
  }
  voxel_m_ = map.voxelSize();
  registry.flatten();
  const std::vector<int32_t>& roots = registry.parents();
  const auto num_labels = roots.size();
  const bool registry_grew = registry.size() != registry_size_;
  registry_size_ = registry.size();
  voxels_.resize(num_labels, 0);
  surface_.resize(num_labels, 0);
  vote_blocks_.resize(num_labels, 0);
  index_sum_.resize(num_labels, Eigen::Matrix<int64_t, 3, 1>::Zero());
  for (size_t i = summaries_.size(); i < blocks.size(); ++i) {
    position_.emplace(TsdfMap::key(blocks[i]->index), i);
  }
  summaries_.resize(blocks.size());

  // Blocks whose voxels changed since they were read, or whose votes' roots did in a way that
  // can change an owner (kRead); blocks whose roots merged into distinct roots, none of a tie
  // (kRename: every owner keeps its voxels under a new name).
  enum : uint8_t { kClean = 0, kRead = 1, kRename = 2 };
  std::vector<uint8_t> state(blocks.size(), kClean);
  forRange(pool, blocks.size(), [&](size_t begin, size_t end, int) {
    for (size_t b = begin; b < end; ++b) {
      const Summary& s = summaries_[b];
      if (!s.read || s.changed != blocks[b]->changed.load(std::memory_order_relaxed)) {
        state[b] = kRead;
        continue;
      }
      bool merged = false, renamable = true;
      for (size_t k = 0; k < s.roots.size(); ++k) {
        // Root 0: a vote whose label the registry did not know then; it may know it now.
        const int32_t r = s.roots[k];
        if (r == 0) {
          if (registry_grew) merged = true, renamable = false;
          continue;
        }
        const int32_t now = roots[static_cast<size_t>(r)];
        if (now == r) continue;
        merged = true;
        // A voxel with a tie may now prefer the other label of it.
        if (std::binary_search(s.tied.begin(), s.tied.end(), r)) renamable = false;
        // Two roots of the block became one: a voxel voting for both now sums their counts.
        for (size_t j = 0; j < s.roots.size() && renamable; ++j) {
          if (j != k && s.roots[j] > 0 && roots[static_cast<size_t>(s.roots[j])] == now) {
            renamable = false;
          }
        }
      }
      state[b] = !merged ? kClean : renamable ? kRename : kRead;
    }
  });
  // Touching pairs cross block faces: a changed block's neighbours are read again too. Their
  // own neighbours' owners are needed to find the pairs.
  auto neighbours = [&](size_t b, auto&& fn) {
    const BlockIndex index = blocks[b]->index;
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const auto it = position_.find(TsdfMap::key(index + BlockIndex(dx, dy, dz)));
          if (it != position_.end()) fn(it->second);
        }
      }
    }
  };
  std::vector<uint8_t> role(blocks.size(), 0);  // 2: read again, 1: owners only
  for (size_t b = 0; b < blocks.size(); ++b) {
    if (state[b] == kRead) neighbours(b, [&role](size_t n) { role[n] = 2; });
  }
  // A renamed block's pairs and its neighbours' name its owners: all of them are renamed
  // (those read again anyway are not).
  std::vector<uint8_t> rename(blocks.size(), 0);
  for (size_t b = 0; b < blocks.size(); ++b) {
    if (state[b] == kRename) neighbours(b, [&rename](size_t n) { rename[n] = 1; });
  }
  std::vector<size_t> read, near_list;
  for (size_t b = 0; b < blocks.size(); ++b) {
    if (role[b] == 2) read.push_back(b);
  }
  for (size_t b : read) {
    neighbours(b, [&role](size_t n) {
      if (role[n] == 0) role[n] = 1;
    });
  }
  std::vector<int32_t> slot(blocks.size(), -1);  // position -> index into readings
  for (size_t b = 0; b < blocks.size(); ++b) {
    if (role[b] != 0) {
      slot[b] = static_cast<int32_t>(near_list.size());
      near_list.push_back(b);
    }
  }
  last_read_ = read.size();
  readBlocks(map, roots, band_voxels, read, near_list, slot, role, pool);
  std::vector<size_t> renames;
  for (size_t b = 0; b < blocks.size(); ++b) {
    if (rename[b] && role[b] != 2) renames.push_back(b);
  }
  std::vector<Summary> renamed_summaries(renames.size());
  std::vector<uint8_t> renamed_any(renames.size(), 0);
  forRange(pool, renames.size(), [&](size_t begin, size_t end, int) {
    for (size_t k = begin; k < end; ++k) {
      const Summary& s = summaries_[renames[k]];
      if (!namesMergedLabel(s, roots)) continue;  // blocks never read are read (kRead)
      renamed_summaries[k] = renamed(s, roots);
      renamed_any[k] = 1;
    }
  });
  last_renamed_ = 0;
  for (size_t k = 0; k < renames.size(); ++k) {  // in block order, as the blocks read
    if (!renamed_any[k]) continue;
    const size_t b = renames[k];
    add(summaries_[b], blocks[b]->index, -1);
    summaries_[b] = std::move(renamed_summaries[k]);
    add(summaries_[b], blocks[b]->index, 1);
    ++last_renamed_;
  }
}

void SurfaceScan::readBlocks(const TsdfMap& map, const std::vector<int32_t>& roots,
                             float band_voxels, const std::vector<size_t>& read,
                             const std::vector<size_t>& near_list, const std::vector<int32_t>& slot,
                             const std::vector<uint8_t>& role, ThreadPool* pool) {
  if (read.empty()) return;
  const auto& blocks = map.blocks();
  const auto num_labels = roots.size();

  const float band_m = band_voxels * map.voxelSize();
  const auto size = static_cast<int32_t>(num_labels);
  auto resolve = [&roots, size](int32_t l) { return l > 0 && l < size ? roots[l] : 0; };
  std::vector<Reading> readings(near_list.size());
  forRange(pool, near_list.size(), [&](size_t begin, size_t end, int) {
    for (size_t n = begin; n < end; ++n) {
      const size_t b = near_list[n];
      const Block& block = *blocks[b];
      Reading& reading = readings[n];
      const bool full = role[b] == 2;
      Summary& s = reading.summary;
      if (full) {
        // What the next refresh compares: a writer moving it sends the block back to be read.
        s.changed = block.changed.load(std::memory_order_relaxed);
        s.read = true;
      }
      for (int i = 0; i < kBlockVoxels; ++i) {
        const Voxel& voxel = block.voxels[i];
        const VoxelVotes* votes = block.votes(i);
        if (full && votes) {
          // A block's votes name a handful of roots: a search beats sorting thousands.
          for (const LabelVote& vote : *votes) {
            if (vote.count == 0) continue;
            const int32_t root = resolve(vote.label);
            if (std::find(s.roots.begin(), s.roots.end(), root) == s.roots.end()) {
              s.roots.push_back(root);
            }
          }
        }
        const bool on_surface = voxel.weight > 0.0f && std::fabs(voxel.sdf_m) <= band_m;
        if (!on_surface && !full) continue;
        bool tie = false;  // asked only of full reads: only their summaries keep it
        const int32_t label = argmaxLabel(votes, resolve, full ? &tie : nullptr);
        if (label <= 0) continue;
        if (tie) {
          for (const LabelVote& vote : *votes) {
            const int32_t root = resolve(vote.label);
            if (vote.count > 0 && std::find(s.tied.begin(), s.tied.end(), root) == s.tied.end()) {
              s.tied.push_back(root);
            }
          }
        }
        if (full) {
          auto it = std::lower_bound(s.owners.begin(), s.owners.end(), label,
                                     [](const Owner& o, int32_t l) { return o.label < l; });
          if (it == s.owners.end() || it->label != label) {
            it = s.owners.insert(it, Owner{label, 0, 0, {0, 0, 0}});
          }
          ++it->voxels;
          it->index_sum[0] += static_cast<uint16_t>(i % kBlockSide);
          it->index_sum[1] += static_cast<uint16_t>((i / kBlockSide) % kBlockSide);
          it->index_sum[2] += static_cast<uint16_t>(i / (kBlockSide * kBlockSide));
          if (on_surface) ++it->surface;
        }
        if (!on_surface) continue;
        if (reading.owners.empty()) reading.owners.assign(kBlockVoxels, 0);
        reading.owners[static_cast<size_t>(i)] = label;
      }
      if (full) {
        std::sort(s.roots.begin(), s.roots.end());
        std::sort(s.tied.begin(), s.tied.end());
        s.roots.shrink_to_fit();
        s.tied.shrink_to_fit();
        s.owners.shrink_to_fit();
      }
    }
  });
  forRange(pool, read.size(), [&](size_t begin, size_t end, int) {
    for (size_t k = begin; k < end; ++k) {
      const size_t b = read[k];
      Reading& reading = readings[static_cast<size_t>(slot[b])];
      if (reading.owners.empty()) continue;
      internal::NearOwners near;
      const BlockIndex index = blocks[b]->index;
      for (int dz = -1; dz <= 1; ++dz) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            const auto it = position_.find(TsdfMap::key(index + BlockIndex(dx, dy, dz)));
            const std::vector<int32_t>* owners = nullptr;
            if (it != position_.end()) {
              const std::vector<int32_t>& o =
                  readings[static_cast<size_t>(slot[it->second])].owners;
              if (!o.empty()) owners = &o;
            }
            near[dx + 1][dy + 1][dz + 1] = owners;
          }
        }
      }
      std::vector<uint64_t>& pairs = reading.summary.pairs;
      internal::forEachTouchingPair(
          near, [&pairs](int32_t a, int32_t c) { pairs.push_back(SurfaceAdjacency::key(a, c)); });
      std::sort(pairs.begin(), pairs.end());
      pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
      pairs.shrink_to_fit();
    }
  });
  // In block order: the sums are integers, so the order only keeps the hash map's history
  // the same on every run.
  for (size_t b : read) {
    Summary& old = summaries_[b];
    if (old.read) add(old, blocks[b]->index, -1);
    old = std::move(readings[static_cast<size_t>(slot[b])].summary);
    add(old, blocks[b]->index, 1);
  }
}

SurfaceAdjacency SurfaceScan::adjacency() const {
  SurfaceAdjacency out;
  for (size_t l = 1; l < surface_.size(); ++l) {
    if (surface_[l] > 0) out.surface_voxels_.emplace(static_cast<int32_t>(l), surface_[l]);
  }
  out.pairs_.reserve(pair_blocks_.size());
  for (const auto& [pair, count] : pair_blocks_) out.pairs_.insert(pair);
  return out;
}

void SurfaceScan::addTotals(SurfaceAdjacency::OwnerTotals* totals) const {
  if (totals->centre_sum.size() != totals->voxels.size()) {
    throw Error("surface scan totals: voxels and centre_sum differ in size");
  }
  // Same arithmetic as SurfaceAdjacency::compute: (sum + count / 2) x voxel size.
  const double voxel_m = voxel_m_;
  const size_t n = std::min(totals->voxels.size(), voxels_.size());
  for (size_t l = 1; l < n; ++l) {
    const int64_t count = voxels_[l];
    if (count == 0) continue;
    totals->voxels[l] += static_cast<int>(count);
    totals->centre_sum[l] += (index_sum_[l].cast<double>() +
                              Eigen::Vector3d::Constant(0.5 * static_cast<double>(count))) *
                             voxel_m;
  }
}

std::vector<uint8_t> SurfaceScan::hasVotes() const {
  std::vector<uint8_t> has(vote_blocks_.size(), 0);
  for (size_t l = 0; l < vote_blocks_.size(); ++l) has[l] = vote_blocks_[l] > 0 ? 1 : 0;
  return has;
}

size_t SurfaceScan::memoryBytes() const {
  size_t bytes = vectorBytes(summaries_) + vectorBytes(voxels_) + vectorBytes(surface_) +
                 vectorBytes(vote_blocks_) + vectorBytes(index_sum_) +
                 position_.capacity() * (sizeof(std::pair<const uint64_t, size_t>) + 1) +
                 pair_blocks_.capacity() * (sizeof(std::pair<const uint64_t, int>) + 1);
  for (const Summary& s : summaries_) {
    bytes +=
        vectorBytes(s.roots) + vectorBytes(s.tied) + vectorBytes(s.owners) + vectorBytes(s.pairs);
  }
  return bytes;
}

}  // namespace panmap

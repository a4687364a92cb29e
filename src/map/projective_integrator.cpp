#include "panmap/map/projective_integrator.h"

#include <algorithm>
#include <atomic>
#include <cmath>

#include "panmap/core/error.h"
#include "panmap/map/internal/block_integration.h"
#include "panmap/map/internal/vote_rows.h"
#include "panmap/map/row_grid.h"
#include "panmap/map/voxel_lookup.h"

namespace panmap {

void IntegratorConfig::check() const {
  if (!(truncation_voxels >= 1.0f)) throw Error("integrator truncation_voxels must be >= 1");
  if (!(max_weight > 0.0f)) throw Error("integrator max_weight must be > 0");
  // Voxel weights are 2-byte floats (Voxel::weight): at 1,024 their step is 1 already.
  if (max_weight > 1000.0f) throw Error("integrator max_weight must be <= 1000");
  if (!(min_depth_m >= 0.0f && max_depth_m > min_depth_m)) {
    throw Error("integrator needs 0 <= min_depth_m < max_depth_m");
  }
  if (vote_stride_px < 0) throw Error("integrator vote_stride_px must be >= 0 (0 = automatic)");
}

int voteStride(const IntegratorConfig& config, float voxel_size_m, double fx_px) {
  if (config.vote_stride_px > 0) return config.vote_stride_px;
  const double spacing = voxel_size_m * fx_px / (2.0 * config.max_depth_m);
  // Clamped before the conversion (a huge focal length would overflow int); beyond 64 pixels a
  // frame would vote in too few places to label small segments at all.
  return static_cast<int>(std::clamp(std::floor(spacing), 1.0, 64.0));
}

ProjectiveIntegrator::ProjectiveIntegrator(const IntegratorConfig& config, ThreadPool* pool)
    : config_(config), pool_(pool) {
  config_.check();
  if (!pool_) throw Error("integrator needs a thread pool");
}

namespace {

// Image rows whose votes are found and summed together: a voxel wider than a pixel gets a run
// of votes from each of the rows that cross it, and one sum per band replaces them all. A
// fixed band, not a thread's share of rows, so that the sums are the same whatever the threads.
constexpr size_t kVoteBandRows = 16;
// Runs ahead whose vote slot is prefetched while votes are applied.
constexpr size_t kAhead = 16;

BlockIndex unpackKey(uint64_t key) {
  auto field = [](uint64_t v) {
    const int x = static_cast<int>(v & 0x1FFFFF);
    return x >= (1 << 20) ? x - (1 << 21) : x;  // sign-extend 21 bits
  };
  return BlockIndex(field(key >> 42), field(key >> 21), field(key));
}

// The thread that applies votes to a block: one per block, since a voxel's first vote grows
// the block's vote sets (Block::votesToWrite); hashed so that blocks spread evenly.
uint32_t voteOwner(const Block* block, size_t owners) {
  const uint64_t region = reinterpret_cast<uintptr_t>(block) >> 6;
  return static_cast<uint32_t>(((region * 0x9E3779B97F4A7C15ull) >> 32) * owners >> 32);
}

}  // namespace

// Pi_V (Eq. 2's counts): every labelled pixel votes for its label in the voxel its measured
// point falls in, as in the paper (a vote per point, not per projected voxel: projective
// distances stretch at grazing angles and would miss the surface voxels there).
// Two passes so both can run on every thread and still give the single-threaded result: first
// each pixel's voxel is looked up (bands of rows split between threads, the map is only read),
// each band's votes summed per voxel and label (sumVoteRuns) and grouped by the thread that
// owns their voxel's block; then every thread applies its own sums band by band, so each voxel
// sees its votes in the same order whatever the thread count.
void ProjectiveIntegrator::voteLabels(const RgbdFrame& frame, const Eigen::Isometry3f& T_W_C,
                                      const LabelImage& labels, TsdfMap* map,
                                      IntegrationStats* stats) {
  const PinholeCamera& cam = frame.camera;
  const RowCamera row_cam = RowCamera::of(cam);
  const int stride = voteStride(config_, map->voxelSize(), cam.fx);
  const size_t cols = (cam.width + stride - 1) / stride, rows = (cam.height + stride - 1) / stride;
  const size_t bands = (rows + kVoteBandRows - 1) / kVoteBandRows;
  const size_t band_capacity = cols * kVoteBandRows;
  const size_t owners = static_cast<size_t>(pool_->size());
  if (vote_runs_.size() < bands * band_capacity) vote_runs_.resize(bands * band_capacity);
  owner_begin_.resize(bands * (owners + 1));
  band_scratch_.resize(owners);
  // Bands differ a lot in cost (invalid depth, blocks missed by the cache): whichever thread is
  // free takes the next; each band's sums land in its own slot.
  pool_->parallelForDynamic(bands, 1, [&](size_t b0, size_t b1, int thread) {
    MutableVoxelLookup lookup(*map);
    BandScratch& scratch = band_scratch_[thread];
    if (owners > 1 && scratch.runs.size() < band_capacity) {
      scratch.runs.resize(band_capacity);
      scratch.owner.resize(band_capacity);
    }
    scratch.next.resize(owners);
    for (size_t b = b0; b < b1; ++b) {
      size_t* begin = &owner_begin_[b * (owners + 1)];
      VoteRun* slot = &vote_runs_[b * band_capacity];
      // One owner: the band's slot is where its runs are found and summed.
      VoteRun* found = owners == 1 ? slot : scratch.runs.data();
      size_t n = 0;
      const size_t r_end = std::min(rows, (b + 1) * kVoteBandRows);
      for (size_t r = b * kVoteBandRows; r < r_end; ++r) {
        n += internal::findRowVotes(depth_m_, labels, static_cast<int>(r) * stride, stride, T_W_C,
                                    row_cam, &lookup, found + n);
      }
      n = internal::sumVoteRuns(found, n, &scratch.sums);
      if (owners == 1) {
        begin[0] = 0;
        begin[1] = n;
        continue;
      }
      // Stable counting sort by owner: each owner's sums stay in the order found.
      uint32_t* owner = scratch.owner.data();
      std::fill(begin, begin + owners + 1, size_t{0});
      for (size_t i = 0; i < n; ++i) {
        owner[i] = voteOwner(found[i].block, owners);
        ++begin[owner[i] + 1];
      }
      for (size_t t = 0; t < owners; ++t) begin[t + 1] += begin[t];
      std::copy(begin, begin + owners, scratch.next.begin());
      for (size_t i = 0; i < n; ++i) slot[scratch.next[owner[i]]++] = found[i];
    }
  });
  std::atomic<size_t> added{0}, evicted{0};
  pool_->parallelFor(owners, [&](size_t t0, size_t t1, int) {
    size_t my_added = 0, my_evicted = 0;
    for (size_t t = t0; t < t1; ++t) {
      for (size_t b = 0; b < bands; ++b) {
        const VoteRun* runs = &vote_runs_[b * band_capacity];
        const size_t* begin = &owner_begin_[b * (owners + 1)];
        const size_t end = begin[t + 1];
        for (size_t i = begin[t]; i < end; ++i) {
          // A vote set is reached through its voxel's slot: both mostly miss the cache, so
          // the slot is fetched kAhead runs ahead and the set half as far.
          if (i + kAhead < end) {
            __builtin_prefetch(&runs[i + kAhead].block->vote_slot[runs[i + kAhead].voxel]);
          }
          if (i + kAhead / 2 < end) {
            const VoteRun& next = runs[i + kAhead / 2];
            const VoxelVotes* votes = next.block->votes(next.voxel);
            if (votes) __builtin_prefetch(votes, 1);
          }
          my_added += runs[i].count;
          my_evicted +=
              addVotes(runs[i].block->votesToWrite(runs[i].voxel), runs[i].label, runs[i].count);
        }
      }
    }
    added += my_added;
    evicted += my_evicted;
  });
  stats->votes_added += added;
  stats->votes_evicted += evicted;
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
  const float min_depth_m = config_.min_depth_m, max_depth_m = config_.max_depth_m;
  pool_->parallelFor(static_cast<size_t>(h), [&](size_t v0, size_t v1, int) {
    // Copies the compiler knows no store can change, so the loop vectorises.
    const float s = scale, lo = min_depth_m, hi = max_depth_m;
    const uint16_t* raw = frame.depth.data() + v0 * w;
    float* metres = depth_m_.data() + v0 * w;
    const size_t n = (v1 - v0) * w;
    for (size_t i = 0; i < n; ++i) {
      const float d = raw[i] * s;
      metres[i] = (d >= lo && d <= hi) ? d : 0.0f;
    }
  });

  // Blocks near the surface: sample the truncation band of every few pixels' rays (the
  // stride keeps neighbouring samples well under a block apart at the far range).
  const Eigen::Isometry3f T_W_Cf = T_W_C.cast<float>();
  const RowCamera row_cam = RowCamera::of(cam);
  // Clamped before the conversion: a huge focal length would overflow int.
  const int stride =
      static_cast<int>(std::clamp(map->blockSize() * cam.fx / config_.max_depth_m / 2.0, 1.0, 8.0));
  // Tens of thousands of samples hit a few hundred blocks: per-thread hash sets drop the
  // repeats, so only the distinct keys are sorted.
  const float inv_block = 1.0f / map->blockSize();
  const float step = std::min(map->blockSize() * 0.5f, trunc);
  const size_t sample_rows = static_cast<size_t>((h + stride - 1) / stride);
  key_sets_.resize(static_cast<size_t>(pool_->size()));
  // Emptied element by element: clear() would free a large table, reallocated every frame.
  for (absl::flat_hash_set<uint64_t>& set : key_sets_) set.erase(set.begin(), set.end());
  pool_->parallelFor(sample_rows, [&](size_t r0, size_t r1, int thread) {
    absl::flat_hash_set<uint64_t>& set = key_sets_[thread];
    for (int v = static_cast<int>(r0) * stride; v < static_cast<int>(r1) * stride; v += stride) {
      // Block coordinates of a ray's points by RowGrid's chain, with blocks for voxels.
      const RowGrid grid(T_W_Cf, row_cam, inv_block, v);
      auto addKey = [&](int u, float z) { set.insert(TsdfMap::key(grid.voxel(u, z))); };
      for (int u = 0; u < w; u += stride) {
        const float d = depth_m_(u, v);
        if (d <= 0.0f) continue;
        const float near = config_.space_carving ? config_.min_depth_m : std::max(d - trunc, 0.0f);
        for (float z = near; z < d + trunc; z += step) addKey(u, z);
        addKey(u, d + trunc);
      }
    }
  });
  // Sorted and unique: allocation order, and so the whole map, is the same on every run.
  keys_.clear();
  for (const absl::flat_hash_set<uint64_t>& set : key_sets_) {
    keys_.insert(keys_.end(), set.begin(), set.end());
  }
  std::sort(keys_.begin(), keys_.end());
  keys_.erase(std::unique(keys_.begin(), keys_.end()), keys_.end());
  blocks_.clear();
  const size_t before = map->numBlocks();
  for (uint64_t key : keys_) blocks_.push_back(map->allocateBlock(unpackKey(key)));
  stats.blocks_in_view = blocks_.size();
  stats.blocks_allocated = map->numBlocks() - before;

  const Eigen::Isometry3f T_C_W = T_W_Cf.inverse();
  internal::BlockUpdateParams params;
  params.depth_m = &depth_m_;
  params.color = has_color ? &frame.color : nullptr;
  params.fx = static_cast<float>(cam.fx);
  params.fy = static_cast<float>(cam.fy);
  params.cx = static_cast<float>(cam.cx);
  params.cy = static_cast<float>(cam.cy);
  params.R_C_W = T_C_W.linear();
  params.voxel_m = voxel;
  params.truncation_m = trunc;
  params.min_depth_m = config_.min_depth_m;
  params.max_weight = config_.max_weight;
  params.weight_dropoff = config_.weight_dropoff;
  params.space_carving = config_.space_carving;
  std::atomic<size_t> voxels_updated{0};
  const uint64_t stamp = map->nextChangeStamp();
  // Blocks differ a lot in how many of their voxels lie in the band: hand them out in small
  // chunks. Each block is updated by one thread from its own data only, so the result does
  // not depend on which thread takes it.
  pool_->parallelForDynamic(blocks_.size(), 8, [&](size_t begin, size_t end, int) {
    size_t updated = 0;
    for (size_t b = begin; b < end; ++b) {
      Block& block = *blocks_[b];
      const size_t n =
          internal::updateBlock(params, T_C_W * map->voxelCentre(block.index, 0, 0, 0), &block);
      if (n > 0) {
        block.updated = true;
        block.changed.store(stamp, std::memory_order_relaxed);
      }
      updated += n;
    }
    voxels_updated += updated;
  });
  stats.voxels_updated = voxels_updated;
  if (labels) voteLabels(frame, T_W_Cf, *labels, map, &stats);
  return stats;
}

}  // namespace panmap

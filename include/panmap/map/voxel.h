#pragma once

#include <algorithm>
#include <cstdint>

#include <Eigen/Core>

#include "panmap/core/image.h"

namespace panmap {

/// Bounded super-point vote slots per voxel. The paper's release keeps 3 and silently drops
/// a 4th label; panmap keeps 4 and evicts the weakest, counting every eviction.
constexpr int kVoteSlots = 4;

/// Votes a slot counts at most. Every pixel votes, so a slot fills fast at coarse voxels (a
/// 5 cm voxel at 1 m covers ~700 pixels of a 525 px focal length: 95 frames) and on long runs;
/// addVotes then halves the voxel's counts rather than saturating, keeping their ratios, which
/// are what Eq. 2's argmax and the eviction read.
constexpr uint32_t kMaxVoteCount = UINT16_MAX;

/// One super-point label and how often it was observed in a voxel: Pi_V(L_S, V). Packed to 6
/// bytes: the map is mostly voxels, and a building at 2 cm outgrew 4 GB with 8-byte slots.
struct __attribute__((packed)) LabelVote {
  int32_t label = 0;   ///< super-point label L_S (0 = empty slot)
  uint16_t count = 0;  ///< observations, at most kMaxVoteCount
};
static_assert(sizeof(LabelVote) == 6, "vote slots are packed");

/// A float kept in 2 bytes (IEEE binary16, rounded to nearest even by Eigen::half): 11
/// significant bits, so 0.03 mm at a truncation distance of 8 cm and finer towards the surface,
/// and 0.06 at a weight of 100. It converts to float and back implicitly and does no arithmetic
/// of its own, so expressions over voxels compute in float and round once, when stored.
class Float16 {
 public:
  Float16() = default;
  /// Rounds `value` to the nearest binary16.
  Float16(float value)  // NOLINT(runtime/explicit): stores like a float
      : bits_(Eigen::numext::bit_cast<uint16_t>(Eigen::half(value))) {}
  /// The stored value, exactly.
  operator float() const {  // NOLINT(runtime/explicit): reads like a float
    return static_cast<float>(Eigen::numext::bit_cast<Eigen::half>(bits_));
  }
  /// Adds in float and rounds the sum.
  Float16& operator+=(float value) { return *this = static_cast<float>(*this) + value; }
  /// The binary16 bit pattern.
  uint16_t bits() const { return bits_; }
  /// The value whose binary16 bit pattern is `bits`.
  static Float16 fromBits(uint16_t bits) {
    Float16 f;
    f.bits_ = bits;
    return f;
  }
  /// Whether a value with these bits is < 0 (negative, not -0, not NaN), without converting.
  static bool bitsBelowZero(uint16_t bits) { return bits > 0x8000u && bits <= 0xFC00u; }

 private:
  uint16_t bits_ = 0;
};
static_assert(sizeof(Float16) == 2, "two bytes");

/// A voxel of the label-TSDF's geometry: 8 bytes, eight to a cache line. Distance and weight
/// are 2-byte floats: the map is mostly voxels. Its super-point votes live beside it, in its
/// block's vote sets (Block::votes), since only one voxel in seven to ten ever holds one.
struct Voxel {
  Float16 sdf_m;      ///< truncated signed distance to the surface, metres (+ in front)
  Float16 weight;     ///< integration weight, 0 = never observed
  Rgb8 color;         ///< running mean colour
  uint8_t flags = 0;  ///< reserved
};
static_assert(sizeof(Voxel) == 8, "keep voxels lean");

/// The super-point votes of one voxel: kVoteSlots slots, 24 bytes.
struct VoxelVotes {
  LabelVote slots[kVoteSlots];

  /// The first slot, for range-for over the slots.
  LabelVote* begin() { return slots; }
  /// Past the last slot.
  LabelVote* end() { return slots + kVoteSlots; }
  /// The first slot, for range-for over the slots.
  const LabelVote* begin() const { return slots; }
  /// Past the last slot.
  const LabelVote* end() const { return slots + kVoteSlots; }
  /// Sum of the slots' counts.
  uint32_t total() const {
    uint32_t sum = 0;
    for (const LabelVote& v : slots) sum += v.count;
    return sum;
  }
};
static_assert(sizeof(VoxelVotes) == 24, "vote sets are packed");

/// Adds `n` votes for `label` (n >= 1), as n calls adding one vote each would (up to rounding
/// where counts are halved): increments its slot, or fills an empty one, or evicts the weakest
/// slot (lowest count, first on ties). A slot that would exceed kMaxVoteCount first halves
/// every count of the voxel (rounding up, so no slot empties); what still does not fit
/// saturates. Returns true when a vote was evicted.
inline bool addVotes(VoxelVotes* votes, int32_t label, uint32_t n) {
  const uint16_t capped = static_cast<uint16_t>(n < kMaxVoteCount ? n : kMaxVoteCount);
  int empty = -1, weakest = 0;
  for (int i = 0; i < kVoteSlots; ++i) {
    LabelVote& v = votes->slots[i];
    if (v.label == label && v.count > 0) {
      if (v.count > kMaxVoteCount - capped) {
        for (LabelVote& other : votes->slots) {
          other.count = static_cast<uint16_t>((other.count + 1u) / 2u);
        }
      }
      v.count = static_cast<uint16_t>(v.count > kMaxVoteCount - capped ? kMaxVoteCount
                                                                       : v.count + capped);
      return false;
    }
    if (v.count == 0) {
      if (empty < 0) empty = i;
    } else if (v.count < votes->slots[weakest].count || votes->slots[weakest].count == 0) {
      weakest = i;
    }
  }
  if (empty >= 0) {
    votes->slots[empty] = LabelVote{label, capped};
    return false;
  }
  votes->slots[weakest] = LabelVote{label, capped};
  return true;
}

/// Adds one vote for `label` (see addVotes). Returns true when a vote was evicted.
inline bool addVote(VoxelVotes* votes, int32_t label) { return addVotes(votes, label, 1); }

/// Eq. 2: the voxel's super-point label, argmax of its votes after mapping every stored label
/// through `resolve` (merged super-points pool their votes). 0 when the voxel has no vote.
/// Ties go to the smaller resolved label, so the result does not depend on slot order.
/// @param tie if given, set to whether another resolved label had the winner's count (a
///        renaming of the labels could then change the winner)
template <typename Resolve>
int32_t argmaxLabel(const VoxelVotes& votes, const Resolve& resolve, bool* tie = nullptr) {
  int32_t labels[kVoteSlots];
  uint64_t counts[kVoteSlots];
  int n = 0;
  for (const LabelVote& v : votes.slots) {
    if (v.count == 0) continue;
    const int32_t label = resolve(v.label);
    int k = 0;
    while (k < n && labels[k] != label) ++k;
    if (k == n) {
      labels[n] = label;
      counts[n++] = 0;
    }
    counts[k] += v.count;
  }
  int32_t best = 0;
  uint64_t best_count = 0;
  for (int k = 0; k < n; ++k) {
    if (counts[k] > best_count || (counts[k] == best_count && labels[k] < best)) {
      best = labels[k];
      best_count = counts[k];
    }
  }
  if (tie) {
    int winners = 0;
    for (int k = 0; k < n; ++k) winners += counts[k] == best_count ? 1 : 0;
    *tie = winners > 1;
  }
  return best;
}

/// Renames every vote of a voxel through `rename` (stored label -> new label, > 0), folding
/// votes that now name one label into its first slot, as addVotes would have counted them (a
/// sum above kMaxVoteCount first halves every count of the voxel, then saturates).
template <typename Rename>
void renameVotes(VoxelVotes* votes, const Rename& rename) {
  for (LabelVote& v : votes->slots) {
    if (v.count > 0) v.label = rename(v.label);
  }
  for (int i = 0; i < kVoteSlots; ++i) {
    LabelVote& kept = votes->slots[i];
    if (kept.count == 0) continue;
    for (int j = i + 1; j < kVoteSlots; ++j) {
      LabelVote& other = votes->slots[j];
      if (other.count == 0 || other.label != kept.label) continue;
      if (static_cast<uint32_t>(kept.count) + other.count > kMaxVoteCount) {
        for (LabelVote& any : votes->slots) {
          any.count = static_cast<uint16_t>((any.count + 1u) / 2u);
        }
      }
      kept.count = static_cast<uint16_t>(
          std::min<uint32_t>(static_cast<uint32_t>(kept.count) + other.count, kMaxVoteCount));
      other = LabelVote{};
    }
  }
}

/// argmaxLabel of a voxel's votes, 0 (and no tie) when it has none (`votes` null).
template <typename Resolve>
int32_t argmaxLabel(const VoxelVotes* votes, const Resolve& resolve, bool* tie = nullptr) {
  if (!votes) {
    if (tie) *tie = false;
    return 0;
  }
  return argmaxLabel(*votes, resolve, tie);
}

}  // namespace panmap

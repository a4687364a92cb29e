#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <vector>

#include "panmap/mapper/mapper.h"

namespace panmap {
namespace test {

/// The map file of `mapper` with its super-points numbered 1, 2, ... in the order their first
/// vote appears (blocks in allocation order, voxels in vote-set order, slots in order), then
/// those with a state and no vote by id: two maps that differ only in how their super-points
/// are numbered (a remap keeps the ids of the map it repairs) give the same bytes.
inline std::vector<uint8_t> canonicalBytes(const Mapper& mapper) {
  std::unique_ptr<Mapper> copy = Mapper::deserialize(mapper.serialize(), "a copy");
  const LabelRegistry& labels = copy->superpoints().labels();
  std::map<int32_t, int32_t> ids;
  int32_t next = 1;
  for (const auto& block : copy->map().blocks()) {
    for (const VoxelVotes& votes : block->vote_sets) {
      for (const LabelVote& v : votes.slots) {
        const int32_t label = labels.resolve(v.label);
        if (v.count > 0 && !ids.count(label)) ids[label] = next++;
      }
    }
  }
  for (const int32_t label : copy->liveSuperpoints()) {
    if (!ids.count(label)) ids[label] = next++;
  }
  copy->renumberSuperpoints(ids, next - 1);
  return copy->serialize();
}

}  // namespace test
}  // namespace panmap

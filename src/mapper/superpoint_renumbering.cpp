// Mapper::renumberSuperpoints(): super-points under new ids (a repair keeps the old ones).

#include "panmap/mapper/mapper.h"

namespace panmap {

std::vector<int32_t> Mapper::liveSuperpoints() const {
  const LabelRegistry& labels = tracker_->labels();
  std::vector<uint8_t> live(static_cast<size_t>(labels.size()) + 1, 0);
  for (const auto& entry : tracker_->states()) live[entry.first] = 1;
  for (const auto& block : map_->blocks()) {
    for (const VoxelVotes& votes : block->vote_sets) {
      for (const LabelVote& v : votes.slots) {
        if (v.count > 0) live[labels.resolve(v.label)] = 1;
      }
    }
  }
  std::vector<int32_t> out;
  for (size_t label = 1; label < live.size(); ++label) {
    if (live[label]) out.push_back(static_cast<int32_t>(label));
  }
  return out;
}

void Mapper::renumberSuperpoints(const std::map<int32_t, int32_t>& ids, int32_t size) {
  // Checked in full before anything changes: the states here, every vote by renameVotes (it
  // looks at all of them before it renames one).
  tracker_->checkSuperpointIds(ids, size);
  const LabelRegistry& labels = tracker_->labels();
  // Every stored label, merged away or not, becomes its super-point's new id.
  std::vector<int32_t> to(static_cast<size_t>(labels.size()) + 1, 0);
  for (size_t label = 1; label < to.size(); ++label) {
    const auto it = ids.find(labels.resolve(static_cast<int32_t>(label)));
    if (it != ids.end()) to[label] = it->second;
  }
  map_->renameVotes(to);
  graph_->renumberSuperpoints(*tracker_, to);
  tracker_->renumberSuperpoints(ids, size);
  mesher_->invalidateAll();
}

}  // namespace panmap

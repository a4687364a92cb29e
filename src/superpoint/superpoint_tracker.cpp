#include "panmap/superpoint/superpoint_tracker.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <tuple>

#include "panmap/core/container_memory.h"
#include "panmap/core/error.h"
#include "panmap/map/voxel.h"
#include "panmap/map/voxel_label_sampler.h"

namespace panmap {

void SuperpointConfig::check() const {
  if (!(association_min_overlap > 0.0f && association_min_overlap <= 1.0f)) {
    throw Error("superpoint association_min_overlap must be in (0, 1]");
  }
  if (!(significant_overlap > 0.0f && significant_overlap <= 1.0f)) {
    throw Error("superpoint significant_overlap must be in (0, 1]");
  }
  if (merge_threshold < 0) throw Error("superpoint merge_threshold must be >= 0");
  if (!(apart_weight >= 0.0f && apart_weight <= 1e6f)) {
    throw Error("superpoint apart_weight must be in [0, 1e6]");
  }
  if (!(unlabelled_void_share >= 0.0 && unlabelled_void_share <= 1.0)) {
    throw Error("superpoint unlabelled_void_share must be in [0, 1]");
  }
  if (sample_stride_px < 1) throw Error("superpoint sample_stride_px must be >= 1");
  if (!(instance_min_overlap >= 0.0f && instance_min_overlap <= 1.0f)) {
    throw Error("superpoint instance_min_overlap must be in [0, 1]");
  }
}

int32_t SuperpointState::semanticClass() const {
  int32_t best = 0;
  double best_count = 0.0;
  for (const auto& [cls, count] : class_counts) {
    if (count > best_count) best = cls, best_count = count;  // ties: the smaller class id
  }
  return best;
}

int32_t SuperpointState::labelledClass() const {
  int32_t best = 0;
  double best_count = 0.0;
  for (const auto& [cls, count] : class_counts) {
    if (cls > 0 && count > best_count) best = cls, best_count = count;  // ties: smaller id
  }
  return best;
}

std::pair<double, double> SuperpointState::voidFrames() const {
  double total = 0.0, none = 0.0;
  for (const auto& [cls, count] : class_counts) {
    total += count;
    if (cls <= 0) none += count;
  }
  return {none, total};
}

double SuperpointState::voidShare() const {
  const auto [none, total] = voidFrames();
  return total > 0.0 ? none / total : 0.0;
}

int32_t SuperpointState::instance() const {
  int32_t best = 0, best_count = 0;
  for (const auto& [id, count] : instance_counts) {
    if (count > best_count) best = id, best_count = count;
  }
  return best;
}

SuperpointTracker::SuperpointTracker(const SuperpointConfig& config) : config_(config) {
  config_.check();
}

const SuperpointState* SuperpointTracker::state(int32_t label) const {
  const auto it = states_.find(labels_.resolve(label));
  return it == states_.end() ? nullptr : &it->second;
}

int32_t SuperpointTracker::labelledClassOf(int32_t label) const {
  const auto it = states_.find(label);
  return it == states_.end() ? 0 : it->second.labelledClass();
}

bool SuperpointTracker::consistent(int32_t a, int32_t b) const {
  if (!config_.semantic_consistency) return true;
  // The paper's III-B also lets any super-point merge with a background one. Unlabelled
  // surface is not "any class": with it as a joker, a wall, an unlabelled chair and the floor
  // chain into one super-point, merge after merge (issue 19: one super-point held floor,
  // walls, cabinets, a bed and a curtain). Unlabelled super-points merge only among
  // themselves; labelled surfaces claim their voxels by votes when the network labels them.
  // Background counts do not dilute a labelled class either, or a chair seen mostly without a
  // mask would count as background and chain the same way.
  if (labelledClassOf(a) != labelledClassOf(b)) return false;
  // The class that decides the merge ignores void frames, the final labelling does not: a
  // merge that leaves the pooled counts unlabelled would take a labelled part's class away.
  const auto sa = states_.find(a), sb = states_.find(b);
  if (sa == states_.end() || sb == states_.end()) return true;
  const auto [none_a, total_a] = sa->second.voidFrames();
  const auto [none_b, total_b] = sb->second.voidFrames();
  const double limit = config_.unlabelled_void_share;
  const bool unlabelled_a = none_a > limit * total_a, unlabelled_b = none_b > limit * total_b;
  const bool unlabelled = none_a + none_b > limit * (total_a + total_b);
  return !unlabelled || (unlabelled_a && unlabelled_b);
}

bool SuperpointTracker::showsAsOne(const Surface& surface, int32_t a, int32_t b) const {
  if (!config_.semantic_consistency || !config_.mask_verdicts) return true;
  // A mask of another class that spills over two super-points (a floor mask over the feet of
  // two cabinets, its outline a few pixels off) says nothing about whether they are one
  // object; counted, it merged a row of three cabinets (issue 19). A surface without a mask
  // still counts: geometry alone joins them, and no verdict contradicts it (not counting it
  // left a chair's pieces small enough for an unlabelled neighbour to outvote).
  return surface.category == 0 ||
         (surface.category == labelledClassOf(a) && surface.category == labelledClassOf(b));
}

bool SuperpointTracker::splitsFrom(const Surface& s, const Surface& t) const {
  return config_.semantic_consistency && config_.mask_verdicts && s.is_thing && t.is_thing &&
         s.category > 0 && s.category == t.category && s.panoptic_segment > 0 &&
         t.panoptic_segment > 0 && s.panoptic_segment != t.panoptic_segment;
}

bool SuperpointTracker::seenApart(const std::pair<int32_t, int32_t>& key, int m) const {
  if (!config_.semantic_consistency) return false;
  const auto it = apart_.find(key);
  return it != apart_.end() && config_.apart_weight * static_cast<float>(it->second) >= m;
}

void SuperpointTracker::mergeLabels(int32_t a, int32_t b, FrameAssociation* out) {
  const int32_t ra = labels_.resolve(a), rb = labels_.resolve(b);
  if (ra == rb) return;
  const int32_t keep = labels_.merge(ra, rb);
  const int32_t gone = keep == ra ? rb : ra;
  SuperpointState& kept = states_[keep];
  const auto it = states_.find(gone);
  if (it != states_.end()) {
    for (const auto& [cls, count] : it->second.class_counts) kept.class_counts[cls] += count;
    for (const auto& [id, count] : it->second.instance_counts) kept.instance_counts[id] += count;
    states_.erase(it);
  }
  // Co-observations and apart counts of the removed super-point now belong to the survivor.
  for (auto* counts : {&co_observed_, &apart_}) {
    std::map<std::pair<int32_t, int32_t>, int> moved;
    for (auto m = counts->begin(); m != counts->end();) {
      if (m->first.first == gone || m->first.second == gone) {
        const int32_t other = m->first.first == gone ? m->first.second : m->first.first;
        if (other != keep) moved[std::minmax(keep, other)] += m->second;
        m = counts->erase(m);
      } else {
        ++m;
      }
    }
    counts->erase(std::minmax(keep, gone));
    for (const auto& [key, count] : moved) (*counts)[key] += count;
  }
  merge_log_.push_back({keep, gone, frames_});
  if (out) ++out->merges;
}

bool SuperpointTracker::rejoin(int32_t a, int32_t b, double share) {
  const int32_t ra = labels_.resolve(a), rb = labels_.resolve(b);
  if (ra == rb || !consistent(ra, rb)) return false;
  const auto key = std::minmax(ra, rb);
  const auto co = co_observed_.find(key);
  // Every frame that saw the one seen less saw the other's surface too, where they coincide.
  const auto frames = [this](int32_t label) {
    const auto it = states_.find(label);
    return it == states_.end() ? 0.0 : it->second.voidFrames().second;
  };
  const double together = std::clamp(share, 0.0, 1.0) * std::min(frames(ra), frames(rb));
  const int m =
      (co == co_observed_.end() ? 0 : co->second) + static_cast<int>(std::lround(together));
  if (seenApart(key, m)) return false;
  mergeLabels(ra, rb, nullptr);
  return true;
}

size_t SuperpointTracker::memoryBytes() const {
  size_t bytes = mapNodesBytes(states_) + mapNodesBytes(co_observed_) + mapNodesBytes(apart_) +
                 vectorBytes(merge_log_) + vectorBytes(labels_.parents());
  for (const auto& [label, state] : states_) {
    bytes += mapNodesBytes(state.class_counts) + mapNodesBytes(state.instance_counts);
  }
  return bytes;
}

size_t SuperpointTracker::forgetUnvoted(const std::vector<uint8_t>& has_votes) {
  auto voted = [&](int32_t label) {
    const int32_t root = labels_.resolve(label);
    return root > 0 && static_cast<size_t>(root) < has_votes.size() && has_votes[root] != 0;
  };
  size_t forgotten = 0;
  for (auto it = states_.begin(); it != states_.end();) {
    if (voted(it->first)) {
      ++it;
    } else {
      it = states_.erase(it);
      ++forgotten;
    }
  }
  for (auto* counts : {&co_observed_, &apart_}) {
    for (auto it = counts->begin(); it != counts->end();) {
      it = voted(it->first.first) && voted(it->first.second) ? std::next(it) : counts->erase(it);
    }
  }
  return forgotten;
}

FrameAssociation SuperpointTracker::associate(const FrameSegmentation& segmentation,
                                              const RgbdFrame& frame,
                                              const Eigen::Isometry3d& T_W_C, const TsdfMap& map) {
  FrameAssociation out;
  associate(segmentation, frame, T_W_C, map, &out);
  return out;
}

void SuperpointTracker::associate(const FrameSegmentation& segmentation, const RgbdFrame& frame,
                                  const Eigen::Isometry3d& T_W_C, const TsdfMap& map,
                                  FrameAssociation* result) {
  const auto& surfaces = segmentation.surface_list;
  const size_t n = surfaces.size();
  const int w = frame.camera.width, h = frame.camera.height;
  if (segmentation.surfaces.width() != w || segmentation.surfaces.height() != h) {
    throw Error("superpoints: segmentation size differs from the frame's");
  }
  ++frames_;
  FrameAssociation& out = *result;
  out.surface_labels.assign(n, 0);
  out.surface_instances.assign(n, 0);
  out.new_labels = 0;
  out.merges = 0;

  // Pi_s(L_S, s_i): votes of the voxels the surface's points fall in (Eq. 2 per voxel).
  std::vector<int> samples(n, 0);
  std::vector<std::map<int32_t, int>> overlap(n);
  const float scale = static_cast<float>(frame.depth_scale_m);
  VoxelLabelSampler sampler(map, T_W_C.cast<float>(), frame.camera,
                            [this](int32_t l) { return labels_.resolve(l); });
  const int stride = config_.sample_stride_px;
  // Neighbouring samples mostly see the same surface and super-point: count runs, and touch
  // the per-surface maps once per run instead of once per sample.
  int run_sid = 0, run_count = 0;
  int32_t run_label = 0;
  auto flush = [&] {
    if (run_count > 0) overlap[run_sid - 1][run_label] += run_count;
    run_count = 0;
  };
  for (int v = 0; v < h; v += stride) {
    row_samples_.clear();
    row_surfaces_.clear();
    for (int u = 0; u < w; u += stride) {
      const int32_t sid = segmentation.surfaces(u, v);
      if (sid <= 0 || static_cast<size_t>(sid) > n) continue;
      const float d = frame.depth(u, v) * scale;
      if (d <= 0.0f) continue;
      ++samples[sid - 1];
      row_samples_.push_back({u, d});
      row_surfaces_.push_back(sid);
    }
    row_labels_.resize(row_samples_.size());
    // Nothing changes the map or the labels during this loop, as the sampler needs.
    sampler.labelRow(v, row_samples_, row_labels_.data(), nullptr);
    for (size_t k = 0; k < row_samples_.size(); ++k) {
      const int32_t sid = row_surfaces_[k], label = row_labels_[k];
      if (label <= 0) continue;
      if (run_count == 0 || sid != run_sid || label != run_label) {
        flush();
        run_sid = sid;
        run_label = label;
      }
      ++run_count;
    }
  }
  flush();

  // Association: best pairs first, one surface per super-point per frame (as Voxblox++).
  std::vector<std::tuple<int, size_t, int32_t>> pairs;  // (-count, surface, label)
  for (size_t s = 0; s < n; ++s) {
    for (const auto& [label, count] : overlap[s]) pairs.emplace_back(-count, s, label);
  }
  std::sort(pairs.begin(), pairs.end());
  std::map<int32_t, size_t> holder;  // super-point -> the surface that took it
  std::vector<int32_t> lost(n, 0);   // the first super-point a surface lost to another
  for (const auto& [neg_count, s, label] : pairs) {
    if (out.surface_labels[s] != 0) continue;
    if (-neg_count < config_.association_min_overlap * samples[s]) continue;
    const auto it = holder.find(label);
    if (it != holder.end()) {
      if (lost[s] == 0 && splitsFrom(surfaces[s], surfaces[it->second])) lost[s] = label;
      continue;
    }
    out.surface_labels[s] = label;
    holder[label] = s;
  }
  if (config_.semantic_consistency && config_.join_mask_pieces) {
    joinMaskPieces(surfaces, pairs, samples, lost, holder, &out);
  }
  if (config_.semantic_consistency && config_.revisit_votes) {
    revisitVotes(segmentation, frame, T_W_C, map, samples, lost, &holder, &out);
  }
  out.splits.clear();
  for (size_t s = 0; s < n; ++s) {
    if (out.surface_labels[s] == 0) {
      out.surface_labels[s] = labels_.create();
      states_[out.surface_labels[s]];
      ++out.new_labels;
      // The network shows what the super-point covers as two objects here. Without the split
      // the new super-point's votes never outweigh the old one's in those voxels (they were
      // labelled under a mask that merged both objects, 15 frames of it), and every later
      // frame starts yet another super-point there: one super-point kept a row of cabinets.
      if (lost[s] != 0) {
        int seen = 0;  // samples of the super-point in the frame, over all surfaces
        for (size_t t = 0; t < n; ++t) {
          const auto it = overlap[t].find(lost[s]);
          if (it != overlap[t].end()) seen += it->second;
        }
        out.splits.push_back({surfaces[s].id, lost[s], out.surface_labels[s],
                              static_cast<double>(overlap[s].at(lost[s])) / seen});
      }
    }
    // Semantic frame count (background surfaces count for class 0). A frame mapped without a
    // segmentation is no evidence either way: counted as class 0, a network that masks one
    // frame in six made every surface "unlabelled in 83 % of its frames", and the optimiser
    // left the map without classes (optimiser.max_void_share).
    if (segmentation.panoptic) {
      states_[out.surface_labels[s]].class_counts[surfaces[s].category] += 1.0;
    }
  }

  // The super-points significantly overlapping each surface: L_N(s_i).
  std::vector<std::vector<int32_t>> significant(n);
  for (size_t s = 0; s < n; ++s) {
    for (const auto& [label, count] : overlap[s]) {
      if (count >= config_.significant_overlap * samples[s]) significant[s].push_back(label);
    }
  }
  // Super-points the frame shows as two objects: significant in surfaces of two different
  // thing masks of one class. Counted once per frame and pair, before this frame's merges.
  std::set<std::pair<int32_t, int32_t>> apart;
  for (size_t s1 = 0; s1 < n; ++s1) {
    const Surface& a = surfaces[s1];
    if (!a.is_thing || a.category <= 0 || a.panoptic_segment <= 0) continue;
    for (size_t s2 = s1 + 1; s2 < n; ++s2) {
      const Surface& b = surfaces[s2];
      if (!b.is_thing || b.category != a.category || b.panoptic_segment == a.panoptic_segment ||
          b.panoptic_segment <= 0) {
        continue;
      }
      for (int32_t x : significant[s1]) {
        for (int32_t y : significant[s2]) {
          if (x != y) apart.insert(std::minmax(x, y));
        }
      }
    }
  }
  for (const auto& key : apart) ++apart_[key];
  // Co-observation M (Eq. 3) of the super-points significantly overlapping each surface, and
  // merging of spatially connected, semantically consistent ones that the network saw as one
  // more than apart_weight times as often as it saw them as two objects (two touching cabinets
  // of a row, one mask over both now and then).
  // With semantic consistency both count once per frame and pair: the network's verdict is
  // per frame, and two surfaces of one mask (a plane cut by a depth edge) are not two
  // verdicts. Spatial-only merging (Voxblox++) counts every surface, as it does.
  std::set<std::pair<int32_t, int32_t>> counted;
  for (size_t s = 0; s < n; ++s) {
    for (size_t i = 0; i < significant[s].size(); ++i) {
      for (size_t j = i + 1; j < significant[s].size(); ++j) {
        const int32_t a = labels_.resolve(significant[s][i]);
        const int32_t b = labels_.resolve(significant[s][j]);
        if (a == b) continue;
        if (!showsAsOne(surfaces[s], a, b)) continue;
        const auto key = std::minmax(a, b);
        if (config_.semantic_consistency && !counted.insert(key).second) continue;
        int& m = co_observed_[key];
        ++m;
        if (m > config_.merge_threshold && consistent(a, b) && !seenApart(key, m)) {
          mergeLabels(a, b, &out);
        }
      }
    }
  }
  for (int32_t& label : out.surface_labels) label = labels_.resolve(label);

  associateInstances(segmentation, &out);

  if (out.pixel_labels.width() != w || out.pixel_labels.height() != h) {
    out.pixel_labels = LabelImage(w, h);
  }
  // Every pixel is written, so the reused image needs no clearing.
  const int32_t* sids = segmentation.surfaces.data();
  int32_t* pixel_labels = out.pixel_labels.data();
  for (size_t i = 0; i < out.pixel_labels.size(); ++i) {
    const int32_t sid = sids[i];
    pixel_labels[i] = sid > 0 && static_cast<size_t>(sid) <= n ? out.surface_labels[sid - 1] : 0;
  }
}

void SuperpointTracker::joinMaskPieces(const std::vector<Surface>& surfaces,
                                       const std::vector<std::tuple<int, size_t, int32_t>>& pairs,
                                       const std::vector<int>& samples,
                                       const std::vector<int32_t>& lost,
                                       const std::map<int32_t, size_t>& holder,
                                       FrameAssociation* out) const {
  // Best pairs first, as the association: a surface joins the largest super-point it can.
  for (const auto& [neg_count, s, label] : pairs) {
    if (out->surface_labels[s] != 0 || lost[s] != 0) continue;
    if (-neg_count < config_.association_min_overlap * samples[s]) continue;
    const auto it = holder.find(label);
    if (it == holder.end()) continue;
    const Surface& piece = surfaces[s];
    const Surface& taker = surfaces[it->second];
    if (piece.panoptic_segment > 0 && piece.panoptic_segment == taker.panoptic_segment &&
        piece.category > 0 && piece.category == labelledClassOf(label)) {
      out->surface_labels[s] = label;
    }
  }
}

void SuperpointTracker::revisitVotes(const FrameSegmentation& segmentation, const RgbdFrame& frame,
                                     const Eigen::Isometry3d& T_W_C, const TsdfMap& map,
                                     const std::vector<int>& samples,
                                     const std::vector<int32_t>& lost,
                                     std::map<int32_t, size_t>* holder, FrameAssociation* out) {
  const auto& surfaces = segmentation.surface_list;
  const size_t n = surfaces.size();
  // Labelled surfaces about to start a super-point; a split's new one is wanted as it is.
  std::vector<uint8_t> looking(n + 1, 0);
  bool any = false;
  for (size_t s = 0; s < n; ++s) {
    if (out->surface_labels[s] == 0 && lost[s] == 0 && surfaces[s].category > 0) {
      looking[s + 1] = 1;
      any = true;
    }
  }
  if (!any) return;
  // Per looking surface: its samples whose voxel holds any vote for each super-point (a
  // super-point counts once per sample however many slots it has there).
  std::vector<std::map<int32_t, int>> held(n);
  VoxelLabelSampler sampler(map, T_W_C.cast<float>(), frame.camera,
                            [this](int32_t l) { return labels_.resolve(l); });
  const float scale = static_cast<float>(frame.depth_scale_m);
  const int stride = config_.sample_stride_px;
  for (int v = 0; v < frame.camera.height; v += stride) {
    for (int u = 0; u < frame.camera.width; u += stride) {
      const int32_t sid = segmentation.surfaces(u, v);
      if (sid <= 0 || static_cast<size_t>(sid) > n || !looking[sid]) continue;
      const float d = frame.depth(u, v) * scale;
      if (!(d > 0.0f)) continue;
      const VoxelVotes* votes = sampler.votes(u, v, d);
      if (!votes) continue;
      int32_t seen[kVoteSlots];
      int k = 0;
      for (const LabelVote& vote : votes->slots) {
        if (vote.count == 0) continue;
        const int32_t root = labels_.resolve(vote.label);
        if (std::find(seen, seen + k, root) != seen + k) continue;
        seen[k++] = root;
        ++held[sid - 1][root];
      }
    }
  }
  std::vector<std::tuple<int, size_t, int32_t>> pairs;  // (-count, surface, label)
  for (size_t s = 0; s < n; ++s) {
    for (const auto& [label, count] : held[s]) {
      if (count >= config_.association_min_overlap * samples[s] &&
          labelledClassOf(label) == surfaces[s].category) {
        pairs.emplace_back(-count, s, label);
      }
    }
  }
  std::sort(pairs.begin(), pairs.end());
  for (const auto& [neg_count, s, label] : pairs) {
    if (out->surface_labels[s] != 0 || holder->count(label)) continue;
    out->surface_labels[s] = label;
    (*holder)[label] = s;
  }
}

void SuperpointTracker::associateInstances(const FrameSegmentation& segmentation,
                                           FrameAssociation* out) {
  const auto& surfaces = segmentation.surface_list;
  // Thing surfaces grouped by their 2D instance o.
  std::map<int32_t, std::vector<size_t>> by_mask;
  for (size_t s = 0; s < surfaces.size(); ++s) {
    if (surfaces[s].is_thing && surfaces[s].panoptic_segment > 0 && surfaces[s].category > 0) {
      by_mask[surfaces[s].panoptic_segment].push_back(s);
    }
  }
  // Overlap of each 2D instance with the global instances of its super-points.
  std::vector<std::tuple<int, int32_t, int32_t>> pairs;  // (-pixels, mask, instance)
  std::map<int32_t, int> mask_pixels;
  for (const auto& [mask, members] : by_mask) {
    std::map<int32_t, int> overlap;
    for (size_t s : members) {
      mask_pixels[mask] += surfaces[s].num_pixels;
      const auto it = states_.find(out->surface_labels[s]);
      const int32_t instance = it == states_.end() ? 0 : it->second.instance();
      if (instance > 0) overlap[instance] += surfaces[s].num_pixels;
    }
    for (const auto& [instance, pixels] : overlap) pairs.emplace_back(-pixels, mask, instance);
  }
  std::sort(pairs.begin(), pairs.end());
  std::map<int32_t, int32_t> assigned;  // mask -> global instance
  std::map<int32_t, bool> used;
  for (const auto& [neg_pixels, mask, instance] : pairs) {
    if (assigned.count(mask) || used[instance]) continue;
    if (-neg_pixels < config_.instance_min_overlap * mask_pixels[mask]) continue;
    assigned[mask] = instance;
    used[instance] = true;
  }
  for (const auto& [mask, members] : by_mask) {
    if (!assigned.count(mask)) assigned[mask] = next_instance_++;
    for (size_t s : members) {
      states_[out->surface_labels[s]].instance_counts[assigned[mask]] += 1;
      out->surface_instances[s] = assigned[mask];
    }
  }
}

void SuperpointTracker::renumberInstances(const std::map<int32_t, int32_t>& ids,
                                          int32_t next_instance) {
  const auto renamed = [&ids](int32_t id) {
    const auto it = ids.find(id);
    return it == ids.end() ? id : it->second;
  };
  std::set<int32_t> taken;
  for (int32_t id = 1; id < next_instance_; ++id) {
    const int32_t to = renamed(id);
    if (to <= 0 || to >= next_instance) {
      throw Error("renumberInstances: instance " + std::to_string(id) + " would become " +
                  std::to_string(to) + ", outside 1.." + std::to_string(next_instance - 1));
    }
    if (!taken.insert(to).second) {
      throw Error("renumberInstances: two instances would become " + std::to_string(to));
    }
  }
  for (auto& [label, state] : states_) {
    std::map<int32_t, int> counts;
    for (const auto& [id, count] : state.instance_counts) counts[renamed(id)] += count;
    state.instance_counts = std::move(counts);
  }
  next_instance_ = next_instance;
}

void SuperpointTracker::checkSuperpointIds(const std::map<int32_t, int32_t>& ids,
                                           int32_t size) const {
  std::set<int32_t> taken;
  for (const auto& [from, to] : ids) {
    if (!labels_.isRoot(from)) {
      throw Error("renumberSuperpoints: label " + std::to_string(from) + " is not a super-point");
    }
    if (to <= 0 || to > size) {
      throw Error("renumberSuperpoints: super-point " + std::to_string(from) + " would become " +
                  std::to_string(to) + ", outside 1.." + std::to_string(size));
    }
    if (!taken.insert(to).second) {
      throw Error("renumberSuperpoints: two super-points would become " + std::to_string(to));
    }
  }
  for (const auto& entry : states_) {
    if (!ids.count(entry.first)) {
      throw Error("renumberSuperpoints: no new id for super-point " + std::to_string(entry.first));
    }
  }
}

void SuperpointTracker::renumberSuperpoints(const std::map<int32_t, int32_t>& ids, int32_t size) {
  checkSuperpointIds(ids, size);
  std::vector<int32_t> roots;
  for (const auto& entry : ids) roots.push_back(entry.second);
  // Every key below is a live super-point's; an unknown one is dropped rather than kept under
  // an id that may now name another.
  const auto renamed = [&](int32_t label) {
    const auto it = ids.find(labels_.resolve(label));
    return it == ids.end() ? 0 : it->second;
  };
  const auto renamePairs = [&](const std::map<std::pair<int32_t, int32_t>, int>& in) {
    std::map<std::pair<int32_t, int32_t>, int> out;
    for (const auto& [pair, count] : in) {
      const int32_t a = renamed(pair.first), b = renamed(pair.second);
      if (a > 0 && b > 0 && a != b) out[{std::min(a, b), std::max(a, b)}] += count;
    }
    return out;
  };
  std::map<int32_t, SuperpointState> states;
  for (auto& [label, state] : states_) states[ids.at(label)] = std::move(state);
  co_observed_ = renamePairs(co_observed_);
  apart_ = renamePairs(apart_);
  for (SuperpointMerge& merge : merge_log_) {
    merge.kept = renamed(merge.kept);
    merge.removed = 0;
  }
  states_ = std::move(states);
  labels_.renumber(roots, size);
}

SuperpointTracker::Snapshot SuperpointTracker::snapshot() const {
  Snapshot s;
  s.parents = labels_.parents();
  s.states = states_;
  s.co_observed = co_observed_;
  s.apart = apart_;
  s.merges = merge_log_;
  s.next_instance = next_instance_;
  s.frames = frames_;
  return s;
}

void SuperpointTracker::restore(const Snapshot& snapshot) {
  labels_.restore(snapshot.parents);
  for (const auto& [label, state] : snapshot.states) {
    if (!labels_.isRoot(label)) throw Error("super-point state for a non-root label");
  }
  states_ = snapshot.states;
  co_observed_ = snapshot.co_observed;
  apart_ = snapshot.apart;
  merge_log_ = snapshot.merges;
  next_instance_ = snapshot.next_instance;
  frames_ = snapshot.frames;
}

}  // namespace panmap

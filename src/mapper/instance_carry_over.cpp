// Instance ids kept across a repair that maps the frames again (docs/LOOP_CLOSURE.md).
#include "panmap/mapper/instance_carry_over.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <tuple>

#include <absl/container/flat_hash_map.h>

#include "panmap/core/error.h"
#include "panmap/map/voxel_label_sampler.h"

namespace panmap {

namespace {

// The super-point (root label) and frame-count instance of the voxel each sample of a frame
// sees from T_W_C (0: none).
void idsSeen(const InstanceSampleFrame& frame, const Eigen::Isometry3d& T_W_C, const TsdfMap& map,
             const SuperpointTracker& tracker, std::vector<int32_t>* superpoints,
             std::vector<int32_t>* instances) {
  auto resolve = [&tracker](int32_t label) { return tracker.labels().resolve(label); };
  VoxelLabelSampler<decltype(resolve)> sampler(map, T_W_C.cast<float>(), frame.camera, resolve);
  superpoints->assign(frame.samples.size(), 0);
  instances->assign(frame.samples.size(), 0);
  for (size_t k = 0; k < frame.samples.size(); ++k) {
    const InstanceSampleFrame::Sample& s = frame.samples[k];
    const int32_t label = sampler.label(s.u, s.v, s.d_m);
    if (label <= 0) continue;
    (*superpoints)[k] = label;
    const SuperpointState* state = tracker.state(label);
    (*instances)[k] = state ? state->instance() : 0;
  }
}

}  // namespace

InstanceSampleFrame sampleFrame(const RgbdFrame& frame, size_t index,
                                const Eigen::Isometry3d& T_W_C, int step_px,
                                const DepthCalibration* calibration) {
  if (step_px < 1) throw Error("sampleFrame: step_px must be at least 1");
  InstanceSampleFrame out;
  out.index = index;
  out.T_W_C = T_W_C;
  out.camera = frame.camera;
  const int width = std::min(frame.depth.width(), 65536);
  const int height = std::min(frame.depth.height(), 65536);
  // The middle of each grid cell, so a coarse grid stays clear of the image border.
  for (int v = step_px / 2; v < height; v += step_px) {
    for (int u = step_px / 2; u < width; u += step_px) {
      uint16_t reading = frame.depth(u, v);
      if (calibration && !calibration->empty()) {
        reading = calibration->correctedReading(u, v, reading, frame.depth_scale_m);
      }
      const float d_m = static_cast<float>(reading * frame.depth_scale_m);
      if (!(d_m > 0.0f) || !std::isfinite(d_m)) continue;
      out.samples.push_back({static_cast<uint16_t>(u), static_cast<uint16_t>(v), d_m});
    }
  }
  return out;
}

CarryOverlap countCarryOverlap(const std::vector<InstanceSampleFrame>& frames,
                               const std::vector<StampedPose>& trajectory_old,
                               const TsdfMap& old_map, const SuperpointTracker& old_tracker,
                               const TsdfMap& new_map, const SuperpointTracker& new_tracker,
                               ThreadPool* pool) {
  for (const InstanceSampleFrame& frame : frames) {
    if (frame.index >= trajectory_old.size()) {
      throw Error("countCarryOverlap: sampled frame " + std::to_string(frame.index) +
                  " of a trajectory of " + std::to_string(trajectory_old.size()));
    }
  }
  // resolve() only reads once flattened, so the threads may share the registries.
  old_tracker.labels().flatten();
  new_tracker.labels().flatten();
  const int threads = pool ? pool->size() : 1;
  // Counted in hash tables (a sample is one increment), ordered once at the end.
  using Counts = absl::flat_hash_map<uint64_t, int>;
  const auto key = [](int32_t a, int32_t b) {
    return (static_cast<uint64_t>(static_cast<uint32_t>(a)) << 32) | static_cast<uint32_t>(b);
  };
  std::vector<Counts> instances(threads), superpoints(threads);
  const auto count = [&](size_t begin, size_t end, int thread) {
    std::vector<int32_t> old_sp, old_inst, new_sp, new_inst;
    for (size_t f = begin; f < end; ++f) {
      const InstanceSampleFrame& frame = frames[f];
      idsSeen(frame, trajectory_old[frame.index].T_W_C, old_map, old_tracker, &old_sp, &old_inst);
      idsSeen(frame, frame.T_W_C, new_map, new_tracker, &new_sp, &new_inst);
      for (size_t k = 0; k < old_sp.size(); ++k) {
        if (old_sp[k] > 0 && new_sp[k] > 0) ++superpoints[thread][key(new_sp[k], old_sp[k])];
        if (old_inst[k] > 0 && new_inst[k] > 0) ++instances[thread][key(new_inst[k], old_inst[k])];
      }
    }
  };
  if (pool) {
    pool->parallelForDynamic(frames.size(), 8, count);
  } else {
    count(0, frames.size(), 0);
  }
  const auto ordered = [](const std::vector<Counts>& parts) {
    IdOverlap out;
    for (const Counts& part : parts) {
      for (const auto& [k, samples] : part) {
        out[{static_cast<int32_t>(k >> 32), static_cast<int32_t>(k & 0xFFFFFFFFu)}] += samples;
      }
    }
    return out;
  };
  CarryOverlap overlap;
  overlap.instances = ordered(instances);
  overlap.superpoints = ordered(superpoints);
  return overlap;
}

std::map<int32_t, int32_t> carriedIds(const IdOverlap& overlap, const std::vector<int32_t>& new_ids,
                                      int32_t old_next, int32_t* next) {
  constexpr int kMinSamples = 3;
  constexpr int kMinShareOfNew = 5;  // the pair holds at least 1/5 of the new one's samples
  const std::set<int32_t> wanted(new_ids.begin(), new_ids.end());
  std::map<int32_t, int> new_total;
  std::vector<std::tuple<int, int32_t, int32_t>> pairs;  // (-samples, new, old)
  for (const auto& [ids, samples] : overlap) {
    new_total[ids.first] += samples;
    pairs.emplace_back(-samples, ids.first, ids.second);
  }
  std::sort(pairs.begin(), pairs.end());
  std::map<int32_t, int32_t> out;
  std::set<int32_t> old_taken;
  for (const auto& [neg_samples, new_id, old_id] : pairs) {
    const int samples = -neg_samples;
    if (samples < kMinSamples || samples * kMinShareOfNew < new_total[new_id]) continue;
    if (!wanted.count(new_id) || old_id <= 0 || old_id >= old_next) {
      continue;  // not an id of the maps the ids came from
    }
    if (out.count(new_id) || old_taken.count(old_id)) continue;
    out[new_id] = old_id;
    old_taken.insert(old_id);
  }
  int32_t free_id = std::max<int32_t>(old_next, 1);
  for (const int32_t id : wanted) {
    if (!out.count(id)) out[id] = free_id++;
  }
  if (next) *next = free_id;
  return out;
}

std::map<int32_t, int32_t> carriedInstanceIds(const InstanceOverlap& overlap,
                                              int32_t new_next_instance, int32_t old_next_instance,
                                              int32_t* next_instance) {
  std::vector<int32_t> new_ids;
  for (int32_t id = 1; id < new_next_instance; ++id) new_ids.push_back(id);
  return carriedIds(overlap, new_ids, old_next_instance, next_instance);
}

}  // namespace panmap

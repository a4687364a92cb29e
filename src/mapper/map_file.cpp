// Map snapshots: "PANMAP\0\0", format version, payload size, payload, CRC-32 of the payload.
// The payload holds the config field by field, the counters, every block's voxels and the
// super-point state, so that load-then-continue equals an uninterrupted run.
#include <zlib.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

#include "panmap/core/binary_io.h"
#include "panmap/io/atomic_file.h"
#include "panmap/io/image_codec.h"
#include "panmap/mapper/mapper.h"

namespace panmap {
namespace {

constexpr char kMagic[8] = {'P', 'A', 'N', 'M', 'A', 'P', '\0', '\0'};
// 2: occupancy cells, pose refinement state and the trajectory.
// 3: the pose refinement's weak_direction_damping.
// 4: III-B apart counts.
// 5: the pose correction model, the drift filter's config and state.
// 6: graph edge pruning (prune_edges, edge_min_share, surface_band_voxels); version 5 files
//    still load, with pruning off as they were built.
// 7: III-B's mask_verdicts; version 5 and 6 files load with it off, as they were built.
// 8: III-B's apart_weight; older files load with 1, the rule they were built with.
// 9: III-B's unlabelled_void_share; older files load with 1 (off), as they were built.
// 10: 36-byte voxels (6-byte vote slots, counts at most 65,535); older files' 44-byte voxels
//     are converted on loading (a voxel's counts scaled together where one exceeds that).
// 11: 32-byte voxels (distance and weight as 2-byte floats); older files' voxels are rounded
//     to them on loading.
// 12: the depth calibration (MapperConfig::depth_calibration); older files load without one,
//     as they were built.
// 13: 8-byte voxels, then the votes of the voxels that hold any (Block::vote_sets): their
//     count, then each one's index in the block and four 6-byte slots, by index. Older files'
//     32-byte voxels are split on loading.
// 14: fusion's mask edge fill (MaskEdgeFillConfig); older files load with it off, as they were
//     built.
// 15: the graph's outline band (GraphConfig::pair_interior_px); older files load with 0.
// 16: the depth check of auto tracking (MapperConfig::depth_check) and its state, and the
//     counts of poses kept as given and corrected; older files load with the check off
//     (frames 0), as they were built.
// 17: fusion's mask-only surfaces (SurfaceFusionConfig::mask_only_surfaces and its depth step);
//     older files load with them off, as they were built.
// 18: III-B's join_mask_pieces and revisit_votes; older files load with both off, as they were
//     built.
constexpr uint32_t kVersion = 18;

// Bytes of one voxel's votes in a file: four slots of a 4-byte label and a 2-byte count.
constexpr size_t kVoteSetBytes = kVoteSlots * 6;
static_assert(sizeof(VoxelVotes) == kVoteSetBytes, "vote sets are stored as they are in memory");

// Gives voxel i of `block` the votes `votes` unless every count is 0.
void keepVotes(const VoxelVotes& votes, int i, Block* block) {
  if (votes.total() > 0) *block->votesToWrite(i) = votes;
}

// Reads a block's voxels as files before version 11 stored them: a 4-byte float distance and
// weight, colour, flags, then four vote slots of a 4-byte label and a count of 4 bytes (before
// version 10) or 2 (version 10).
void getVoxelsBefore11(BinaryReader* r, uint32_t version, Block* block) {
  const size_t count_bytes = version >= 10 ? 2 : 4;
  const size_t slot_bytes = 4 + count_bytes;
  for (int i = 0; i < kBlockVoxels; ++i) {
    Voxel& v = block->voxels[i];
    VoxelVotes votes;
    uint8_t bytes[12 + kVoteSlots * 8];
    r->getBytes(bytes, 12 + kVoteSlots * slot_bytes);
    float sdf_m, weight;
    std::memcpy(&sdf_m, bytes, 4);
    std::memcpy(&weight, bytes + 4, 4);
    v.sdf_m = sdf_m;
    v.weight = weight;
    v.color = Rgb8{bytes[8], bytes[9], bytes[10]};
    v.flags = bytes[11];
    uint32_t counts[kVoteSlots], most = 0;
    for (int k = 0; k < kVoteSlots; ++k) {
      const uint8_t* slot = bytes + 12 + slot_bytes * k;
      std::memcpy(&votes.slots[k].label, slot, 4);
      uint16_t short_count = 0;
      if (count_bytes == 2) {
        std::memcpy(&short_count, slot + 4, 2);
        counts[k] = short_count;
      } else {
        std::memcpy(&counts[k], slot + 4, 4);
      }
      most = std::max(most, counts[k]);
    }
    // Counts beyond today's slots are scaled down together, as addVotes halves them: the
    // ratios survive and no slot empties.
    for (int k = 0; k < kVoteSlots; ++k) {
      const uint64_t c = counts[k];
      votes.slots[k].count =
          static_cast<uint16_t>(most <= kMaxVoteCount ? c : (c * kMaxVoteCount + most - 1) / most);
    }
    keepVotes(votes, i, block);
  }
}

// Reads a block's voxels as versions 11 and 12 stored them: each voxel's 8 bytes of geometry
// followed by its four vote slots.
void getVoxels11(BinaryReader* r, Block* block) {
  for (int i = 0; i < kBlockVoxels; ++i) {
    r->getBytes(&block->voxels[i], sizeof(Voxel));
    VoxelVotes votes;
    r->getBytes(&votes, sizeof(votes));
    keepVotes(votes, i, block);
  }
}

// Writes a block's voxels and votes as version 13 stores them.
void putVoxels(BinaryWriter* w, const Block& block) {
  w->putBytes(block.voxels, sizeof(block.voxels));
  w->put<uint16_t>(static_cast<uint16_t>(block.vote_sets.size()));
  for (int i = 0; i < kBlockVoxels; ++i) {
    const VoxelVotes* votes = block.votes(i);
    if (!votes) continue;
    w->put<uint16_t>(static_cast<uint16_t>(i));
    w->putBytes(votes, sizeof(*votes));
  }
}

// Reads what putVoxels wrote; throws Error naming `path` on an impossible vote list.
void getVoxels(BinaryReader* r, const std::string& path, Block* block) {
  r->getBytes(block->voxels, sizeof(block->voxels));
  const uint16_t n = r->get<uint16_t>();
  if (n > kBlockVoxels) throw Error(path + ": " + std::to_string(n) + " voted voxels in a block");
  block->vote_sets.reserve(n);
  int previous = -1;
  for (uint16_t k = 0; k < n; ++k) {
    const int i = r->get<uint16_t>();
    if (i <= previous || i >= kBlockVoxels) {
      throw Error(path + ": voted voxel " + std::to_string(i) + " out of order in a block");
    }
    previous = i;
    VoxelVotes votes;
    r->getBytes(&votes, sizeof(votes));
    keepVotes(votes, i, block);
  }
}
// Bytes of a voxel in files of `version`.
// (Version 13: the geometry alone; its votes follow, two bytes at least.)
size_t voxelBytes(uint32_t version) {
  if (version >= 13) return sizeof(Voxel);
  return version >= 11 ? sizeof(Voxel) + kVoteSetBytes : 12 + kVoteSlots * (version >= 10 ? 6 : 8);
}
constexpr uint32_t kOldestVersion = 5;
// Magic, version, payload size.
constexpr size_t kHeaderBytes = sizeof(kMagic) + sizeof(uint32_t) + sizeof(uint64_t);

// Forwards a stream and keeps the CRC-32 of what follows the header (the payload).
class ChecksummingSink : public ByteSink {
 public:
  explicit ChecksummingSink(ByteSink* out) : out_(out) {}
  void append(const uint8_t* data, size_t size) override {
    const size_t skip = seen_ < kHeaderBytes ? std::min(size, kHeaderBytes - seen_) : 0;
    crc_ = crc32(crc_, data + skip, static_cast<uInt>(size - skip));
    seen_ += size;
    out_->append(data, size);
  }
  // Only the header's size field is overwritten, outside the checksummed payload.
  void overwrite(uint64_t offset, const uint8_t* data, size_t size) override {
    if (offset + size > kHeaderBytes) throw Error("map file: payload overwritten");
    out_->overwrite(offset, data, size);
  }
  uint32_t crc() const { return static_cast<uint32_t>(crc_); }

 private:
  ByteSink* out_;
  uLong crc_ = crc32(0L, Z_NULL, 0);
  size_t seen_ = 0;
};

void putConfig(BinaryWriter* w, const MapperConfig& c) {
  w->put(c.map.voxel_size_m);
  w->put(c.integrator.truncation_voxels);
  w->put(c.integrator.max_weight);
  w->put(c.integrator.min_depth_m);
  w->put(c.integrator.max_depth_m);
  w->put<uint8_t>(c.integrator.weight_dropoff);
  w->put<uint8_t>(c.integrator.space_carving);
  w->put<int32_t>(c.integrator.vote_stride_px);
  w->put<int32_t>(c.depth_segmentation.normals_window_px);
  w->put<int32_t>(c.depth_segmentation.min_convexity_window_px);
  w->put(c.depth_segmentation.min_convexity_threshold);
  w->put(c.depth_segmentation.depth_discontinuity_ratio);
  w->put<int32_t>(c.depth_segmentation.min_segment_px);
  w->put(c.depth_segmentation.max_depth_m);
  w->put<int32_t>(c.fusion.min_surface_px);
  w->put(c.fusion.stuff_confidence);
  w->put<uint8_t>(c.fusion.geometry_only);
  w->put(c.superpoints.association_min_overlap);
  w->put(c.superpoints.significant_overlap);
  w->put<int32_t>(c.superpoints.merge_threshold);
  w->put<uint8_t>(c.superpoints.semantic_consistency);
  w->put<int32_t>(c.superpoints.sample_stride_px);
  w->put(c.superpoints.instance_min_overlap);
  w->put(c.graph.spatial_scale_m);
  w->put<int32_t>(c.graph.sample_stride_px);
  w->put<uint8_t>(c.graph.prune_edges);
  w->put(c.graph.edge_min_share);
  w->put(c.graph.surface_band_voxels);
  w->put<uint8_t>(c.superpoints.mask_verdicts);
  w->put(c.superpoints.apart_weight);
  w->put(c.superpoints.unlabelled_void_share);
  w->put<uint8_t>(c.occupancy_enabled);
  const OccupancyMap::Config& o = c.occupancy;
  for (double v : {o.resolution_m, o.min_depth_m, o.max_depth_m, o.prob_hit, o.prob_miss,
                   o.clamping_min, o.clamping_max, o.occupancy_threshold}) {
    w->put(v);
  }
  w->put<int32_t>(o.pixel_stride);
  w->put<int8_t>(static_cast<int8_t>(c.tracking_mode));
  w->put<int32_t>(c.tracking_warmup_frames);
  w->put<int8_t>(static_cast<int8_t>(c.tracking_correction));
  const FrameToModelAligner::Config& t = c.tracking;
  w->put<uint64_t>(t.level_strides_px.size());
  for (int stride : t.level_strides_px) w->put<int32_t>(stride);
  w->put<int32_t>(t.max_iterations);
  w->put<int8_t>(static_cast<int8_t>(t.loss));
  for (double v :
       {t.robust_scale_m, t.point_sigma_m, t.prior_sigma_translation_m, t.prior_sigma_rotation_rad,
        t.min_depth_m, t.max_depth_m, t.inlier_distance_m, t.min_inlier_ratio,
        t.min_relative_eigenvalue, t.max_correction_translation_m, t.max_correction_rotation_rad,
        t.weak_direction_damping, t.depth_noise_at_1m_m}) {
    w->put(v);
  }
  w->put<int32_t>(t.min_points);
  w->put<uint8_t>(t.remap_degenerate);
  const DriftFilter::Config& d = c.drift;
  for (double v : {d.drift_per_m, d.drift_deg_per_m, d.drift_deg_per_90deg, d.correlation_m,
                   d.measurement_sigma_m, d.measurement_sigma_deg}) {
    w->put(v);
  }
  w->put<int32_t>(c.num_threads);
  const bool calibrated = c.hasDepthCalibration();
  w->put<uint8_t>(calibrated);
  if (calibrated) {
    const DepthCalibration& k = *c.depth_calibration;
    for (int v : {k.width(), k.height(), k.cellsX(), k.cellsY(), k.knots()}) w->put<int32_t>(v);
    w->put(k.knotSpacingM());
    w->put<uint64_t>(k.offsetsM().size());
    w->putBytes(k.offsetsM().data(), k.offsetsM().size() * sizeof(float));
    w->putString(c.depth_calibration_file);
  }
  w->put<uint8_t>(c.mask_edge_fill.enabled);
  w->put(c.mask_edge_fill.max_depth_step);
  w->put<int32_t>(c.mask_edge_fill.max_distance_px);
  w->put<int32_t>(c.graph.pair_interior_px);
  const DepthPatternMonitor::Config& k = c.depth_check;
  for (int v : {k.frames, k.min_cell_points, k.min_cell_frames, k.min_cells}) w->put<int32_t>(v);
  w->put(k.max_pattern_m);
  w->put<uint8_t>(c.fusion.mask_only_surfaces);
  w->put(c.fusion.mask_only_depth_step);
  w->put<uint8_t>(c.superpoints.join_mask_pieces);
  w->put<uint8_t>(c.superpoints.revisit_votes);
}

MapperConfig getConfig(BinaryReader* r, uint32_t version) {
  MapperConfig c;
  c.map.voxel_size_m = r->get<float>();
  c.integrator.truncation_voxels = r->get<float>();
  c.integrator.max_weight = r->get<float>();
  c.integrator.min_depth_m = r->get<float>();
  c.integrator.max_depth_m = r->get<float>();
  c.integrator.weight_dropoff = r->get<uint8_t>() != 0;
  c.integrator.space_carving = r->get<uint8_t>() != 0;
  c.integrator.vote_stride_px = r->get<int32_t>();
  c.depth_segmentation.normals_window_px = r->get<int32_t>();
  c.depth_segmentation.min_convexity_window_px = r->get<int32_t>();
  c.depth_segmentation.min_convexity_threshold = r->get<float>();
  c.depth_segmentation.depth_discontinuity_ratio = r->get<float>();
  c.depth_segmentation.min_segment_px = r->get<int32_t>();
  c.depth_segmentation.max_depth_m = r->get<float>();
  c.fusion.min_surface_px = r->get<int32_t>();
  c.fusion.stuff_confidence = r->get<float>();
  c.fusion.geometry_only = r->get<uint8_t>() != 0;
  c.superpoints.association_min_overlap = r->get<float>();
  c.superpoints.significant_overlap = r->get<float>();
  c.superpoints.merge_threshold = r->get<int32_t>();
  c.superpoints.semantic_consistency = r->get<uint8_t>() != 0;
  c.superpoints.sample_stride_px = r->get<int32_t>();
  c.superpoints.instance_min_overlap = r->get<float>();
  c.graph.spatial_scale_m = r->get<double>();
  c.graph.sample_stride_px = r->get<int32_t>();
  if (version >= 6) {
    c.graph.prune_edges = r->get<uint8_t>() != 0;
    c.graph.edge_min_share = r->get<double>();
    c.graph.surface_band_voxels = r->get<float>();
  } else {
    c.graph.prune_edges = false;
  }
  c.superpoints.mask_verdicts = version >= 7 && r->get<uint8_t>() != 0;
  c.superpoints.apart_weight = version >= 8 ? r->get<float>() : 1.0f;
  c.superpoints.unlabelled_void_share = version >= 9 ? r->get<double>() : 1.0;
  c.occupancy_enabled = r->get<uint8_t>() != 0;
  OccupancyMap::Config& o = c.occupancy;
  for (double* v : {&o.resolution_m, &o.min_depth_m, &o.max_depth_m, &o.prob_hit, &o.prob_miss,
                    &o.clamping_min, &o.clamping_max, &o.occupancy_threshold}) {
    *v = r->get<double>();
  }
  o.pixel_stride = r->get<int32_t>();
  c.tracking_mode = static_cast<MapperConfig::TrackingMode>(r->get<int8_t>());
  c.tracking_warmup_frames = r->get<int32_t>();
  c.tracking_correction = static_cast<MapperConfig::PoseCorrection>(r->get<int8_t>());
  FrameToModelAligner::Config& t = c.tracking;
  t.level_strides_px.resize(r->getCount(sizeof(int32_t)));
  for (int& stride : t.level_strides_px) stride = r->get<int32_t>();
  t.max_iterations = r->get<int32_t>();
  t.loss = static_cast<RobustLoss>(r->get<int8_t>());
  for (double* v :
       {&t.robust_scale_m, &t.point_sigma_m, &t.prior_sigma_translation_m,
        &t.prior_sigma_rotation_rad, &t.min_depth_m, &t.max_depth_m, &t.inlier_distance_m,
        &t.min_inlier_ratio, &t.min_relative_eigenvalue, &t.max_correction_translation_m,
        &t.max_correction_rotation_rad, &t.weak_direction_damping, &t.depth_noise_at_1m_m}) {
    *v = r->get<double>();
  }
  t.min_points = r->get<int32_t>();
  t.remap_degenerate = r->get<uint8_t>() != 0;
  DriftFilter::Config& d = c.drift;
  for (double* v : {&d.drift_per_m, &d.drift_deg_per_m, &d.drift_deg_per_90deg, &d.correlation_m,
                    &d.measurement_sigma_m, &d.measurement_sigma_deg}) {
    *v = r->get<double>();
  }
  c.num_threads = r->get<int32_t>();
  if (version >= 12 && r->get<uint8_t>() != 0) {
    int v[5];
    for (int& x : v) x = r->get<int32_t>();
    const double spacing_m = r->get<double>();
    std::vector<float> offsets(r->getCount(sizeof(float)));
    r->getBytes(offsets.data(), offsets.size() * sizeof(float));
    c.depth_calibration = std::make_shared<const DepthCalibration>(v[0], v[1], v[2], v[3], v[4],
                                                                   spacing_m, std::move(offsets));
    c.depth_calibration_file = r->getString();
  }
  if (version >= 14) {
    c.mask_edge_fill.enabled = r->get<uint8_t>() != 0;
    c.mask_edge_fill.max_depth_step = r->get<double>();
    c.mask_edge_fill.max_distance_px = r->get<int32_t>();
  } else {
    c.mask_edge_fill.enabled = false;
  }
  // Older maps counted every pixel of a mask as co-observation: they go on as they began.
  c.graph.pair_interior_px = version >= 15 ? r->get<int32_t>() : 0;
  DepthPatternMonitor::Config& k = c.depth_check;
  if (version >= 16) {
    for (int* v : {&k.frames, &k.min_cell_points, &k.min_cell_frames, &k.min_cells}) {
      *v = r->get<int32_t>();
    }
    k.max_pattern_m = r->get<double>();
  } else {
    k.frames = 0;
  }
  if (version >= 17) {
    c.fusion.mask_only_surfaces = r->get<uint8_t>() != 0;
    c.fusion.mask_only_depth_step = r->get<float>();
  } else {
    c.fusion.mask_only_surfaces = false;
  }
  c.superpoints.join_mask_pieces = version >= 18 && r->get<uint8_t>() != 0;
  c.superpoints.revisit_votes = version >= 18 && r->get<uint8_t>() != 0;
  return c;
}

void putPose(BinaryWriter* w, const Eigen::Isometry3d& T) {
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 4; ++j) w->put(T.matrix()(i, j));
  }
}

Eigen::Isometry3d getPose(BinaryReader* r) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 4; ++j) T.matrix()(i, j) = r->get<double>();
  }
  return T;
}

void putSnapshot(BinaryWriter* w, const SuperpointTracker::Snapshot& s) {
  w->put<uint64_t>(s.parents.size());
  w->putBytes(s.parents.data(), s.parents.size() * sizeof(int32_t));
  w->put<uint64_t>(s.states.size());
  for (const auto& [label, state] : s.states) {
    w->put<int32_t>(label);
    w->put<uint64_t>(state.class_counts.size());
    for (const auto& [cls, count] : state.class_counts) {
      w->put<int32_t>(cls);
      w->put<double>(count);
    }
    w->put<uint64_t>(state.instance_counts.size());
    for (const auto& [id, count] : state.instance_counts) {
      w->put<int32_t>(id);
      w->put<int32_t>(count);
    }
  }
  w->put<uint64_t>(s.co_observed.size());
  for (const auto& [key, count] : s.co_observed) {
    w->put<int32_t>(key.first);
    w->put<int32_t>(key.second);
    w->put<int32_t>(count);
  }
  w->put<uint64_t>(s.apart.size());
  for (const auto& [key, count] : s.apart) {
    w->put<int32_t>(key.first);
    w->put<int32_t>(key.second);
    w->put<int32_t>(count);
  }
  w->put<uint64_t>(s.merges.size());
  for (const SuperpointMerge& m : s.merges) {
    w->put<int32_t>(m.kept);
    w->put<int32_t>(m.removed);
    w->put<int64_t>(m.frame);
  }
  w->put<int32_t>(s.next_instance);
  w->put<int64_t>(s.frames);
}

SuperpointTracker::Snapshot getSnapshot(BinaryReader* r) {
  SuperpointTracker::Snapshot s;
  s.parents.resize(r->getCount(sizeof(int32_t)));
  r->getBytes(s.parents.data(), s.parents.size() * sizeof(int32_t));
  const uint64_t states = r->getCount(20);
  for (uint64_t i = 0; i < states; ++i) {
    SuperpointState& state = s.states[r->get<int32_t>()];
    const uint64_t classes = r->getCount(12);
    for (uint64_t k = 0; k < classes; ++k) {
      const int32_t cls = r->get<int32_t>();
      state.class_counts[cls] = r->get<double>();
    }
    const uint64_t instances = r->getCount(8);
    for (uint64_t k = 0; k < instances; ++k) {
      const int32_t id = r->get<int32_t>();
      state.instance_counts[id] = r->get<int32_t>();
    }
  }
  const uint64_t pairs = r->getCount(12);
  for (uint64_t i = 0; i < pairs; ++i) {
    const int32_t a = r->get<int32_t>(), b = r->get<int32_t>();
    s.co_observed[{a, b}] = r->get<int32_t>();
  }
  const uint64_t apart = r->getCount(12);
  for (uint64_t i = 0; i < apart; ++i) {
    const int32_t a = r->get<int32_t>(), b = r->get<int32_t>();
    s.apart[{a, b}] = r->get<int32_t>();
  }
  const uint64_t merges = r->getCount(16);
  for (uint64_t i = 0; i < merges; ++i) {
    SuperpointMerge m;
    m.kept = r->get<int32_t>();
    m.removed = r->get<int32_t>();
    m.frame = r->get<int64_t>();
    s.merges.push_back(m);
  }
  s.next_instance = r->get<int32_t>();
  s.frames = r->get<int64_t>();
  return s;
}

void putClassMap(BinaryWriter* w, const std::map<int32_t, double>& m) {
  w->put<uint64_t>(m.size());
  for (const auto& [cls, value] : m) {
    w->put<int32_t>(cls);
    w->put<double>(value);
  }
}

std::map<int32_t, double> getClassMap(BinaryReader* r) {
  std::map<int32_t, double> m;
  const uint64_t n = r->getCount(12);
  for (uint64_t i = 0; i < n; ++i) {
    const int32_t cls = r->get<int32_t>();
    m[cls] = r->get<double>();
  }
  return m;
}

void putGraph(BinaryWriter* w, const GraphAccumulator::Snapshot& g) {
  w->put<uint64_t>(g.scores.size());
  for (const auto& [label, scores] : g.scores) {
    w->put<int32_t>(label);
    putClassMap(w, scores);
  }
  w->put<uint64_t>(g.edges.size());
  for (const auto& [key, conf] : g.edges) {
    w->put<int32_t>(key.first);
    w->put<int32_t>(key.second);
    putClassMap(w, conf);
  }
  w->put<uint64_t>(g.merges_applied);
}

GraphAccumulator::Snapshot getGraph(BinaryReader* r) {
  GraphAccumulator::Snapshot g;
  const uint64_t labels = r->getCount(12);
  for (uint64_t i = 0; i < labels; ++i) {
    const int32_t label = r->get<int32_t>();
    g.scores[label] = getClassMap(r);
  }
  const uint64_t edges = r->getCount(16);
  for (uint64_t i = 0; i < edges; ++i) {
    const int32_t a = r->get<int32_t>(), b = r->get<int32_t>();
    g.edges[{a, b}] = getClassMap(r);
  }
  g.merges_applied = r->get<uint64_t>();
  return g;
}

}  // namespace

void Mapper::serialize(ByteSink* sink) const {
  // Streamed: header, payload, CRC; the payload size is patched in at the end.
  ChecksummingSink checked(sink);
  BinaryWriter payload(&checked);
  payload.putBytes(kMagic, sizeof(kMagic));
  payload.put<uint32_t>(kVersion);
  payload.put<uint64_t>(0);
  putConfig(&payload, config_);
  payload.put<int64_t>(frames_);
  payload.put<uint64_t>(vote_evictions_);
  payload.put<uint64_t>(map_->numBlocks());
  for (const auto& block : map_->blocks()) {
    payload.put<int32_t>(block->index.x());
    payload.put<int32_t>(block->index.y());
    payload.put<int32_t>(block->index.z());
    payload.put<uint8_t>(block->updated);
    putVoxels(&payload, *block);
  }
  putSnapshot(&payload, tracker_->snapshot());
  putGraph(&payload, graph_->snapshot());
  const DriftFilter::State drift = drift_.state();
  payload.put<uint8_t>(drift.started);
  putPose(&payload, drift.input);
  putPose(&payload, drift.correction);
  for (int i = 0; i < 36; ++i) payload.put(drift.covariance.data()[i]);
  for (int64_t n : tracking_counts_) payload.put(n);
  const DepthPatternMonitor::State check = depth_check_.state();
  payload.put<int8_t>(static_cast<int8_t>(check.verdict));
  payload.put<int32_t>(check.frames);
  for (int h = 0; h < 2; ++h) {
    payload.put<uint64_t>(check.cell_frames[h].size());
    for (size_t i = 0; i < check.cell_frames[h].size(); ++i) {
      payload.put(check.cell_mean_sum_m[h][i]);
      payload.put<int32_t>(check.cell_frames[h][i]);
    }
  }
  payload.put(poses_kept_);
  payload.put(poses_corrected_);
  payload.put<uint64_t>(trajectory_.size());
  for (const StampedPose& p : trajectory_) {
    payload.put(p.utime);
    payload.put(p.frame_id);
    payload.put<int8_t>(static_cast<int8_t>(p.source));
    putPose(&payload, p.T_W_C);
  }
  if (occupancy_) occupancy_->writeState(&payload);

  payload.flush();
  const uint64_t size = payload.size() - kHeaderBytes;
  payload.putAt<uint64_t>(sizeof(kMagic) + sizeof(uint32_t), size);
  const uint32_t crc = checked.crc();
  sink->append(reinterpret_cast<const uint8_t*>(&crc), sizeof(crc));
}

std::vector<uint8_t> Mapper::serialize() const {
  std::vector<uint8_t> bytes;
  VectorSink sink(&bytes);
  serialize(&sink);
  return bytes;
}

void Mapper::save(const std::string& path) const {
  // A crash never leaves a half-written snapshot in place of a good one.
  AtomicFileWriter file(path);
  serialize(&file);
  file.commit();
}

namespace {

// Reads the header (magic, version, payload size) of a map file of `total_bytes` and checks it
// against that length; returns the payload size and sets `version`.
uint64_t readHeader(BinaryReader* header, size_t total_bytes, const std::string& path,
                    uint32_t* version) {
  char magic[8];
  header->getBytes(magic, sizeof(magic));
  if (std::memcmp(magic, kMagic, sizeof(kMagic)) != 0)
    throw Error(path + ": not a panmap map file");
  *version = header->get<uint32_t>();
  if (*version < kOldestVersion || *version > kVersion) {
    throw Error(path + ": map file version " + std::to_string(*version) + ", this panmap reads " +
                std::to_string(kOldestVersion) + " to " + std::to_string(kVersion));
  }
  const uint64_t size = header->get<uint64_t>();
  const size_t after = total_bytes - kHeaderBytes;
  if (size == 0 && after > sizeof(uint32_t)) {
    // serialize() fills the size in last: a writer stopped part way (a snapshot's .partial
    // file after a kill) left it 0, which read as an "overlong" file announcing 24 bytes.
    throw Error(path + ": unfinished map file (" + std::to_string(total_bytes) +
                " bytes; its writer stopped before the end, the header's size was never filled "
                "in)");
  }
  if (size > after || after - size != sizeof(uint32_t)) {
    throw Error(path + ": " + (size + sizeof(uint32_t) > after ? "truncated" : "overlong") +
                " map file (" + std::to_string(total_bytes) +
                " bytes; the header at offset 12 announces " +
                std::to_string(kHeaderBytes + size + sizeof(uint32_t)) + ")");
  }
  return size;
}

std::string checksumMismatch(const std::string& path, uint64_t size) {
  return path + ": checksum mismatch over bytes " + std::to_string(kHeaderBytes) + "-" +
         std::to_string(kHeaderBytes + size) + " (corrupt map file)";
}

// A map file's payload read in order, with the CRC-32 of what was read so far.
class ChecksummingFileSource : public ByteSource {
 public:
  ChecksummingFileSource(std::FILE* file, std::string path) : file_(file), path_(std::move(path)) {}
  void read(uint8_t* out, size_t size) override {
    if (std::fread(out, 1, size, file_) != size) {
      throw Error(path_ + ": cannot read (the file changed or shrank while it was loaded)");
    }
    crc_ = crc32_z(crc_, out, size);
  }
  uint32_t crc() const { return static_cast<uint32_t>(crc_); }

 private:
  std::FILE* file_;
  std::string path_;
  uLong crc_ = crc32(0L, Z_NULL, 0);
};

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

}  // namespace

std::unique_ptr<Mapper> Mapper::load(const std::string& path) {
  std::error_code ec;
  const bool regular = std::filesystem::is_regular_file(path, ec);
  const std::uintmax_t total = regular ? std::filesystem::file_size(path, ec) : 0;
  // Pipes and devices have no size to check the header against: read them whole.
  if (!regular || ec) return deserialize(readFileBytes(path), path);
  std::unique_ptr<std::FILE, FileCloser> file(std::fopen(path.c_str(), "rb"));
  if (!file) throw Error("cannot read " + path);
  // Streamed, so that loading needs the map's memory and not also the file's (a 2 cm building
  // is 3.6 GB of both). The payload is parsed as it is read and its checksum compared at the
  // end; a corrupt file is reported as such even when the corruption also broke the parsing.
  uint8_t head[kHeaderBytes];
  const size_t head_bytes = std::min<size_t>(kHeaderBytes, static_cast<size_t>(total));
  if (std::fread(head, 1, head_bytes, file.get()) != head_bytes) throw Error("cannot read " + path);
  BinaryReader header(head, head_bytes, path);
  uint32_t version = 0;
  const uint64_t size = readHeader(&header, static_cast<size_t>(total), path, &version);
  ChecksummingFileSource source(file.get(), path);
  BinaryReader r(&source, size, path, kHeaderBytes);
  std::unique_ptr<Mapper> mapper;
  try {
    mapper = parsePayload(&r, version, path);
  } catch (const Error&) {
    r.skipRest();
    uint32_t stored_crc = 0;
    if (std::fread(&stored_crc, 1, sizeof(stored_crc), file.get()) == sizeof(stored_crc) &&
        stored_crc != source.crc()) {
      throw Error(checksumMismatch(path, size));
    }
    throw;
  }
  uint32_t stored_crc = 0;
  if (std::fread(&stored_crc, 1, sizeof(stored_crc), file.get()) != sizeof(stored_crc)) {
    throw Error("cannot read " + path);
  }
  if (stored_crc != source.crc()) throw Error(checksumMismatch(path, size));
  return mapper;
}

std::unique_ptr<Mapper> Mapper::deserialize(const std::vector<uint8_t>& bytes,
                                            const std::string& path) {
  BinaryReader header(bytes.data(), bytes.size(), path);
  uint32_t version = 0;
  const uint64_t size = readHeader(&header, bytes.size(), path, &version);
  const uint8_t* payload = bytes.data() + (bytes.size() - header.remaining());
  uint32_t stored_crc;
  std::memcpy(&stored_crc, payload + size, sizeof(stored_crc));
  // crc32_z: crc32 takes a 32-bit length, and a 2 cm building's payload is near 4 GiB.
  if (stored_crc != static_cast<uint32_t>(crc32_z(0L, payload, static_cast<size_t>(size)))) {
    throw Error(checksumMismatch(path, size));
  }
  BinaryReader r(payload, size, path, kHeaderBytes);
  return parsePayload(&r, version, path);
}

std::unique_ptr<Mapper> Mapper::parsePayload(BinaryReader* reader, uint32_t version,
                                             const std::string& path) {
  BinaryReader& r = *reader;
  auto mapper = std::make_unique<Mapper>(getConfig(&r, version));
  mapper->frames_ = r.get<int64_t>();
  mapper->vote_evictions_ = r.get<uint64_t>();
  const uint64_t blocks = r.getCount(13 + kBlockVoxels * voxelBytes(version));
  // Block keys hold 21 bits per axis: an index beyond them would alias another block, and its
  // voxel coordinates (index * 8) overflow int (fuzz/fuzz_map_file).
  constexpr int32_t kMaxBlockIndex = 1 << 20;
  for (uint64_t i = 0; i < blocks; ++i) {
    BlockIndex index;
    index.x() = r.get<int32_t>();
    index.y() = r.get<int32_t>();
    index.z() = r.get<int32_t>();
    for (int axis = 0; axis < 3; ++axis) {
      if (index[axis] < -kMaxBlockIndex || index[axis] >= kMaxBlockIndex) {
        throw Error(path + ": block index " + std::to_string(index[axis]) + " out of range");
      }
    }
    Block* block = mapper->map_->allocateBlock(index);
    block->updated = r.get<uint8_t>() != 0;
    // The file does not say which faces changed: a changed block may have changed them all.
    block->lower_changed = block->updated ? 0xFE : 0;
    if (version >= 13) {
      getVoxels(&r, path, block);
    } else if (version >= 11) {
      getVoxels11(&r, block);
    } else {
      getVoxelsBefore11(&r, version, block);
    }
  }
  mapper->tracker_->restore(getSnapshot(&r));
  mapper->graph_->restore(getGraph(&r));
  DriftFilter::State drift;
  drift.started = r.get<uint8_t>() != 0;
  drift.input = getPose(&r);
  drift.correction = getPose(&r);
  for (int i = 0; i < 36; ++i) drift.covariance.data()[i] = r.get<double>();
  mapper->drift_.restore(drift);
  for (int64_t& n : mapper->tracking_counts_) n = r.get<int64_t>();
  if (version >= 16) {
    DepthPatternMonitor::State check;
    const int8_t verdict = r.get<int8_t>();
    if (verdict < 0 || verdict > 2) throw Error(path + ": unknown depth check verdict");
    check.verdict = static_cast<DepthPatternMonitor::Verdict>(verdict);
    check.frames = r.get<int32_t>();
    for (int h = 0; h < 2; ++h) {
      const size_t cells = r.getCount(sizeof(double) + sizeof(int32_t));
      check.cell_mean_sum_m[h].resize(cells);
      check.cell_frames[h].resize(cells);
      for (size_t i = 0; i < cells; ++i) {
        check.cell_mean_sum_m[h][i] = r.get<double>();
        check.cell_frames[h][i] = r.get<int32_t>();
      }
    }
    mapper->depth_check_.restore(check);
    mapper->poses_kept_ = r.get<int64_t>();
    mapper->poses_corrected_ = r.get<int64_t>();
  }
  mapper->trajectory_.resize(r.getCount(17 + 12 * sizeof(double)));
  for (StampedPose& p : mapper->trajectory_) {
    p.utime = r.get<int64_t>();
    p.frame_id = r.get<int64_t>();
    p.source = static_cast<PoseSource>(r.get<int8_t>());
    p.T_W_C = getPose(&r);
  }
  if (mapper->occupancy_) mapper->occupancy_->readState(&r);
  // The frames a pending depth check would revert are not in the file.
  mapper->probation_complete_ = mapper->trajectory_.empty();
  if (r.remaining() != 0) throw Error(path + ": unexpected bytes after the map state");
  return mapper;
}

}  // namespace panmap

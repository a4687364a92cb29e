// BackgroundRepair: a loop closure's repair on its own thread while mapping goes on.
#include "panmap/loop/background_repair.h"

#include <chrono>
#include <cstdio>
#include <utility>

#include "panmap/core/error.h"
#include "panmap/mapper/frame_prefetcher.h"

namespace panmap {

BackgroundRepair::BackgroundRepair(Mapper* mapper, FrameLoader load, FrameStore* store,
                                   const MapRepairConfig& config, PanopticFrameLoader panoptic_load,
                                   std::function<bool()> holds_segmentations)
    : mapper_(mapper),
      load_(std::move(load)),
      store_(store),
      config_(config),
      panoptic_load_(std::move(panoptic_load)),
      holds_segmentations_(std::move(holds_segmentations)) {
  if (!mapper_) throw Error("BackgroundRepair: no mapper");
  if (!load_) throw Error("BackgroundRepair: no frame loader");
  config_.check();
}

BackgroundRepair::BackgroundRepair(Mapper* mapper, FrameStore* store, const MapRepairConfig& config)
    : BackgroundRepair(mapper, storeLoader(store), store, config, storePanopticLoader(store)) {}

BackgroundRepair::~BackgroundRepair() { stopWorker(); }

int64_t BackgroundRepair::framesDone() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int64_t>(next_);
}

int64_t BackgroundRepair::framesTotal() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return static_cast<int64_t>(jobs_.size());
}

void BackgroundRepair::stopWorker() {
  if (!worker_.joinable()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  worker_.join();
}

void BackgroundRepair::cancel() {
  stopWorker();
  rebuild_.reset();
  occupancy_.reset();
  early_map_.reset();
  early_pass_ = false;
  early_handover_ = false;
}

MapRepairResult BackgroundRepair::start(const PoseCorrection& correction) {
  const std::string name = "correction " + std::to_string(correction.correction_id);
  try {
    correction.check();
  } catch (const Error& e) {
    throw Error(name + ": " + e.what());
  }
  CorrectedTrajectory corrected =
      applyCorrection(mapper_->trajectory(), correction, config_.match_tolerance_us);
  if (corrected.matched == 0) {
    throw Error(
        name + ": " +
        unmatchedCorrectionReason(mapper_->trajectory(), correction, config_.match_tolerance_us));
  }
  // Nothing to repair, unless a repair under way is to be superseded (it moves the map).
  if (!running() && negligible(corrected, config_)) {
    MapRepairResult nothing = matchedResult(correction, corrected);
    nothing.nothing_moved = true;
    nothing.reintegration.completed = true;
    return nothing;
  }
  if (running()) {
    cancel();
    ++superseded_;
  }
  result_ = matchedResult(correction, corrected);
  corrected_ = std::move(corrected);
  started_ = std::chrono::steady_clock::now();
  blocks_before_ = mapper_->map().numBlocks();
  // As repairMap() decides: a store holding segmentations keeps every frame's.
  const bool holds =
      holds_segmentations_ ? holds_segmentations_() : store_ && store_->sizeWithPanoptic() > 0;
  remap_ = config_.reassociate && panoptic_load_ && holds;
  rebuild_ = mapper_->beginRebuild(&pool_, remap_);
  // Mapping the frames again takes the whole pipeline per frame. The occupancy tree a planner
  // reads needs only the depth and the pose, and re-integrating the frames with the
  // super-points they voted for takes integration alone: those go first, in that order.
  const bool early_map = remap_ && config_.reintegrate_first;
  const bool early_occupancy = remap_ && config_.occupancy_first && mapper_->occupancy();
  occupancy_ =
      early_occupancy ? std::make_unique<OccupancyRebuild>(mapper_->config(), &pool_) : nullptr;
  early_map_ = early_map ? mapper_->beginRebuild(&pool_, false) : nullptr;
  occupancy_swapped_s_ = -1.0;
  map_swapped_s_ = -1.0;
  map_swapped_rejoined_ = 0;
  map_swapped_rejoin_s_ = 0.0;
  poses_recorded_ = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    jobs_ = corrected_.poses;
    next_ = 0;
    early_pass_ = early_occupancy || early_map;
    early_stage_ = early_occupancy ? EarlyStage::kOccupancy : EarlyStage::kMap;
    early_handover_ = false;
    early_next_ = 0;
    idle_ = false;
    stop_ = false;
    failure_.clear();
  }
  worker_ = std::thread(&BackgroundRepair::work, this);
  return result_;
}

void BackgroundRepair::frameIntegrated() {
  if (!running() || mapper_->trajectory().empty()) return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    jobs_.push_back(mapper_->trajectory().back());
  }
  cv_.notify_all();
}

void BackgroundRepair::reintegrate(const StampedPose& job, RgbdFrame* frame, LabelImage* labels,
                                   PanopticFrame* panoptic, GeometricSegments* kept) {
  *frame = RgbdFrame();
  *labels = LabelImage();
  if (remap_) {
    *panoptic = PanopticFrame();
    *kept = GeometricSegments();
    const bool has_panoptic = panoptic_load_(job.utime, frame, panoptic, kept);
    addLoaded(job, *frame, *labels, has_panoptic ? panoptic : nullptr,
              kept->ids.empty() ? nullptr : kept);
  } else {
    load_(job.utime, frame, labels);
    addLoaded(job, *frame, *labels, nullptr, nullptr);
  }
}

void BackgroundRepair::checkFrameOf(const StampedPose& job, const RgbdFrame& frame) {
  if (frame.utime != job.utime) {
    throw Error("asked for the frame of utime " + std::to_string(job.utime) + ", got " +
                std::to_string(frame.utime));
  }
}

void BackgroundRepair::addLoaded(const StampedPose& job, const RgbdFrame& frame,
                                 const LabelImage& labels, const PanopticFrame* panoptic,
                                 const GeometricSegments* kept) {
  checkFrameOf(job, frame);
  rebuild_->add(frame, job.T_W_C, &labels, panoptic, kept);
}

void BackgroundRepair::addEarly(EarlyStage stage, const StampedPose& job, const RgbdFrame& frame,
                                const LabelImage& labels) {
  checkFrameOf(job, frame);
  if (stage == EarlyStage::kMap) {
    early_map_->add(frame, job.T_W_C, &labels);
  } else {
    occupancy_->add(frame, job.T_W_C);
  }
}

bool BackgroundRepair::earlyPass() {
  for (;;) {
    EarlyStage stage;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      if (!early_pass_) return true;
      stage = early_stage_;
    }
    if (!earlyStage(stage)) return false;
  }
}

bool BackgroundRepair::earlyStage(EarlyStage stage) {
  RgbdFrame frame;
  LabelImage labels;
  std::vector<int64_t> covered;
  for (const StampedPose& p : corrected_.poses) covered.push_back(p.utime);
  FramePrefetcher prefetched(load_, std::move(covered));
  for (;;) {
    StampedPose job;
    size_t index = 0;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      if (early_handover_ || early_next_ == jobs_.size()) {
        // Caught up, or poll() takes the pass over with the last few frames: wait.
        idle_ = true;
        cv_.notify_all();
        cv_.wait(lock, [this, stage] {
          return stop_ || !early_pass_ || early_stage_ != stage ||
                 (!early_handover_ && early_next_ < jobs_.size());
        });
        idle_ = false;
      }
      if (stop_) return false;
      if (!early_pass_ || early_stage_ != stage) return true;
      index = early_next_;
      job = jobs_[index];
    }
    try {
      if (index < corrected_.poses.size()) {
        prefetched.next(&frame, &labels);
      } else {
        frame = RgbdFrame();
        load_(job.utime, &frame, &labels);
      }
      addEarly(stage, job, frame, labels);
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex_);
      failure_ = e.what();
      idle_ = true;
      cv_.notify_all();
      return false;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    ++early_next_;
  }
}

void BackgroundRepair::takeEarlyIfReady(std::unique_lock<std::mutex>* lock) {
  if (!early_pass_ || !failure_.empty()) return;
  // Frames keep coming, so the pass is never quite done when asked (as for the commit): at most
  // kFramesLeftToCommit behind, it is handed over after the frame it is on.
  if (jobs_.size() - early_next_ > kFramesLeftToCommit) return;
  early_handover_ = true;
  cv_.notify_all();
  cv_.wait(*lock, [this] { return !failure_.empty() || idle_; });
  if (!failure_.empty()) return;
  // The worker waits: the pass is this thread's until it ends.
  const EarlyStage stage = early_stage_;
  const bool map = stage == EarlyStage::kMap;
  try {
    RgbdFrame frame;
    LabelImage labels;
    for (; early_next_ < jobs_.size(); ++early_next_) {
      const StampedPose& job = jobs_[early_next_];
      load_(job.utime, &frame, &labels);
      addEarly(stage, job, frame, labels);
    }
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
    if (map) {
      ReintegrationStats early;
      mapper_->commitRebuild(std::move(early_map_), &early);
      map_swapped_s_ = seconds;
      map_swapped_rejoined_ = early.superpoints_rejoined;
      map_swapped_rejoin_s_ = early.rejoin_s;
      if (mapper_->occupancy() && occupancy_swapped_s_ < 0.0) occupancy_swapped_s_ = seconds;
      recordPoses();
    } else {
      const std::vector<StampedPose> poses = occupancy_->poses();
      mapper_->replaceOccupancy(occupancy_->take(), poses);
      occupancy_swapped_s_ = seconds;
    }
  } catch (const std::exception& e) {
    // The commit brings the whole repair all the same.
    std::fprintf(stderr, "panmap: the repair's early %s not swapped in: %s\n",
                 map ? "re-integrated map" : "occupancy tree", e.what());
  }
  if (map) {
    early_map_.reset();
  } else {
    occupancy_.reset();
  }
  // After the tree, the re-integrated map when there is one: a pass over every frame again.
  if (early_map_) {
    early_stage_ = EarlyStage::kMap;
    early_next_ = 0;
  } else {
    early_pass_ = false;
  }
  early_handover_ = false;
  cv_.notify_all();
}

void BackgroundRepair::recordPoses() {
  if (!store_ || poses_recorded_) return;
  for (size_t i = 0; i < corrected_.poses.size(); ++i) {
    if (corrected_.translation_m[i] > 0.0 || corrected_.rotation_rad[i] > 0.0) {
      store_->updatePose(corrected_.poses[i].utime, corrected_.poses[i].T_W_C);
    }
  }
  poses_recorded_ = true;
}

void BackgroundRepair::work() {
  if (!earlyPass()) return;
  RgbdFrame frame;
  LabelImage labels;
  PanopticFrame panoptic;
  GeometricSegments kept;
  // The frames the correction covers are decoded ahead on another thread; those mapped since
  // come one by one, as the mapping thread hands them over.
  std::vector<int64_t> covered;
  for (const StampedPose& p : corrected_.poses) covered.push_back(p.utime);
  std::unique_ptr<FramePrefetcher> prefetched =
      remap_ ? std::make_unique<FramePrefetcher>(panoptic_load_, std::move(covered))
             : std::make_unique<FramePrefetcher>(load_, std::move(covered));
  for (;;) {
    StampedPose job;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      if (next_ == jobs_.size()) {
        idle_ = true;
        cv_.notify_all();
        cv_.wait(lock, [this] { return stop_ || next_ < jobs_.size(); });
        idle_ = false;
      }
      if (stop_) return;
      job = jobs_[next_];
    }
    try {
      if (next_ < corrected_.poses.size()) {
        const bool has_panoptic = prefetched->next(&frame, &labels, &panoptic, &kept);
        addLoaded(job, frame, labels, has_panoptic ? &panoptic : nullptr,
                  kept.ids.empty() ? nullptr : &kept);
      } else {
        reintegrate(job, &frame, &labels, &panoptic, &kept);
      }
    } catch (const std::exception& e) {
      std::lock_guard<std::mutex> lock(mutex_);
      failure_ = e.what();
      idle_ = true;
      cv_.notify_all();
      return;
    }
    std::lock_guard<std::mutex> lock(mutex_);
    ++next_;
  }
}

MapRepairResult BackgroundRepair::commit() {
  // The worker has returned: everything below is this thread's.
  MapRepairResult result = std::move(result_);
  result.occupancy_swapped_s = occupancy_swapped_s_;
  result.map_swapped_s = map_swapped_s_;
  result.map_swapped_rejoined = map_swapped_rejoined_;
  result.map_swapped_rejoin_s = map_swapped_rejoin_s_;
  ReintegrationStats& stats = result.reintegration;
  stats.blocks_before = blocks_before_;
  stats.seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
  if (!failure_.empty()) {
    result.failure = failure_;
    stats.blocks_after = blocks_before_;
    rebuild_.reset();
    return result;
  }
  stats.frames = rebuild_->poses().size();
  stats.reassociated = rebuild_->remaps();
  stats.votes_evicted = rebuild_->votesEvicted();
  stats.frames_with_kept_segments = rebuild_->framesWithKeptSegments();
  for (size_t i = 0; i < corrected_.poses.size(); ++i) {
    stats.frames_moved += corrected_.translation_m[i] > 0.0 || corrected_.rotation_rad[i] > 0.0;
  }
  try {
    mapper_->commitRebuild(std::move(rebuild_), &stats);
  } catch (const Error& e) {
    result.failure = e.what();
    stats.frames = 0;
    stats.frames_moved = 0;
    stats.blocks_after = blocks_before_;
    return result;
  }
  recordPoses();
  stats.completed = true;
  stats.blocks_after = mapper_->map().numBlocks();
  return result;
}

std::optional<MapRepairResult> BackgroundRepair::poll() {
  if (!running()) return std::nullopt;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    takeEarlyIfReady(&lock);
    // Frames keep coming while the worker catches up, so it is never quite done when asked:
    // the last few frames are re-integrated here instead.
    if (failure_.empty() && (early_pass_ || jobs_.size() - next_ > kFramesLeftToCommit)) {
      return std::nullopt;
    }
  }
  stopWorker();  // it finishes the frame it is on
  if (failure_.empty()) {
    RgbdFrame frame;
    LabelImage labels;
    PanopticFrame panoptic;
    GeometricSegments kept;
    try {
      for (; next_ < jobs_.size(); ++next_) {
        reintegrate(jobs_[next_], &frame, &labels, &panoptic, &kept);
      }
    } catch (const std::exception& e) {
      failure_ = e.what();
    }
  }
  return commit();
}

std::optional<MapRepairResult> BackgroundRepair::finish() {
  if (!running()) return std::nullopt;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      cv_.wait(lock, [this] {
        return !failure_.empty() || (idle_ && (early_pass_ ? early_next_ : next_) == jobs_.size());
      });
      if (!failure_.empty() || !early_pass_) break;
      takeEarlyIfReady(&lock);
    }
  }
  return poll();
}

}  // namespace panmap

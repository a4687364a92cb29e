#include "panmap/lcm/live_mapper.h"

#include <lcm/lcm_coretypes.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>

#include "panmap/command_t.hpp"
#include "panmap/core/error.h"
#include "panmap/core/process_memory.h"
#include "panmap/graph_labels_t.hpp"
#include "panmap/lcm/decode.h"
#include "panmap/lcm/graph_conversions.h"
#include "panmap/mapper/final_labels.h"

namespace panmap {

namespace {

int64_t wallUtime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// The time of the map state a message describes: its newest frame's utime, in the sensor's
// clock as objects.json has it (the wall clock told a planner nothing about which frame the
// map holds). 0 before the first frame.
int64_t mapUtime(const Mapper& mapper) {
  return mapper.trajectory().empty() ? 0 : mapper.trajectory().back().utime;
}

}  // namespace

void LiveOptions::check() const {
  session.sync.check();
  if (!(status_period_s > 0.0)) throw Error("live: status_period_s must be positive");
  if (!(publish_period_s >= 0.0)) throw Error("live: publish_period_s must be >= 0");
  if (max_queued_frames < 1) throw Error("live: max_queued_frames must be at least 1");
  if (!(optimiser_timeout_s >= 0.0)) throw Error("live: optimiser_timeout_s must be >= 0");
  if (!(optimiser_retry_s > 0.0)) throw Error("live: optimiser_retry_s must be positive");
  if (!(optimise_period_s >= 0.0)) throw Error("live: optimise_period_s must be >= 0");
  if (request_id_base < -1) throw Error("live: request_id_base must be >= -1 (-1: random)");
  if (idle_scan_every_frames < 0) throw Error("live: idle_scan_every_frames must be >= 0");
}

LiveMapper::LiveMapper(lcm::LCM* lcm, const LiveOptions& options, Mapper* mapper,
                       MappingSession::FrameHook hook)
    : lcm_(lcm), options_(options), mapper_(mapper), session_(options.session, mapper) {
  options_.check();
  // 2^24 requests of room above a random base below 2^56.
  request_base_ = options_.request_id_base >= 0
                      ? options_.request_id_base
                      : static_cast<int64_t>((static_cast<uint64_t>(std::random_device{}()) << 24) &
                                             ((uint64_t{1} << 56) - 1));
  request_id_ = request_base_;
  if (hook) session_.setFrameHook(std::move(hook));
  if (!lcm_ || !lcm_->good()) throw Error("LCM is not ready");
  // A repair that runs on the worker (without SessionOptions::background_repair) blocks it:
  // the status says so while frames wait in the queue.
  session_.setRepairHook([this](int64_t done, int64_t total) {
    const auto now = std::chrono::steady_clock::now();
    if (done < total &&
        now - last_repair_status_ < std::chrono::duration<double>(options_.status_period_s)) {
      return;
    }
    last_repair_status_ = now;
    publishStatus("repairing");
  });
  for (const std::string& channel :
       {options_.session.channel_rgbd, options_.session.channel_pose,
        options_.session.channel_panoptic, options_.session.channel_correction}) {
    subscriptions_.push_back(lcm_->subscribe(channel, &LiveMapper::onInput, this));
  }
  subscriptions_.push_back(lcm_->subscribe(options_.channel_command, &LiveMapper::onCommand, this));
  subscriptions_.push_back(lcm_->subscribe(options_.channel_labels, &LiveMapper::onLabels, this));
  worker_ = std::thread(&LiveMapper::workerLoop, this);
}

LiveMapper::~LiveMapper() {
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    stop_worker_ = true;
  }
  queue_cv_.notify_all();
  if (worker_.joinable()) worker_.join();
  for (lcm::Subscription* s : subscriptions_) lcm_->unsubscribe(s);
}

void LiveMapper::post(Item item) {
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    if (draining_ || stop_worker_) {
      // Received while the outputs are made: counted, so every frame received is accounted for.
      if (item.channel == options_.session.channel_rgbd) ++after_finish_frames_;
      return;
    }
    if (item.channel == options_.session.channel_rgbd) {
      if (queued_frames_ >= options_.max_queued_frames) {
        // Newest data is worth more to a robot than a backlog: push the oldest frame out.
        for (auto it = queue_.begin(); it != queue_.end(); ++it) {
          if (it->channel == options_.session.channel_rgbd) {
            // Its mask is dropped with it, not counted as one that matched no frame (whose
            // warning blamed the masks' timestamps): the session hears of the drop in order.
            // The utime is the message's first field, after LCM's 8-byte fingerprint: LCM's
            // own decoder reads it without decoding the images.
            int64_t utime = 0;
            if (__int64_t_decode_array(it->bytes.data(), 8, static_cast<int>(it->bytes.size()),
                                       &utime, 1) > 0) {
              *it = Item{"", {}, [this, utime](Mapper*) { session_.skipFrame(utime); }};
            } else {
              queue_.erase(it);
            }
            --queued_frames_;
            ++dropped_frames_;
            break;
          }
        }
      }
      ++queued_frames_;
    }
    queue_.push_back(std::move(item));
  }
  queue_cv_.notify_one();
}

void LiveMapper::onInput(const lcm::ReceiveBuffer* buffer, const std::string& channel) {
  // LCM's C code calls this: copy and return, nothing may throw out of here.
  try {
    if (channel == options_.session.channel_rgbd) ++received_frames_;
    const uint8_t* data = static_cast<const uint8_t*>(buffer->data);
    post(Item{channel, std::vector<uint8_t>(data, data + buffer->data_size), {}});
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-mapper: message on %s lost: %s\n", channel.c_str(), e.what());
  }
}

SessionStats LiveMapper::withOwnRejections(SessionStats stats) const {
  {
    std::lock_guard<std::mutex> lock(rejected_mutex_);
    for (const auto& [reason, n] : rejected_commands_) stats.rejected[reason] += n;
  }
  const int64_t late = after_finish_frames_;
  if (late > 0) stats.rejected[kAfterFinish] += late;
  return stats;
}

void LiveMapper::countRejected(const std::string& reason) {
  std::lock_guard<std::mutex> lock(rejected_mutex_);
  ++rejected_commands_[reason];
}

void LiveMapper::onCommand(const lcm::ReceiveBuffer* buffer, const std::string& channel) {
  try {
    command_t msg;
    if (!decodeExactly(buffer->data, buffer->data_size, &msg)) {
      countRejected("malformed " + channel);
      std::fprintf(stderr, "panmap-mapper: malformed message on %s ignored\n", channel.c_str());
      return;
    }
    const int64_t utime = msg.utime;
    switch (msg.command) {
      case command_t::COMMAND_FINISH:
        finish_requested_ = true;
        finish_command_utime_ = utime;
        finish_by_command_ = true;
        setCommandState(utime, "running", "finishing: mapping what is queued, then the outputs");
        return;
      case command_t::COMMAND_OPTIMISE:
        requestOptimisation();
        setCommandState(utime, "done", "graph sent to the optimiser");
        return;
      case command_t::COMMAND_SAVE:
      case command_t::COMMAND_EXPORT: {
        if (!command_handler_) {
          setCommandState(utime, "failed", "this mapper does not save or export on command");
          return;
        }
        if (serving_after_finish_) {
          // The worker is gone and the map is this thread's: the command runs here, now.
          try {
            setCommandState(utime, "done",
                            command_handler_(msg.command, msg.argument, mapper_,
                                             labels_ ? &*labels_ : nullptr));
          } catch (const std::exception& e) {
            setCommandState(utime, "failed", e.what());
          }
          publishStatus("finish failed");
          return;
        }
        const int8_t command = msg.command;
        const std::string argument = msg.argument;
        setCommandState(utime, "running", "queued behind the frames already received");
        postWithLabels([this, command, argument, utime](Mapper* mapper, const GraphLabels* labels) {
          try {
            setCommandState(utime, "done", command_handler_(command, argument, mapper, labels));
          } catch (const std::exception& e) {
            std::fprintf(stderr, "panmap-mapper: command failed: %s\n", e.what());
            setCommandState(utime, "failed", e.what());
          }
          // At once, not at the next period: panmap-command is waiting for it.
          const status_t now = status(session_.stats().repair_running ? "repairing" : "mapping");
          std::lock_guard<std::mutex> lock(outbox_mutex_);
          outbox_.push_back(encodeMessage(options_.channel_status, now));
        });
        return;
      }
      default:
        countRejected("unknown command");
        std::fprintf(stderr, "panmap-mapper: unknown command %d ignored\n", msg.command);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-mapper: command ignored: %s\n", e.what());
  }
}

void LiveMapper::setCommandState(int64_t utime, const std::string& state,
                                 const std::string& result) {
  std::lock_guard<std::mutex> lock(command_mutex_);
  for (CommandState& c : commands_) {
    if (c.utime == utime) {
      c.state = state;
      c.result = result;
      return;
    }
  }
  commands_.push_back({utime, state, result});
  if (commands_.size() > kCommandsReported) commands_.pop_front();
}

bool LiveMapper::serveCommandsAfterFailedFinish(const std::atomic<bool>& stop) {
  if (worker_.joinable()) throw Error("serveCommandsAfterFailedFinish: drain() first");
  serving_after_finish_ = true;
  finish_requested_ = false;
  auto next_status = std::chrono::steady_clock::now();
  while (!stop && !finish_requested_) {
    lcm_->handleTimeout(100);
    if (std::chrono::steady_clock::now() >= next_status) {
      publishStatus("finish failed");
      next_status += std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::duration<double>(options_.status_period_s));
    }
  }
  serving_after_finish_ = false;
  return finish_requested_;
}

void LiveMapper::publishFinished(bool ok, const std::string& result) {
  if (finish_by_command_) {
    setCommandState(finish_command_utime_, ok ? "done" : "failed", result);
  }
  publishStatus(ok ? "done" : "finish failed");
}

void LiveMapper::requestOptimisation() {
  const int64_t request = ++request_id_;
  unanswered_requests_ = request_id_ - std::max(labels_request_id_, request_base_);
  const std::string graph_channel = options_.channel_graph;
  post(Item{"", {}, [this, request, graph_channel](Mapper* mapper) {
              const SuperpointGraph taken = mapper->graph();
              graph_instances_[request] = largestInitialInstance(taken);
              // Only the latest few requests can still be answered.
              while (graph_instances_.size() > 16) graph_instances_.erase(graph_instances_.begin());
              const superpoint_graph_t graph = toMessage(taken, mapUtime(*mapper), request);
              std::lock_guard<std::mutex> lock(outbox_mutex_);
              outbox_.push_back(encodeMessage(graph_channel, graph));
            }});
}

void LiveMapper::postWithLabels(std::function<void(Mapper*, const GraphLabels*)> use) {
  const std::optional<GraphLabels> labels = labels_;
  const int64_t labels_request = labels_request_id_;
  post(Item{"", {}, [this, use, labels, labels_request](Mapper* mapper) {
              // The answer names the super-points of its graph; those made since (new frames, a
              // repair) keep their frame-count labels beside it.
              std::optional<GraphLabels> fitted;
              const auto taken = graph_instances_.find(labels_request);
              if (labels && taken != graph_instances_.end()) {
                fitted = fitLabelsToMap(*labels, taken->second, mapper->superpoints());
              } else if (labels) {
                std::fprintf(stderr,
                             "panmap-mapper: the optimiser's labels answer a request too old to "
                             "match; frame-count labels used\n");
              }
              use(mapper, fitted ? &*fitted : nullptr);
            }});
}

void LiveMapper::onLabels(const lcm::ReceiveBuffer* buffer, const std::string& channel) {
  try {
    graph_labels_t msg;
    if (!decodeExactly(buffer->data, buffer->data_size, &msg)) {
      countRejected("malformed " + channel);
      return;
    }
    // Only answers to our own requests count (another mapper may share the bus), the newest
    // first: with periodic requests an answer may come after the next request went out.
    if (msg.request_id <= request_base_ || msg.request_id > request_id_ ||
        msg.request_id <= labels_request_id_) {
      return;
    }
    labels_ = fromMessage(msg);
    labels_request_id_ = msg.request_id;
    unanswered_requests_ = request_id_ - labels_request_id_;
  } catch (const std::exception& e) {
    countRejected("bad " + channel);
    std::fprintf(stderr, "panmap-mapper: labels ignored: %s\n", e.what());
  }
}

void LiveMapper::workerLoop() {
  for (;;) {
    Item item;
    {
      std::unique_lock<std::mutex> lock(queue_mutex_);
      queue_cv_.wait(lock, [&] { return stop_worker_ || draining_ || !queue_.empty(); });
      if (stop_worker_) return;
      if (queue_.empty()) {
        if (draining_) break;
        continue;
      }
      item = std::move(queue_.front());
      queue_.pop_front();
      if (item.channel == options_.session.channel_rgbd) --queued_frames_;
    }
    if (item.channel.empty()) {
      item.task(mapper_);
    } else {
      session_.handle(item.channel, item.bytes.data(), item.bytes.size());
    }
    refreshScanIfIdle();
  }
  session_.flush();
}

void LiveMapper::refreshScanIfIdle() {
  if (options_.idle_scan_every_frames <= 0) return;
  const int64_t frames = mapper_->framesIntegrated();
  // A repair swapped in, or a map loaded, may have fewer frames: count from there.
  if (frames < scanned_at_frame_) scanned_at_frame_ = frames;
  if (frames - scanned_at_frame_ < options_.idle_scan_every_frames) return;
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    // Only time the worker would wait: a frame waiting, or the final drain, comes first.
    if (!queue_.empty() || draining_ || stop_worker_) return;
  }
  scanned_at_frame_ = frames;
  try {
    mapper_->refreshSurfaceScan();
    ++idle_scan_refreshes_;
  } catch (const std::exception& e) {
    // Only a cache: the final graph reads what this could not.
    std::fprintf(stderr, "panmap-mapper: surface scan refresh failed: %s\n", e.what());
  }
}

void LiveMapper::publishNow(const std::vector<OutgoingMessage>& messages) {
  if (worker_.joinable()) throw Error("publishNow: drain() first");
  for (const OutgoingMessage& m : messages) {
    lcm_->publish(m.channel, m.bytes.data(), static_cast<unsigned int>(m.bytes.size()));
  }
}

void LiveMapper::publishOutbox() {
  std::vector<OutgoingMessage> out;
  {
    std::lock_guard<std::mutex> lock(outbox_mutex_);
    out.swap(outbox_);
  }
  for (const OutgoingMessage& m : out) {
    lcm_->publish(m.channel, m.bytes.data(), static_cast<unsigned int>(m.bytes.size()));
  }
}

status_t LiveMapper::status(const std::string& state) const {
  const SessionStats s = session_.stats();
  status_t msg;
  msg.utime = wallUtime();
  msg.state = state;
  msg.frames_received = received_frames_;
  msg.frames_integrated = s.frames_integrated;
  msg.frames_dropped = dropped_frames_;  // the synchroniser's drops are counted as rejected
  const std::map<std::string, int64_t> reasons = withOwnRejections(s).rejected;
  msg.frames_rejected = 0;
  for (const auto& [reason, n] : reasons) {
    msg.reject_reasons.push_back(reason);
    msg.reject_counts.push_back(n);
    msg.frames_rejected += n;
  }
  msg.num_reject_reasons = static_cast<int32_t>(reasons.size());
  for (const auto& [stage, t] : s.timings) {
    msg.stage_names.push_back(stage);
    msg.stage_median_ms.push_back(static_cast<float>(t.median_ms));
    msg.stage_last_ms.push_back(static_cast<float>(t.last_ms));
  }
  msg.num_stages = static_cast<int32_t>(msg.stage_names.size());
  msg.memory_bytes = static_cast<int64_t>(residentBytes());
  msg.num_blocks = static_cast<int64_t>(mapper_->map().numBlocks());
  msg.num_voxels = msg.num_blocks * kBlockVoxels;
  msg.num_superpoints = static_cast<int32_t>(mapper_->superpoints().states().size());
  // Instances some live super-point holds (the tracker's numInstances() is the largest id it
  // has given, 451 where a room had 27-44 objects).
  std::vector<int32_t> instances;
  for (const auto& [superpoint, state] : mapper_->superpoints().states()) {
    if (state.instance() > 0) instances.push_back(state.instance());
  }
  std::sort(instances.begin(), instances.end());
  msg.num_instances =
      static_cast<int32_t>(std::unique(instances.begin(), instances.end()) - instances.begin());
  msg.vote_evictions = static_cast<int64_t>(mapper_->voteEvictions());
  msg.corrections_applied = s.corrections_applied;
  msg.last_correction_id = s.last_correction_id;
  msg.repair_frames_done = s.repair_frames_done;
  msg.repair_frames_total = s.repair_frames_total;
  msg.last_repair_s = static_cast<float>(s.last_repair_s);
  msg.poses_corrected = mapper_->posesCorrected();
  msg.poses_kept_as_given = mapper_->posesKeptAsGiven();
  const DepthPatternMonitor& check = mapper_->depthCheck();
  msg.depth_check = DepthPatternMonitor::name(check.verdict());
  const double pattern_m = check.patternRmsM();
  msg.depth_pattern_mm = std::isfinite(pattern_m) ? static_cast<float>(1000.0 * pattern_m) : -1.0f;
  if (warning_source_) msg.warnings = warning_source_();
  for (std::string& w : syncWarnings(s, options_.session.sync)) msg.warnings.push_back(w);
  // One request may be on its way; two or more without an answer mean no optimiser listens.
  if (const int64_t unanswered = unanswered_requests_; unanswered >= 2) {
    msg.warnings.push_back("optimiser: no answer to the last " + std::to_string(unanswered) +
                           " graph requests on " + options_.channel_graph +
                           " (is panmap-optimizer running on this LCM URL?); labels from frame "
                           "counts since its last answer");
  }
  if (!waiting_for_labels_.empty()) msg.warnings.push_back(waiting_for_labels_);
  if (std::string poses = mapper_->poseConventionWarning(); !poses.empty()) {
    msg.warnings.push_back(std::move(poses));
  }
  msg.num_warnings = static_cast<int32_t>(msg.warnings.size());
  {
    std::lock_guard<std::mutex> lock(command_mutex_);
    for (const CommandState& c : commands_) {
      msg.command_utimes.push_back(c.utime);
      msg.command_states.push_back(c.state);
      msg.command_results.push_back(c.result);
    }
    msg.num_commands = static_cast<int32_t>(commands_.size());
  }
  return msg;
}

void LiveMapper::publishStatus(const std::string& state) {
  const status_t msg = status(state);
  lcm_->publish(options_.channel_status, &msg);
}

bool LiveMapper::run(const std::atomic<bool>& stop) {
  using Clock = std::chrono::steady_clock;
  const auto period = [](double s) {
    return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
  };
  auto next_status = Clock::now();
  auto next_publish = Clock::now() + period(options_.publish_period_s);
  auto next_optimise = Clock::now() + period(options_.optimise_period_s);
  while (!stop && !finish_requested_) {
    lcm_->handleTimeout(20);
    publishOutbox();
    const auto now = Clock::now();
    if (now >= next_status) {
      next_status = now + period(options_.status_period_s);
      const std::string channel = options_.channel_status;
      post(Item{"", {}, [this, channel](Mapper*) {
                  // A background repair that caught up is swapped in even when no frame comes.
                  session_.poll();
                  const status_t msg =
                      status(session_.stats().repair_running ? "repairing" : "mapping");
                  std::lock_guard<std::mutex> lock(outbox_mutex_);
                  outbox_.push_back(encodeMessage(channel, msg));
                }});
    }
    if (options_.optimise_period_s > 0.0 && now >= next_optimise) {
      next_optimise = now + period(options_.optimise_period_s);
      requestOptimisation();
    }
    if (options_.publish_period_s > 0.0 && publisher_ && now >= next_publish) {
      next_publish = now + period(options_.publish_period_s);
      postWithLabels([this](Mapper* mapper, const GraphLabels* labels) {
        std::vector<OutgoingMessage> out = publisher_(mapper, mapUtime(*mapper), labels);
        std::lock_guard<std::mutex> lock(outbox_mutex_);
        for (OutgoingMessage& m : out) outbox_.push_back(std::move(m));
      });
    }
  }
  return finish_requested_;
}

void LiveMapper::drain() {
  {
    std::lock_guard<std::mutex> lock(queue_mutex_);
    draining_ = true;
  }
  queue_cv_.notify_all();
  if (worker_.joinable()) worker_.join();
  publishOutbox();
  publishStatus("finishing");
}

std::optional<GraphLabels> LiveMapper::requestLabels(const std::atomic<bool>& stop) {
  if (worker_.joinable()) throw Error("requestLabels: drain() first");
  const int64_t request = ++request_id_;
  labels_.reset();
  const superpoint_graph_t graph = toMessage(mapper_->graph(), mapUtime(*mapper_), request);
  using Clock = std::chrono::steady_clock;
  const auto seconds = [](double s) {
    return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
  };
  const auto start = Clock::now();
  const auto deadline = start + seconds(options_.optimiser_timeout_s);
  auto next_send = Clock::now();
  int sent = 0;
  publishStatus("optimising");
  while (!stop && Clock::now() < deadline) {
    if (Clock::now() >= next_send) {
      // Again and again until answered: an optimiser that was down or restarted meanwhile
      // never saw the earlier copies (it answers each copy; the first answer is taken).
      lcm_->publish(options_.channel_graph, &graph);
      ++graph_requests_sent_;
      next_send = Clock::now() + seconds(options_.optimiser_retry_s);
      if (++sent > 1) {
        // Said on the status channel too: it went silent for the whole timeout.
        char text[200];
        std::snprintf(text, sizeof(text),
                      "optimiser: no answer to the final graph after %.0f s; the outputs get "
                      "frame-count labels after %.0f s",
                      std::chrono::duration<double>(Clock::now() - start).count(),
                      options_.optimiser_timeout_s);
        waiting_for_labels_ = text;
        publishStatus("optimising");
      }
    }
    lcm_->handleTimeout(50);
    if (labels_ && labels_request_id_ == request) {
      waiting_for_labels_.clear();
      return labels_;
    }
  }
  waiting_for_labels_.clear();
  return std::nullopt;
}

}  // namespace panmap

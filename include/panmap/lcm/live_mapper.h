#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <lcm/lcm-cpp.hpp>

#include "panmap/graph/superpoint_graph.h"
#include "panmap/lcm/channels.h"
#include "panmap/lcm/mapping_session.h"
#include "panmap/mapper/mapper.h"
#include "panmap/status_t.hpp"

namespace panmap {

/// Channels, rates and limits of the live mapping process.
struct LiveOptions {
  SessionOptions session;
  std::string channel_status = kChannelStatus;
  std::string channel_objects = kChannelObjects;
  std::string channel_octomap = kChannelOctomap;
  std::string channel_graph = kChannelGraph;
  std::string channel_labels = kChannelLabels;
  std::string channel_command = kChannelCommand;
  double status_period_s = 1.0;   ///< PANMAP_STATUS period
  double publish_period_s = 5.0;  ///< PANMAP_OBJECTS / PANMAP_OCTOMAP period (0 = never)
  /// RGB-D messages waiting for the worker at most; a newer one pushes the oldest out (counted),
  /// so a slow mapper stays current instead of falling further behind.
  size_t max_queued_frames = 4;
  double optimiser_timeout_s = 30.0;  ///< how long finish() waits for PANMAP_LABELS
  /// The graph is published again at this period while no labels came: an optimiser started
  /// (or restarted) after the first request still answers.
  double optimiser_retry_s = 2.0;
  /// While mapping, the graph goes to the optimiser at this period (as the optimise command
  /// sends it), and PANMAP_OBJECTS and exports use its latest answer, fitted to the map as it
  /// is then (fitLabelsToMap): objects as the final optimisation makes them (fragments folded,
  /// calibrated confidences), not the frame-count instances. 0: only on request.
  double optimise_period_s = 10.0;
  /// The first optimisation request gets this id + 1, and answers (PANMAP_LABELS echo the id)
  /// count only for ids this mapper gave. -1: a random base per process, so that two mappers
  /// sharing a bus and an optimiser never take each other's answers (requests go out every
  /// optimise_period_s; counting from 0, theirs would meet).
  int64_t request_id_base = -1;
  /// When the worker finds its queue empty and at least this many frames were integrated since
  /// the last time, it brings the graph's surface scan up to date (Mapper::refreshSurfaceScan),
  /// so that the final graph reads only the blocks of the last few frames instead of those of up
  /// to Mapper::kForgetEveryFrames frames (issue 23: 120 ms of the final optimisation on the
  /// 2 cm building). Uses time the worker would spend waiting; changes no result. 0: never.
  int64_t idle_scan_every_frames = Mapper::kIdleScanEveryFrames;
  /// Throws Error naming the bad field.
  void check() const;
};

/// A message for LCM, produced off the LCM thread and published by it (LCM's handle and
/// publish calls stay on one thread).
struct OutgoingMessage {
  std::string channel;
  std::vector<uint8_t> bytes;
};

/// Encodes an LCM message for the outbox.
template <typename Msg>
OutgoingMessage encodeMessage(const std::string& channel, const Msg& msg) {
  OutgoingMessage out{channel, std::vector<uint8_t>(static_cast<size_t>(msg.getEncodedSize()))};
  msg.encode(out.bytes.data(), 0, static_cast<int>(out.bytes.size()));
  return out;
}

/// The live mapper: LCM handlers only copy messages into a bounded queue; a worker thread
/// decodes, synchronises and integrates them through a MappingSession, and runs tasks (save,
/// export, periodic publications) between frames, so the map is only touched by one thread.
class LiveMapper {
 public:
  /// Work run on the worker thread with exclusive access to the mapper.
  using Task = std::function<void(Mapper* mapper)>;
  /// Builds periodic messages on the worker thread (objects, occupancy); may return none.
  /// Labels are the latest optimised ones fitted to the map (fitLabelsToMap), or null.
  using Publisher = std::function<std::vector<OutgoingMessage>(Mapper* mapper, int64_t utime,
                                                               const GraphLabels* labels)>;
  /// Runs a command's file work on the worker thread: COMMAND_SAVE / COMMAND_EXPORT with the
  /// command's argument. Labels are the latest optimised ones, or null. Returns what it did
  /// ("map saved to PATH"), which the status reports; throws Error when it failed.
  using CommandHandler = std::function<std::string(int8_t command, const std::string& argument,
                                                   Mapper* mapper, const GraphLabels* labels)>;

  /// Subscribes on `lcm` (not owned; must outlive this) and starts the worker.
  /// @param mapper the map (not owned); only the worker touches it until stop()
  /// @param hook called on the worker after every integrated frame (e.g. autosave)
  LiveMapper(lcm::LCM* lcm, const LiveOptions& options, Mapper* mapper,
             MappingSession::FrameHook hook = {});
  /// Stops the worker (without draining).
  ~LiveMapper();

  /// Sets what is published every publish_period_s.
  void setPeriodicPublisher(Publisher publisher) { publisher_ = std::move(publisher); }
  /// Publishes messages at once, on the calling thread; after drain() (the final objects and
  /// occupancy, so a planner on the channels gets what the output files hold).
  void publishNow(const std::vector<OutgoingMessage>& messages);
  /// Sets what the status's warnings are (called with each status, on the worker thread):
  /// problems mapping survives that an operator must hear of, e.g. autosaves that fail.
  void setWarningSource(std::function<std::vector<std::string>()> source) {
    warning_source_ = std::move(source);
  }
  /// Sets what save and export commands do.
  void setCommandHandler(CommandHandler handler) { command_handler_ = std::move(handler); }

  /// Handles LCM traffic, status and periodic publications until a finish command arrives or
  /// `stop` becomes true. Returns true when a finish command ended it.
  bool run(const std::atomic<bool>& stop);
  /// Stops taking input, maps everything queued (and what the synchroniser still holds),
  /// and stops the worker. The mapper is then the caller's again.
  void drain();
  /// Publishes the super-point graph and waits for the optimiser's PANMAP_LABELS answer.
  /// Call after drain(). Returns nothing when no answer came within optimiser_timeout_s.
  std::optional<GraphLabels> requestLabels(const std::atomic<bool>& stop);

  /// Counters and timings of the session, with what this process refused itself (malformed
  /// commands, frames that came after finish). Call after drain() (the worker owns them before).
  SessionStats stats() const { return withOwnRejections(session_.stats()); }
  /// The reason RGB-D frames received after a finish command or signal are counted under.
  static constexpr const char* kAfterFinish = "frame: arrived after finish (not mapped)";
  /// RGB-D messages pushed out of the full queue so far.
  int64_t framesDropped() const { return dropped_frames_; }
  /// RGB-D messages received on the input channel so far.
  int64_t framesReceived() const { return received_frames_; }
  /// Copies of the final graph published by requestLabels() (more than one: the optimiser was
  /// slow, down or restarted).
  int64_t graphRequestsSent() const { return graph_requests_sent_; }
  /// Surface-scan refreshes run while the worker was idle (idle_scan_every_frames). Call after
  /// drain().
  int64_t idleScanRefreshes() const { return idle_scan_refreshes_; }
  /// A status message of the current state. Call from the worker, or after drain().
  status_t status(const std::string& state) const;
  /// After drain(), when the final outputs could not be written: keeps the map and serves
  /// PANMAP_COMMAND on this thread (save and export at once, with the final labels; their
  /// results on the status channel, state "finish failed") until a finish command asks to try
  /// again (returns true) or `stop` is set (returns false: the caller gives the map up).
  bool serveCommandsAfterFailedFinish(const std::atomic<bool>& stop);
  /// Reports how the finish command ended (ok: what was written; else why it failed) in a
  /// "done" status, so that `panmap-command finish` returns when the outputs exist. Call after
  /// the outputs were written, whether a command or a signal ended the run.
  void publishFinished(bool ok, const std::string& result);

 private:
  struct Item {
    std::string channel;  ///< empty: a task
    std::vector<uint8_t> bytes;
    Task task;
  };

  void onInput(const lcm::ReceiveBuffer* buffer, const std::string& channel);
  void onCommand(const lcm::ReceiveBuffer* buffer, const std::string& channel);
  void onLabels(const lcm::ReceiveBuffer* buffer, const std::string& channel);
  /// Posts a task that publishes the graph for the optimiser (LCM thread).
  void requestOptimisation();
  /// Runs `use` on the worker with the latest answer fitted to the map, or null (LCM thread).
  void postWithLabels(std::function<void(Mapper*, const GraphLabels*)> use);
  void post(Item item);
  void workerLoop();
  /// Refreshes the surface scan when the queue is empty and enough frames came (worker only).
  void refreshScanIfIdle();
  void publishOutbox();
  void publishStatus(const std::string& state);
  void countRejected(const std::string& reason);
  /// `stats` with this process's own rejections added (any thread).
  SessionStats withOwnRejections(SessionStats stats) const;
  /// Records the state of the command sent at `utime` for the status messages (any thread).
  void setCommandState(int64_t utime, const std::string& state, const std::string& result);

  lcm::LCM* lcm_;
  LiveOptions options_;
  Mapper* mapper_;
  MappingSession session_;
  std::chrono::steady_clock::time_point last_repair_status_{};  // throttles "repairing"
  std::vector<lcm::Subscription*> subscriptions_;
  Publisher publisher_;
  CommandHandler command_handler_;
  std::function<std::vector<std::string>()> warning_source_;

  // Input queue (LCM thread -> worker).
  mutable std::mutex queue_mutex_;
  std::condition_variable queue_cv_;
  std::deque<Item> queue_;
  size_t queued_frames_ = 0;
  bool draining_ = false;
  bool stop_worker_ = false;
  std::thread worker_;

  // Worker -> LCM thread.
  mutable std::mutex outbox_mutex_;
  std::vector<OutgoingMessage> outbox_;

  // Idle work (worker only).
  int64_t scanned_at_frame_ = 0;
  int64_t idle_scan_refreshes_ = 0;
  // Per optimisation request, largestInitialInstance() of the graph it sent (worker only):
  // what fitLabelsToMap() needs to use its answer on the map as it is later (super-points keep
  // their ids through a loop-closure repair, so the answer still names the same surfaces).
  std::map<int64_t, int32_t> graph_instances_;

  std::atomic<int64_t> received_frames_{0};
  std::atomic<int64_t> dropped_frames_{0};
  std::atomic<int64_t> after_finish_frames_{0};  // RGB-D frames that came while draining
  // Commands and labels refused (written by the LCM thread, read by status()).
  mutable std::mutex rejected_mutex_;
  std::map<std::string, int64_t> rejected_commands_;
  bool finish_requested_ = false;      // LCM thread only
  bool serving_after_finish_ = false;  // LCM thread only: serveCommandsAfterFailedFinish()
  bool finish_by_command_ = false;     // LCM thread only: a finish command (not a signal) came
  int64_t finish_command_utime_ = 0;   // LCM thread only: the finish command's utime
  // The newest commands' progress, oldest first (written by the LCM thread and the worker,
  // read by status()): a save still running when the next command comes keeps its own entry.
  struct CommandState {
    int64_t utime = 0;
    std::string state;
    std::string result;
  };
  static constexpr size_t kCommandsReported = 8;
  mutable std::mutex command_mutex_;
  std::deque<CommandState> commands_;

  // Optimiser round trip (LCM thread only).
  int64_t request_base_ = 0;  // request ids above this are ours
  int64_t request_id_ = 0;
  std::optional<GraphLabels> labels_;
  int64_t labels_request_id_ = -1;
  int64_t graph_requests_sent_ = 0;
  // Graph requests sent since the last answer (set on the LCM thread, read by status()): an
  // optimiser that is not running was never mentioned while mapping.
  std::atomic<int64_t> unanswered_requests_{0};
  // While finish() waits for the final labels (main thread, worker gone): what status() says.
  std::string waiting_for_labels_;
};

}  // namespace panmap

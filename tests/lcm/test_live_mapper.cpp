// The live mapper over LCM's in-process memq:// provider: the same map as the session on the
// same messages, a bounded queue that drops (and counts) the oldest frames, status messages,
// commands, the optimiser round trip and its timeout.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <set>

#include "panmap/command_t.hpp"
#include "panmap/graph/optimiser.h"
#include "panmap/lcm/correction_conversions.h"
#include "panmap/lcm/graph_conversions.h"
#include "panmap/lcm/live_mapper.h"
#include "panmap/lcm/optimizer_node.h"
#include "panmap/mapper/final_labels.h"
#include "panmap/mapper/objects.h"
#include "synthetic_stream.h"
#include "test_helpers.h"

namespace panmap {
namespace {

struct StatusInbox {
  std::vector<status_t> received;
  void onStatus(const lcm::ReceiveBuffer*, const std::string&, const status_t* msg) {
    received.push_back(*msg);
  }
};

void publishAll(lcm::LCM* lcm, const std::vector<test::Encoded>& messages) {
  for (const test::Encoded& m : messages) {
    lcm->publish(m.channel, m.bytes.data(), static_cast<unsigned>(m.bytes.size()));
  }
}

void publishCommand(lcm::LCM* lcm, int8_t command, const std::string& argument = "",
                    int64_t utime = 0) {
  command_t msg;
  msg.utime = utime;
  msg.command = command;
  msg.argument = argument;
  lcm->publish("PANMAP_COMMAND", &msg);
}

// A frame store in a folder of its own, for live runs that repair.
struct TempStore {
  static FrameStoreConfig configIn(const test::TempDir& dir) {
    FrameStoreConfig config;
    config.folder = dir.path("store");
    return config;
  }
  test::TempDir dir;
  FrameStore store{configIn(dir)};
};

// A back-end's correction moving keyframe 4 (and so every frame) 5 cm along x.
void publishKeyframeCorrection(lcm::LCM* lcm, const test::SyntheticStream& stream) {
  PoseCorrection correction;
  correction.correction_id = 1;
  StampedPose keyframe = stream.poses[4];
  keyframe.T_W_C.translation() += Eigen::Vector3d(0.05, 0.0, 0.0);
  correction.poses.push_back(keyframe);
  const pose_correction_t msg = toMessage(correction);
  lcm->publish("PANMAP_POSE_CORRECTION", &msg);
}

LiveOptions testOptions() {
  LiveOptions options;
  options.max_queued_frames = 1000;  // no drops: the result must equal the session's
  options.optimiser_timeout_s = 0.5;
  options.publish_period_s = 0.0;
  options.optimise_period_s = 0.0;
  options.request_id_base = 0;  // the first request is 1
  return options;
}

TEST(LiveMapper, MapsLikeTheSessionAndAnswersStatus) {
  const test::SyntheticStream& stream = test::syntheticStream();
  Mapper reference(test::streamMapperConfig());
  {
    MappingSession session(SessionOptions{}, &reference);
    for (const test::Encoded& m : stream.messages()) {
      session.handle(m.channel, m.bytes.data(), m.bytes.size());
    }
    session.flush();
  }

  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  StatusInbox inbox;
  lcm.subscribe("PANMAP_STATUS", &StatusInbox::onStatus, &inbox);
  Mapper mapper(test::streamMapperConfig());
  LiveOptions options = testOptions();
  // The worker refreshes the surface scan whenever it waits (how often depends on timing):
  // the map and the final graph must not depend on it.
  options.idle_scan_every_frames = 1;
  LiveMapper live(&lcm, options, &mapper);
  publishAll(&lcm, stream.messages());
  const uint8_t junk[3] = {9, 9, 9};
  lcm.publish("CAMERA_POSE", junk, sizeof(junk));
  publishCommand(&lcm, command_t::COMMAND_FINISH);
  std::atomic<bool> stop{false};
  EXPECT_TRUE(live.run(stop));  // ended by the finish command
  live.drain();
  while (lcm.handleTimeout(0) > 0) {
  }
  const SessionStats stats = live.stats();
  EXPECT_EQ(stats.frames_integrated, static_cast<int64_t>(stream.frames.size()));
  EXPECT_EQ(live.framesReceived(), static_cast<int64_t>(stream.frames.size()));
  EXPECT_EQ(live.framesDropped(), 0);
  EXPECT_EQ(stats.rejected.at("malformed CAMERA_POSE"), 1);
  EXPECT_EQ(test::mapBytes(mapper), test::mapBytes(reference));
  const SuperpointGraph graph = mapper.graph(), expected = reference.graph();
  ASSERT_EQ(graph.vertices.size(), expected.vertices.size());
  ASSERT_EQ(graph.edges.size(), expected.edges.size());
  for (size_t i = 0; i < graph.vertices.size(); ++i) {
    EXPECT_EQ(graph.vertices[i].num_voxels, expected.vertices[i].num_voxels);
  }
  for (size_t i = 0; i < graph.edges.size(); ++i) {
    EXPECT_EQ(std::tie(graph.edges[i].a, graph.edges[i].b),
              std::tie(expected.edges[i].a, expected.edges[i].b));
  }

  // drain() publishes a "finishing" status with the final counts.
  ASSERT_FALSE(inbox.received.empty());
  const status_t& last = inbox.received.back();
  EXPECT_EQ(last.state, "finishing");
  EXPECT_EQ(last.frames_integrated, static_cast<int64_t>(stream.frames.size()));
  EXPECT_EQ(last.frames_rejected, 1);
  ASSERT_EQ(last.num_reject_reasons, 1);
  EXPECT_EQ(last.reject_reasons[0], "malformed CAMERA_POSE");
  EXPECT_EQ(last.num_superpoints, static_cast<int32_t>(mapper.superpoints().states().size()));
  std::set<int32_t> instances;  // distinct instances held, not the largest id given
  for (const auto& [superpoint, state] : mapper.superpoints().states()) {
    if (state.instance() > 0) instances.insert(state.instance());
  }
  EXPECT_EQ(last.num_instances, static_cast<int32_t>(instances.size()));
  EXPECT_GT(last.num_blocks, 0);
  EXPECT_GT(last.memory_bytes, 0);
  EXPECT_GE(last.num_stages, 5);
  // Ground-truth poses: tracking never ran, so the depth check has nothing to judge.
  EXPECT_EQ(last.depth_check, "pending");
  EXPECT_EQ(last.depth_pattern_mm, -1.0f);
  EXPECT_EQ(last.poses_corrected, 0);
  EXPECT_EQ(last.poses_kept_as_given, 0);
}

// A loop-closure correction over LCM repairs the live map from its frame store, and the
// status says so: "repairing" with its progress while it runs, then the repair's counts.
// A correction over LCM repairs the live map (on the worker, or on a thread of its own beside
// it), and the status channel shows the repair running, then its counts.
void checkLiveRepair(bool background) {
  const test::SyntheticStream& stream = test::syntheticStream();
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  StatusInbox inbox;
  lcm.subscribe("PANMAP_STATUS", &StatusInbox::onStatus, &inbox);
  TempStore stored;
  FrameStore& store = stored.store;
  LiveOptions options = testOptions();
  options.session.frame_store = &store;
  options.session.background_repair = background;
  Mapper mapper(test::streamMapperConfig());
  LiveMapper live(&lcm, options, &mapper);
  publishAll(&lcm, stream.messages());
  publishKeyframeCorrection(&lcm, stream);
  publishCommand(&lcm, command_t::COMMAND_FINISH);
  std::atomic<bool> stop{false};
  EXPECT_TRUE(live.run(stop));
  live.drain();
  while (lcm.handleTimeout(0) > 0) {
  }
  EXPECT_EQ(live.stats().corrections_applied, 1);
  EXPECT_EQ(store.size(), stream.frames.size());
  for (size_t k = 0; k < stream.frames.size(); ++k) {
    const Eigen::Vector3d moved =
        mapper.trajectory()[k].T_W_C.translation() - stream.poses[k].T_W_C.translation();
    EXPECT_NEAR((moved - Eigen::Vector3d(0.05, 0.0, 0.0)).norm(), 0.0, 1e-9) << k;
  }
  bool saw_repairing = false;
  for (const status_t& s : inbox.received) {
    if (s.state != "repairing") continue;
    saw_repairing = true;
    EXPECT_EQ(s.repair_frames_total, static_cast<int64_t>(stream.frames.size()));
  }
  EXPECT_TRUE(saw_repairing);
  const status_t& last = inbox.received.back();
  EXPECT_EQ(last.corrections_applied, 1);
  EXPECT_EQ(last.last_correction_id, 1);
  EXPECT_EQ(last.repair_frames_done, static_cast<int64_t>(stream.frames.size()));
  EXPECT_GT(last.last_repair_s, 0.0f);
}

TEST(LiveMapper, ACorrectionRepairsTheLiveMapAndTheStatusReportsIt) { checkLiveRepair(false); }

TEST(LiveMapper, ABackgroundRepairRepairsTheLiveMapAndTheStatusReportsIt) { checkLiveRepair(true); }

// The optimiser's labels name super-points by id, and a repair that maps the frames again keeps
// the ids of the super-points it finds again: an export after it still uses the labels, fitted
// to the map as it is then (fitLabelsToMap), and they name super-points that are still there.
TEST(LiveMapper, LabelsFromBeforeARemapStillNameTheSuperpointsThatKeptTheirIds) {
  const test::SyntheticStream& stream = test::syntheticStream();
  // The graph the optimisation request will carry: every frame mapped, no correction yet.
  Mapper reference(test::streamMapperConfig());
  for (size_t k = 0; k < stream.frames.size(); ++k) {
    reference.integrate(stream.frames[k], stream.poses[k].T_W_C, &stream.masks[k],
                        stream.poses[k].source);
  }
  const SuperpointGraph graph = reference.graph();
  ASSERT_FALSE(graph.vertices.empty());
  const int32_t largest = largestInitialInstance(graph);
  // Half the super-points keep their frame-count instance, the other half go to one the
  // optimiser made (an id above the graph's).
  GraphLabels labels;
  for (size_t i = 0; i < graph.vertices.size(); ++i) {
    const GraphVertex& v = graph.vertices[i];
    labels.semantic[v.id] = 5;
    labels.instance[v.id] = i % 2 == 0 ? v.instance : largest + 1;
  }
  labels.instance_confidence[largest + 1] = 0.75f;

  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  TempStore stored;
  const test::TempDir& dir = stored.dir;
  LiveOptions options = testOptions();
  options.session.frame_store = &stored.store;
  Mapper mapper(test::streamMapperConfig());
  LiveMapper live(&lcm, options, &mapper);
  std::vector<GraphLabels> exported;
  std::vector<size_t> named_live;  // per export: named super-points live in the map it writes
  live.setCommandHandler(
      [&](int8_t command, const std::string&, Mapper* m, const GraphLabels* given) {
        EXPECT_EQ(command, +command_t::COMMAND_EXPORT);
        if (given == nullptr) {
          ADD_FAILURE() << "an export without labels";
          return std::string();
        }
        exported.push_back(*given);
        named_live.push_back(0);
        for (const auto& entry : given->instance) {
          named_live.back() += m->superpoints().states().count(entry.first);
        }
        // What the export got is the answer fitted to the map it writes.
        const GraphLabels fitted = fitLabelsToMap(labels, largest, m->superpoints());
        EXPECT_EQ(given->instance, fitted.instance);
        EXPECT_EQ(given->instance_confidence, fitted.instance_confidence);
        return std::string("exported");
      });
  publishAll(&lcm, stream.messages());
  publishCommand(&lcm, command_t::COMMAND_OPTIMISE);  // request 1
  // The optimiser's answer to request 1 (handled after the command, as the bus orders them).
  const graph_labels_t answer = toMessage(labels, 0, 1);
  lcm.publish("PANMAP_LABELS", &answer);
  publishCommand(&lcm, command_t::COMMAND_EXPORT, dir.path("before"));
  publishKeyframeCorrection(&lcm, stream);
  publishCommand(&lcm, command_t::COMMAND_EXPORT, dir.path("after"));
  publishCommand(&lcm, command_t::COMMAND_FINISH);
  std::atomic<bool> stop{false};
  EXPECT_TRUE(live.run(stop));
  live.drain();
  ASSERT_EQ(live.stats().corrections_applied, 1);
  ASSERT_TRUE(mapper.trajectory().back().T_W_C.isApprox(Eigen::Translation3d(0.05, 0.0, 0.0) *
                                                        stream.poses.back().T_W_C));
  ASSERT_EQ(exported.size(), 2u);
  // Before the repair the map is the graph's: every named super-point is live.
  EXPECT_EQ(named_live[0], graph.vertices.size());
  // After it, those that kept their ids are still named.
  EXPECT_GT(named_live[1], 0u);
  EXPECT_LE(named_live[1], graph.vertices.size());
  // The repair numbered the instances it did not pair above the graph's largest: the one the
  // optimiser made moved above them (checked against fitLabelsToMap in the handler).
  EXPECT_NE(exported[1].instance, labels.instance);
}

// With optimise_period_s the mapper sends its graph to the optimiser while it maps, and
// PANMAP_OBJECTS carries the objects of the latest answer (fragments folded, calibrated
// confidences): once every frame is in, those of the labels the optimiser gives the final graph.
TEST(LiveMapper, PeriodicObjectsUseTheOptimisersLatestAnswer) {
  const test::SyntheticStream& stream = test::syntheticStream();
  const int64_t n = static_cast<int64_t>(stream.frames.size());
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  LiveOptions options = testOptions();
  options.optimise_period_s = 0.02;
  options.publish_period_s = 0.02;
  Mapper mapper(test::streamMapperConfig());
  LiveMapper live(&lcm, options, &mapper);
  OptimizerNode optimiser(&lcm, OptimizerNode::Config{});
  std::atomic<bool> stop{false};
  int publications = 0, with_labels = 0;
  bool matched = false;
  std::vector<MappedObject> published, frame_count;
  live.setPeriodicPublisher([&](Mapper* m, int64_t, const GraphLabels* labels) {
    // A bound on the wait, in publications, should the answer never come.
    if (++publications >= 2000) stop = true;
    with_labels += labels != nullptr;
    if (!labels || matched || m->framesIntegrated() < n) return std::vector<OutgoingMessage>{};
    const SuperpointGraph graph = m->graph();
    const GraphLabels expected = fitLabelsToMap(optimise(graph, OptimiserConfig{}),
                                                largestInitialInstance(graph), m->superpoints());
    if (labels->instance == expected.instance && labels->semantic == expected.semantic &&
        labels->instance_confidence == expected.instance_confidence) {
      matched = true;
      published = computeObjects(*m, labels);
      frame_count = computeObjects(*m, nullptr);
      stop = true;
    }
    return std::vector<OutgoingMessage>{};
  });
  publishAll(&lcm, stream.messages());
  EXPECT_FALSE(live.run(stop));  // ended by `stop`, not a finish command
  live.drain();
  ASSERT_TRUE(matched) << publications << " publications, " << with_labels << " with labels";
  EXPECT_EQ(mapper.framesIntegrated(), n);
  ASSERT_FALSE(published.empty());
  // Not the frame-count objects: the optimiser's confidences are calibrated (on this stream the
  // instances are the same five).
  std::vector<float> calibrated, counted;
  for (const MappedObject& o : published) calibrated.push_back(o.confidence);
  for (const MappedObject& o : frame_count) counted.push_back(o.confidence);
  EXPECT_NE(calibrated, counted);
  const GraphLabels final_labels = optimise(mapper.graph(), OptimiserConfig{});
  const std::vector<MappedObject> final_objects = computeObjects(mapper, &final_labels);
  ASSERT_EQ(published.size(), final_objects.size());
  for (size_t i = 0; i < published.size(); ++i) {
    EXPECT_EQ(published[i].id, final_objects[i].id);
    EXPECT_EQ(published[i].class_id, final_objects[i].class_id);
    EXPECT_EQ(published[i].num_voxels, final_objects[i].num_voxels);
    EXPECT_EQ(published[i].confidence, final_objects[i].confidence);
  }
}

TEST(LiveMapper, FullQueueDropsTheOldestFramesAndCountsThem) {
  const test::SyntheticStream& stream = test::syntheticStream();
  lcm::LCM lcm("memq://");
  Mapper mapper(test::streamMapperConfig());
  LiveOptions options = testOptions();
  options.max_queued_frames = 1;
  LiveMapper live(&lcm, options, &mapper);
  publishAll(&lcm, stream.messages());
  publishCommand(&lcm, command_t::COMMAND_FINISH);
  std::atomic<bool> stop{false};
  live.run(stop);
  live.drain();
  const SessionStats stats = live.stats();
  const int64_t n = static_cast<int64_t>(stream.frames.size());
  // Every frame is accounted for: integrated or dropped, none silently lost.
  EXPECT_EQ(live.framesReceived(), n);
  EXPECT_EQ(stats.frames_integrated + live.framesDropped(), n);
  EXPECT_GE(stats.frames_integrated, 1);
  // The dropped frames' masks go with them, not among masks that matched no frame.
  EXPECT_GT(live.framesDropped(), 0);
  EXPECT_EQ(stats.sync.panoptic_of_skipped_frames, live.framesDropped());
  EXPECT_EQ(stats.sync.unmatched_panoptic, 0);
}

TEST(LiveMapper, OptimiserAnswersAndItsAbsenceTimesOut) {
  const test::SyntheticStream& stream = test::syntheticStream();
  std::atomic<bool> stop{false};
  {
    lcm::LCM lcm("memq://");
    Mapper mapper(test::streamMapperConfig());
    LiveMapper live(&lcm, testOptions(), &mapper);
    OptimizerNode optimiser(&lcm, OptimizerNode::Config{});
    publishAll(&lcm, stream.messages());
    publishCommand(&lcm, command_t::COMMAND_FINISH);
    live.run(stop);
    live.drain();
    const std::optional<GraphLabels> labels = live.requestLabels(stop);
    ASSERT_TRUE(labels.has_value());
    EXPECT_EQ(optimiser.answered(), 1);
    EXPECT_EQ(labels->semantic.size(), mapper.graph().vertices.size());
    EXPECT_FALSE(labels->semantic.empty());
  }
  {
    // No optimiser on the bus (or one killed mid-run): no labels, the map stays intact.
    lcm::LCM lcm("memq://");
    Mapper mapper(test::streamMapperConfig());
    LiveMapper live(&lcm, testOptions(), &mapper);
    publishAll(&lcm, stream.messages());
    publishCommand(&lcm, command_t::COMMAND_FINISH);
    live.run(stop);
    live.drain();
    EXPECT_FALSE(live.requestLabels(stop).has_value());
    EXPECT_EQ(mapper.framesIntegrated(), static_cast<int64_t>(stream.frames.size()));
  }
}

TEST(LiveMapper, SaveCommandRunsOnTheWorkerAndMappingGoesOn) {
  const test::SyntheticStream& stream = test::syntheticStream();
  const std::vector<test::Encoded> messages = stream.messages();
  test::TempDir dir;
  lcm::LCM lcm("memq://");
  Mapper mapper(test::streamMapperConfig());
  LiveMapper live(&lcm, testOptions(), &mapper);
  std::vector<std::string> saved;
  live.setCommandHandler(
      [&](int8_t command, const std::string& argument, Mapper* m, const GraphLabels*) {
        EXPECT_EQ(command, +command_t::COMMAND_SAVE);
        m->save(argument);
        saved.push_back(argument);
        return "saved " + argument;
      });
  StatusInbox inbox;
  lcm.subscribe("PANMAP_STATUS", &StatusInbox::onStatus, &inbox);
  // Half the stream, a save, the rest: the snapshot holds exactly the first half.
  const size_t half = messages.size() / 2 / 3 * 3;
  publishAll(&lcm, {messages.begin(), messages.begin() + half});
  publishCommand(&lcm, command_t::COMMAND_SAVE, dir.path("half.panmap"), 11);
  // A save that cannot be written: mapping goes on, and the status says why (utime 12).
  publishCommand(&lcm, command_t::COMMAND_SAVE, dir.path("none/x.panmap"), 12);
  publishAll(&lcm, {messages.begin() + half, messages.end()});
  publishCommand(&lcm, 42);  // unknown: counted, ignored
  publishCommand(&lcm, command_t::COMMAND_FINISH);
  std::atomic<bool> stop{false};
  live.run(stop);
  live.drain();
  while (lcm.handleTimeout(0) > 0) {
  }
  // Each command's result reaches the status channel as soon as it is known.
  std::map<int64_t, std::pair<std::string, std::string>> results;
  for (const status_t& st : inbox.received) {
    for (int i = 0; i < st.num_commands; ++i) {
      if (st.command_states[i] != "running") {
        results[st.command_utimes[i]] = {st.command_states[i], st.command_results[i]};
      }
    }
  }
  ASSERT_EQ(results.count(11), 1u);
  EXPECT_EQ(results[11].first, "done");
  EXPECT_EQ(results[11].second, "saved " + dir.path("half.panmap"));
  ASSERT_EQ(results.count(12), 1u);
  EXPECT_EQ(results[12].first, "failed");
  EXPECT_NE(results[12].second.find("x.panmap"), std::string::npos) << results[12].second;
  // The finish command (utime 0) after them, still running, keeps its own entry.
  const status_t finished = live.status("finishing");
  EXPECT_EQ(finished.command_utimes, (std::vector<int64_t>{11, 12, 0}));
  EXPECT_EQ(finished.command_states, (std::vector<std::string>{"done", "failed", "running"}));

  ASSERT_EQ(saved.size(), 1u);
  const std::unique_ptr<Mapper> snapshot = Mapper::load(dir.path("half.panmap"));
  // The synchroniser may hold the newest frame back until its mask and pose are in.
  EXPECT_GE(snapshot->framesIntegrated(), static_cast<int64_t>(half / 3) - 1);
  EXPECT_LE(snapshot->framesIntegrated(), static_cast<int64_t>(half / 3));
  EXPECT_EQ(mapper.framesIntegrated(), static_cast<int64_t>(stream.frames.size()));
  EXPECT_EQ(live.status("done").frames_rejected, 1);
}

// Frames that came after the finish command were counted as received and then neither mapped,
// dropped nor refused (48 of 85 in a replay finished part way).
TEST(LiveMapper, FramesAfterFinishAreCountedNotLost) {
  const test::SyntheticStream& stream = test::syntheticStream();
  const std::vector<test::Encoded> messages = stream.messages();
  lcm::LCM lcm("memq://");
  Mapper mapper(test::streamMapperConfig());
  LiveMapper live(&lcm, testOptions(), &mapper);
  const size_t half = messages.size() / 2 / 3 * 3;
  publishAll(&lcm, {messages.begin(), messages.begin() + half});
  publishCommand(&lcm, command_t::COMMAND_FINISH);
  publishAll(&lcm, {messages.begin() + half, messages.end()});
  std::atomic<bool> stop{false};
  EXPECT_TRUE(live.run(stop));
  live.drain();
  while (lcm.handleTimeout(0) > 0) {  // what comes while the outputs are made
  }
  const SessionStats stats = live.stats();
  int64_t rejected = 0;
  for (const auto& [reason, n] : stats.rejected) rejected += n;
  EXPECT_EQ(live.framesReceived(), static_cast<int64_t>(stream.frames.size()));
  EXPECT_EQ(stats.rejected.at(LiveMapper::kAfterFinish),
            static_cast<int64_t>(stream.frames.size() - half / 3));
  // Every frame received is mapped, dropped or refused with a reason.
  EXPECT_EQ(stats.frames_integrated + live.framesDropped() + rejected, live.framesReceived());
  EXPECT_EQ(live.status("done").frames_rejected, rejected);
}

// No optimiser on the bus: the status said nothing while mapping and went silent for the whole
// wait at the end. Two requests without an answer, and every resend at the end, are named.
TEST(LiveMapper, AnOptimiserThatDoesNotAnswerIsNamedOnTheStatus) {
  const test::SyntheticStream& stream = test::syntheticStream();
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  StatusInbox inbox;
  lcm.subscribe("PANMAP_STATUS", &StatusInbox::onStatus, &inbox);
  LiveOptions options = testOptions();
  options.optimiser_retry_s = 0.1;
  Mapper mapper(test::streamMapperConfig());
  LiveMapper live(&lcm, options, &mapper);
  publishAll(&lcm, stream.messages());
  publishCommand(&lcm, command_t::COMMAND_OPTIMISE);
  EXPECT_EQ(live.status("mapping").num_warnings, 0);
  publishCommand(&lcm, command_t::COMMAND_OPTIMISE);
  publishCommand(&lcm, command_t::COMMAND_FINISH);
  std::atomic<bool> stop{false};
  EXPECT_TRUE(live.run(stop));
  live.drain();
  const status_t mapping = live.status("mapping");
  ASSERT_EQ(mapping.num_warnings, 1);
  EXPECT_NE(mapping.warnings[0].find("optimiser: no answer to the last 2 graph requests on "
                                     "PANMAP_GRAPH (is panmap-optimizer running"),
            std::string::npos)
      << mapping.warnings[0];
  inbox.received.clear();
  EXPECT_FALSE(live.requestLabels(stop).has_value());
  while (lcm.handleTimeout(0) > 0) {
  }
  int waiting = 0;
  for (const status_t& s : inbox.received) {
    for (const std::string& w : s.warnings) {
      waiting += w.find("optimiser: no answer to the final graph after") != std::string::npos;
    }
  }
  EXPECT_GE(waiting, 1);  // resent every 0.1 s for 0.5 s: each resend says so
}

TEST(LiveMapper, TheStatusCarriesTheWarningsOfItsSource) {
  lcm::LCM lcm("memq://");
  Mapper mapper(test::streamMapperConfig());
  LiveMapper live(&lcm, testOptions(), &mapper);
  EXPECT_EQ(live.status("mapping").num_warnings, 0);
  live.setWarningSource(
      [] { return std::vector<std::string>{"autosave: the last snapshot failed"}; });
  const status_t status = live.status("mapping");
  EXPECT_EQ(status.num_warnings, 1);
  EXPECT_EQ(status.warnings, std::vector<std::string>{"autosave: the last snapshot failed"});
}

TEST(LiveMapper, RefusesBadOptionsNamingThem) {
  LiveOptions options = testOptions();
  options.idle_scan_every_frames = -1;
  try {
    options.check();
    FAIL() << "a negative idle_scan_every_frames was accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("idle_scan_every_frames"), std::string::npos) << e.what();
  }
  options.idle_scan_every_frames = 0;  // never: valid
  EXPECT_NO_THROW(options.check());
  options.optimise_period_s = -1.0;
  EXPECT_THROW(options.check(), Error);
  options.optimise_period_s = 0.0;
  options.request_id_base = -2;
  EXPECT_THROW(options.check(), Error);
}

// An optimiser answers every graph on the bus: an answer to another mapper's request (its ids
// count from its own base) is not taken for one of ours.
TEST(LiveMapper, AnswersToAnotherMappersRequestsAreIgnored) {
  const test::SyntheticStream& stream = test::syntheticStream();
  lcm::LCM lcm("memq://");
  ASSERT_TRUE(lcm.good());
  LiveOptions options = testOptions();
  options.request_id_base = 1000;
  Mapper mapper(test::streamMapperConfig());
  LiveMapper live(&lcm, options, &mapper);
  std::vector<bool> exported_with_labels;
  live.setCommandHandler([&](int8_t, const std::string&, Mapper*, const GraphLabels* labels) {
    exported_with_labels.push_back(labels != nullptr);
    return std::string("exported");
  });
  GraphLabels labels;
  labels.semantic[1] = 5;
  publishAll(&lcm, stream.messages());
  publishCommand(&lcm, command_t::COMMAND_OPTIMISE);       // request 1001
  const graph_labels_t foreign = toMessage(labels, 0, 1);  // another mapper's first request
  lcm.publish("PANMAP_LABELS", &foreign);
  publishCommand(&lcm, command_t::COMMAND_EXPORT);
  const graph_labels_t ours = toMessage(labels, 0, 1001);
  lcm.publish("PANMAP_LABELS", &ours);
  publishCommand(&lcm, command_t::COMMAND_EXPORT);
  publishCommand(&lcm, command_t::COMMAND_FINISH);
  std::atomic<bool> stop{false};
  EXPECT_TRUE(live.run(stop));
  live.drain();
  EXPECT_EQ(exported_with_labels, (std::vector<bool>{false, true}));
}

}  // namespace
}  // namespace panmap

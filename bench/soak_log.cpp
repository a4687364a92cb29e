// panmap-bench-soak-log: turns a short log into a long one for the soak test
// (scripts/bench/soak.py): the log is repeated with its timestamps shifted past the previous
// repetition (a fresh stream, not a replay the mapper would refuse), and garbage is injected
// every N events: random bytes, messages of another type, truncated copies, NaN poses,
// repeated messages and late (out-of-order) frames. A JSON summary gives, per rejection reason
// the mapper reports, how many it must count.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "panmap/core/error.h"
#include "panmap/core/progress.h"
#include "panmap/lcm/decode.h"
#include "panmap/lcm/log_writer.h"
#include "panmap/panoptic_t.hpp"
#include "panmap/pose_t.hpp"
#include "panmap/rgbd_frame_t.hpp"

namespace {

struct Event {
  std::string channel;
  int64_t timestamp = 0;
  std::vector<uint8_t> bytes;
};

const char* const kInputs[] = {"CAMERA_RGBD", "CAMERA_POSE", "PANOPTIC"};

template <typename Msg>
std::vector<uint8_t> encode(const Msg& msg) {
  std::vector<uint8_t> out(static_cast<size_t>(msg.getEncodedSize()));
  msg.encode(out.data(), 0, static_cast<int>(out.size()));
  return out;
}

// The event with every utime inside shifted by `shift_us`.
std::vector<uint8_t> shifted(const Event& e, int64_t shift_us) {
  if (e.channel == "CAMERA_RGBD") {
    panmap::rgbd_frame_t m;
    if (!panmap::decodeExactly(e.bytes.data(), e.bytes.size(), &m))
      throw panmap::Error("bad frame");
    m.utime += shift_us;
    return encode(m);
  }
  if (e.channel == "CAMERA_POSE") {
    panmap::pose_t m;
    if (!panmap::decodeExactly(e.bytes.data(), e.bytes.size(), &m)) throw panmap::Error("bad pose");
    m.utime += shift_us;
    return encode(m);
  }
  panmap::panoptic_t m;
  if (!panmap::decodeExactly(e.bytes.data(), e.bytes.size(), &m)) throw panmap::Error("bad mask");
  m.utime += shift_us;
  return encode(m);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Repeat a log with shifted timestamps until it has N frames, injecting garbage."};
  std::string in_path, out_path, summary_path;
  int64_t frames = 10000;
  int garbage_every = 50;
  uint64_t seed = 1;
  app.add_option("input", in_path, "log with CAMERA_RGBD, CAMERA_POSE, PANOPTIC")->required();
  app.add_option("output", out_path, "long log to write")->required();
  app.add_option("--frames", frames, "frames in the output")->capture_default_str();
  app.add_option("--garbage-every", garbage_every, "one garbage event per N real ones (0: none)")
      ->capture_default_str();
  app.add_option("--seed", seed, "garbage seed")->capture_default_str();
  app.add_option("--summary", summary_path, "JSON summary (default: OUTPUT.json)");
  CLI11_PARSE(app, argc, argv);
  if (summary_path.empty()) summary_path = out_path + ".json";
  try {
    std::vector<Event> events;
    {
      lcm::LogFile log(in_path, "r");
      if (!log.good()) throw panmap::Error("cannot read " + in_path);
      while (const lcm::LogEvent* e = log.readNextEvent()) {
        const auto* p = static_cast<const uint8_t*>(e->data);
        events.push_back({e->channel, e->timestamp, std::vector<uint8_t>(p, p + e->datalen)});
      }
    }
    int64_t per_loop = 0;
    for (const Event& e : events) per_loop += e.channel == "CAMERA_RGBD";
    if (per_loop == 0 || events.size() < 2) throw panmap::Error(in_path + ": no frames");
    // One repetition lasts the log's span plus one frame interval.
    const int64_t span = events.back().timestamp - events.front().timestamp;
    const int64_t period = span + span / std::max<int64_t>(1, per_loop - 1);

    std::mt19937_64 rng(seed);
    panmap::LogWriter out(out_path);
    std::map<std::string, int64_t> expected;  // rejection reason -> count
    int64_t written_frames = 0, real_events = 0, garbage = 0;
    Event previous;                    // the last real event written (re-stamped)
    std::vector<Event> recent_frames;  // re-stamped frames, for late copies
    panmap::ProgressLine progress("soak log", "frames", true);
    for (int64_t loop = 0; written_frames < frames; ++loop) {
      const int64_t shift = loop * period;
      for (const Event& e : events) {
        if (written_frames >= frames) break;
        Event now{e.channel, e.timestamp + shift, shifted(e, shift)};
        out.writeRaw(now.channel, now.timestamp, now.bytes.data(), now.bytes.size());
        ++real_events;
        if (now.channel == "CAMERA_RGBD") {
          ++written_frames;
          recent_frames.push_back(now);
          if (recent_frames.size() > 60) recent_frames.erase(recent_frames.begin());
          progress.update(static_cast<size_t>(written_frames), static_cast<size_t>(frames));
        }
        previous = now;
        if (garbage_every <= 0 || real_events % garbage_every != 0) continue;
        const int kind = static_cast<int>(garbage++ % 6);
        const int64_t t = now.timestamp;
        if (kind == 0) {
          std::vector<uint8_t> junk(rng() % 513);
          for (uint8_t& b : junk) b = static_cast<uint8_t>(rng());
          const std::string channel = kInputs[rng() % 3];
          out.writeRaw(channel, t, junk.data(), junk.size());
          ++expected["malformed " + channel];
        } else if (kind == 1 || kind == 2) {
          // Another type on the frame channel, or a frame cut short: malformed frames.
          std::vector<uint8_t> bytes = kind == 1 ? encode(panmap::pose_t()) : previous.bytes;
          if (kind == 2) bytes.resize(bytes.size() / 2);
          out.writeRaw("CAMERA_RGBD", t, bytes.data(), bytes.size());
          ++expected["malformed CAMERA_RGBD"];
        } else if (kind == 3) {
          panmap::pose_t nan_pose;
          nan_pose.utime = t;
          nan_pose.frame_id = -1;
          nan_pose.position[0] = std::numeric_limits<double>::quiet_NaN();
          nan_pose.position[1] = nan_pose.position[2] = 0.0;
          nan_pose.orientation[0] = 1.0;
          nan_pose.orientation[1] = nan_pose.orientation[2] = nan_pose.orientation[3] = 0.0;
          nan_pose.source = panmap::pose_t::SOURCE_GROUND_TRUTH;
          const std::vector<uint8_t> bytes = encode(nan_pose);
          out.writeRaw("CAMERA_POSE", t, bytes.data(), bytes.size());
          ++expected["bad CAMERA_POSE"];  // the reason's first words; the rest names the field
        } else if (kind == 4) {
          // A mask repeated after its frame was mapped (synth logs send frame, pose, mask) is
          // late rather than a duplicate of one still held.
          out.writeRaw(previous.channel, t, previous.bytes.data(), previous.bytes.size());
          ++expected[previous.channel == "CAMERA_RGBD"   ? "frame: repeated timestamp"
                     : previous.channel == "CAMERA_POSE" ? "pose: repeated timestamp"
                                                         : "panoptic: frame already mapped"];
        } else if (recent_frames.size() >= 45) {
          const Event& late = recent_frames[recent_frames.size() - 45];  // 1.5 s old at 30 Hz
          out.writeRaw(late.channel, t, late.bytes.data(), late.bytes.size());
          ++expected["frame: out of order"];
        } else {
          --garbage;  // nothing old enough yet
        }
      }
    }
    progress.finish();
    nlohmann::json summary = {{"frames", written_frames},
                              {"real_events", real_events},
                              {"garbage_events", garbage},
                              {"loop_period_us", period},
                              {"expected_rejections", expected}};
    std::ofstream(summary_path) << summary.dump(2) << "\n";
    std::printf("wrote %s: %lld frames, %lld garbage events; summary %s\n", out_path.c_str(),
                static_cast<long long>(written_frames), static_cast<long long>(garbage),
                summary_path.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-bench-soak-log: error: %s\n", e.what());
    return 1;
  }
  return 0;
}

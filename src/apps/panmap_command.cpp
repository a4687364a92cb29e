// panmap-command: sends one PANMAP_COMMAND to a running panmap-mapper (finish, save, export,
// optimise), e.g. at the end of an lcm-logplayer replay, and waits for the mapper's status that
// reports the command's result (finish: the outputs written); `status` prints the mapper's
// next PANMAP_STATUS as one JSON line (for scripts and monitoring).
#include <chrono>
#include <cstdio>
#include <map>
#include <optional>
#include <utility>

#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "panmap/command_t.hpp"
#include "panmap/lcm/channels.h"
#include "panmap/lcm/decode.h"
#include "panmap/status_t.hpp"

namespace {

struct Echo {
  int received = 0;
  void onMessage(const lcm::ReceiveBuffer*, const std::string&) { ++received; }
};

// True when a message published on the URL reaches a subscriber of this process.
bool selfTest(const std::string& url) {
  lcm::LCM lcm(url);
  if (!lcm.good()) return false;
  Echo echo;
  lcm.subscribe("PANMAP_SELF_TEST", &Echo::onMessage, &echo);
  const uint8_t probe[4] = {1, 2, 3, 4};
  for (int attempt = 0; attempt < 3 && echo.received == 0; ++attempt) {
    lcm.publish("PANMAP_SELF_TEST", probe, sizeof(probe));
    lcm.handleTimeout(300);
  }
  return echo.received > 0;
}

nlohmann::json statusJson(const panmap::status_t& s) {
  nlohmann::json rejected = nlohmann::json::object(), stages = nlohmann::json::object();
  for (int i = 0; i < s.num_reject_reasons; ++i) rejected[s.reject_reasons[i]] = s.reject_counts[i];
  for (int i = 0; i < s.num_stages; ++i) {
    stages[s.stage_names[i]] = {{"median_ms", s.stage_median_ms[i]},
                                {"last_ms", s.stage_last_ms[i]}};
  }
  nlohmann::json commands = nlohmann::json::array();
  for (int i = 0; i < s.num_commands; ++i) {
    commands.push_back({{"utime", s.command_utimes[i]},
                        {"state", s.command_states[i]},
                        {"result", s.command_results[i]}});
  }
  return {{"utime", s.utime},
          {"state", s.state},
          {"frames_received", s.frames_received},
          {"frames_integrated", s.frames_integrated},
          {"frames_dropped", s.frames_dropped},
          {"frames_rejected", s.frames_rejected},
          {"rejected", rejected},
          {"stages", stages},
          {"memory_bytes", s.memory_bytes},
          {"num_blocks", s.num_blocks},
          {"num_voxels", s.num_voxels},
          {"num_superpoints", s.num_superpoints},
          {"num_instances", s.num_instances},
          {"vote_evictions", s.vote_evictions},
          {"corrections_applied", s.corrections_applied},
          {"last_correction_id", s.last_correction_id},
          {"repair_frames_done", s.repair_frames_done},
          {"repair_frames_total", s.repair_frames_total},
          {"last_repair_s", s.last_repair_s},
          {"poses_corrected", s.poses_corrected},
          {"poses_kept_as_given", s.poses_kept_as_given},
          {"depth_check", s.depth_check},
          {"depth_pattern_mm", s.depth_pattern_mm},
          {"warnings", s.warnings},
          {"commands", commands}};
}

// What a status says about one command.
struct CommandProgress {
  std::string state;   ///< "running", "done" or "failed"
  std::string result;  ///< what it did, or why it failed
  std::string mapper_state;
  int64_t frames_integrated = 0;
};

struct StatusCatcher {
  std::optional<panmap::status_t> received;  ///< the newest status
  int64_t command_utime = -1;                ///< the command whose state is followed
  std::optional<CommandProgress> about;      ///< the newest status's word on that command
  int malformed = 0;
  void onMessage(const lcm::ReceiveBuffer* buffer, const std::string&) {
    panmap::status_t msg;
    if (!panmap::decodeExactly(buffer->data, buffer->data_size, &msg)) {
      ++malformed;
      return;
    }
    received = msg;
    for (int i = 0; i < msg.num_commands; ++i) {
      if (msg.command_utimes[i] == command_utime) {
        about = CommandProgress{msg.command_states[i], msg.command_results[i], msg.state,
                                msg.frames_integrated};
      }
    }
  }
  bool finished() const { return about && (about->state == "done" || about->state == "failed"); }
};

// Handles messages until `until()` holds or `timeout_s` has passed.
template <typename Until>
void waitForStatus(lcm::LCM* lcm, double timeout_s, Until until) {
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::milliseconds(static_cast<int64_t>(timeout_s * 1000));
  while (!until() && std::chrono::steady_clock::now() < deadline) {
    lcm->handleTimeout(100);
  }
}

// Waits for one status message; prints it as JSON. 0 when one came, 1 otherwise.
int printStatus(lcm::LCM* lcm, const std::string& channel, double timeout_s) {
  StatusCatcher catcher;
  lcm->subscribe(channel, &StatusCatcher::onMessage, &catcher);
  waitForStatus(lcm, timeout_s, [&] { return catcher.received.has_value(); });
  if (!catcher.received) {
    std::fprintf(stderr, "panmap-command: error: no status on %s within %.1f s%s\n",
                 channel.c_str(), timeout_s, catcher.malformed ? " (only malformed messages)" : "");
    return 1;
  }
  std::printf("%s\n", statusJson(*catcher.received)
                          .dump(-1, ' ', false, nlohmann::json::error_handler_t::replace)
                          .c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Sends a command to panmap-mapper on PANMAP_COMMAND: finish (optimise, write the "
      "outputs, exit), save [PATH] (map snapshot), export [DIR] (outputs now), optimise; or "
      "status: print the mapper's next PANMAP_STATUS as one JSON line. A command returns when "
      "the mapper's status reports its result (finish: when the outputs are written): exit 1 "
      "when it failed, or when no mapper status comes (none listening)."};
  std::string url, channel = panmap::kChannelCommand, command, argument;
  bool self_test = false;
  app.add_option("command", command, "finish | save | export | optimise | status");
  double timeout_s = 5.0;
  std::string status_channel = panmap::kChannelStatus;
  app.add_option("--timeout-s", timeout_s,
                 "how long to wait for the mapper's status that shows it took the command")
      ->capture_default_str();
  double result_timeout_s = 3600.0;
  app.add_option("--result-timeout-s", result_timeout_s,
                 "how long to wait after that for the command's result (finish optimises and "
                 "writes every output)")
      ->capture_default_str();
  bool no_wait = false, quiet = false;
  app.add_flag("-q,--quiet", quiet, "no line while waiting for the result");
  app.add_flag("--no-wait", no_wait,
               "send the command and exit 0 without waiting for a status that shows a mapper "
               "listening");
  app.add_option("--channel-status", status_channel)->capture_default_str();
  app.add_flag("--self-test", self_test,
               "send nothing; exit 0 when a message published on the URL comes back (UDP "
               "multicast works), 1 otherwise");
  app.add_option("argument", argument, "save: snapshot path; export: output folder");
  app.add_option("--lcm-url", url, "LCM URL (default: LCM_DEFAULT_URL or LCM's own)");
  app.add_option("--channel", channel)->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (self_test) return selfTest(url) ? 0 : 1;
  const std::map<std::string, int8_t> commands = {
      {"finish", panmap::command_t::COMMAND_FINISH},
      {"save", panmap::command_t::COMMAND_SAVE},
      {"export", panmap::command_t::COMMAND_EXPORT},
      {"optimise", panmap::command_t::COMMAND_OPTIMISE},
      {"optimize", panmap::command_t::COMMAND_OPTIMISE}};
  const auto it = commands.find(command);
  if (command == "status") {
    lcm::LCM lcm(url);
    if (!lcm.good()) {
      std::fprintf(stderr, "panmap-command: error: cannot open LCM URL '%s'\n", url.c_str());
      return 1;
    }
    return printStatus(&lcm, status_channel, timeout_s);
  }
  if (command.empty()) {
    std::fprintf(stderr, "panmap-command: error: a command is required (see --help)\n");
    return 2;
  }
  if (it == commands.end()) {
    std::fprintf(stderr,
                 "panmap-command: error: unknown command '%s' (finish, save, export, "
                 "optimise, status)\n",
                 command.c_str());
    return 2;
  }
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    std::fprintf(stderr, "panmap-command: error: cannot open LCM URL '%s'\n", url.c_str());
    return 1;
  }
  panmap::command_t msg;
  msg.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                  std::chrono::system_clock::now().time_since_epoch())
                  .count();
  msg.command = it->second;
  msg.argument = argument;
  // Subscribed before sending: a finishing mapper publishes its status at once, then exits.
  StatusCatcher catcher;
  catcher.command_utime = msg.utime;
  if (!no_wait) lcm.subscribe(status_channel, &StatusCatcher::onMessage, &catcher);
  if (lcm.publish(channel, &msg) != 0) {
    std::fprintf(stderr, "panmap-command: error: publishing on %s failed\n", channel.c_str());
    return 1;
  }
  if (no_wait) return 0;
  // LCM publishes whether or not anyone listens: only a mapper's status shows that one does.
  waitForStatus(&lcm, timeout_s, [&] { return catcher.about.has_value(); });
  if (!catcher.about) {
    if (catcher.received) {
      std::fprintf(stderr,
                   "panmap-command: error: sent %s on %s; panmap-mapper is %s but its status "
                   "within %.1f s does not show the command taken (lost on the way, or another "
                   "--channel)\n",
                   command.c_str(), channel.c_str(), catcher.received->state.c_str(), timeout_s);
    } else {
      std::fprintf(stderr,
                   "panmap-command: error: sent %s on %s, but no panmap-mapper status came on %s "
                   "within %.1f s: is a mapper running on this LCM URL? (--self-test checks "
                   "multicast, --no-wait only sends)\n",
                   command.c_str(), channel.c_str(), status_channel.c_str(), timeout_s);
    }
    return 1;
  }
  if (!catcher.finished() && !quiet) {
    std::fprintf(stderr, "panmap-command: %s: %s\n", command.c_str(),
                 catcher.about->result.c_str());
  }
  waitForStatus(&lcm, result_timeout_s, [&] { return catcher.finished(); });
  if (!catcher.finished()) {
    std::fprintf(stderr,
                 "panmap-command: error: %s taken by panmap-mapper, but no result within %.0f s "
                 "(last state: %s)\n",
                 command.c_str(), result_timeout_s, catcher.about->state.c_str());
    return 1;
  }
  const CommandProgress& done = *catcher.about;
  if (done.state == "failed") {
    std::fprintf(stderr, "panmap-command: error: %s failed: %s\n", command.c_str(),
                 done.result.c_str());
    return 1;
  }
  std::printf("panmap-command: %s: %s; panmap-mapper is %s, %lld frames integrated by this run\n",
              command.c_str(), done.result.c_str(), done.mapper_state.c_str(),
              static_cast<long long>(done.frames_integrated));
  return 0;
}

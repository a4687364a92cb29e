// panmap-command: sends one PANMAP_COMMAND to a running panmap-mapper (finish, save, export,
// optimise), e.g. at the end of an lcm-logplayer replay; `status` prints the mapper's next
// PANMAP_STATUS as one JSON line (for scripts and monitoring).
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
          {"depth_pattern_mm", s.depth_pattern_mm}};
}

struct StatusCatcher {
  std::optional<panmap::status_t> received;
  int malformed = 0;
  void onMessage(const lcm::ReceiveBuffer* buffer, const std::string&) {
    panmap::status_t msg;
    if (panmap::decodeExactly(buffer->data, buffer->data_size, &msg)) {
      received = msg;
    } else {
      ++malformed;
    }
  }
};

// Waits for one status message; prints it as JSON. 0 when one came, 1 otherwise.
int printStatus(lcm::LCM* lcm, const std::string& channel, double timeout_s) {
  StatusCatcher catcher;
  lcm->subscribe(channel, &StatusCatcher::onMessage, &catcher);
  std::optional<panmap::status_t>& received = catcher.received;
  const int& malformed = catcher.malformed;
  const auto deadline = std::chrono::steady_clock::now() +
                        std::chrono::milliseconds(static_cast<int64_t>(timeout_s * 1000));
  while (!received && std::chrono::steady_clock::now() < deadline) lcm->handleTimeout(100);
  if (!received) {
    std::fprintf(stderr, "panmap-command: error: no status on %s within %.1f s%s\n",
                 channel.c_str(), timeout_s, malformed ? " (only malformed messages)" : "");
    return 1;
  }
  std::printf("%s\n", statusJson(*received).dump().c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Sends a command to panmap-mapper on PANMAP_COMMAND: finish (optimise, write the "
      "outputs, exit), save [PATH] (map snapshot), export [DIR] (outputs now), optimise; or "
      "status: print the mapper's next PANMAP_STATUS as one JSON line."};
  std::string url, channel = panmap::kChannelCommand, command, argument;
  bool self_test = false;
  app.add_option("command", command, "finish | save | export | optimise | status");
  double timeout_s = 5.0;
  std::string status_channel = panmap::kChannelStatus;
  app.add_option("--timeout-s", timeout_s, "status: how long to wait")->capture_default_str();
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
  if (lcm.publish(channel, &msg) != 0) {
    std::fprintf(stderr, "panmap-command: error: publishing on %s failed\n", channel.c_str());
    return 1;
  }
  return 0;
}

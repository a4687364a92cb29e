// panmap-command: sends one PANMAP_COMMAND to a running panmap-mapper (finish, save, export,
// optimise), e.g. at the end of an lcm-logplayer replay.
#include <chrono>
#include <cstdio>
#include <map>

#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>

#include "panmap/command_t.hpp"
#include "panmap/lcm/channels.h"

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

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Sends a command to panmap-mapper on PANMAP_COMMAND: finish (optimise, write the "
      "outputs, exit), save [PATH] (map snapshot), export [DIR] (outputs now), optimise."};
  std::string url, channel = panmap::kChannelCommand, command, argument;
  bool self_test = false;
  app.add_option("command", command, "finish | save | export | optimise");
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
  if (command.empty()) {
    std::fprintf(stderr, "panmap-command: error: a command is required (see --help)\n");
    return 2;
  }
  if (it == commands.end()) {
    std::fprintf(stderr,
                 "panmap-command: error: unknown command '%s' (finish, save, export, "
                 "optimise)\n",
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

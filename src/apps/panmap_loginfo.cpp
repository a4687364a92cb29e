// panmap-loginfo: per-channel statistics of an LCM log, and whether every message decodes.
#include <cstdio>

#include <CLI/CLI.hpp>

#include "panmap/core/progress.h"
#include "panmap/lcm/log_info.h"

int main(int argc, char** argv) {
  CLI::App app{
      "Print per-channel statistics of an LCM log (count, rate, mean size, first/last utime) "
      "and check that every message decodes as its panmap type.\nExits 1 if any message fails "
      "to decode or the log is truncated."};
  std::string log_path;
  bool json = false, shallow = false, quiet = false;
  app.add_option("log", log_path, "LCM log file")->required();
  app.add_flag("--json", json, "print JSON instead of a table");
  app.add_flag("--shallow", shallow, "only decode messages, not the images inside them");
  app.add_flag("-q,--quiet", quiet, "no progress line");
  CLI11_PARSE(app, argc, argv);

  try {
    panmap::ProgressLine progress("loginfo", "MiB", !quiet && !json);
    const panmap::LogInfo info = panmap::inspectLog(
        log_path, !shallow,
        [&](size_t done, size_t total) { progress.update(done >> 20, total >> 20); });
    progress.finish();
    std::printf("%s\n",
                json ? panmap::logInfoToJson(info).c_str() : panmap::logInfoToTable(info).c_str());
    if (!info.allDecoded()) {
      // Say which: a cut log decodes every message it has (this said "do not decode" then).
      bool failures = false;
      for (const panmap::ChannelInfo& c : info.channels) failures = failures || c.failures > 0;
      std::fprintf(stderr, "panmap-loginfo: %s %s\n", log_path.c_str(),
                   failures         ? "has messages that do not decode"
                   : info.truncated ? "is cut or corrupt after its last whole event"
                                    : "has bytes between events that are not events");
      return 1;
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-loginfo: error: %s\n", e.what());
    return 1;
  }
  return 0;
}

#include "panmap/lcm/offline_mapping.h"

#include <sys/stat.h>

#include <chrono>
#include <cstdio>

#include <lcm/lcm-cpp.hpp>

#include "panmap/core/error.h"

namespace panmap {

OfflineReport mapLog(const std::string& log_path, const SessionOptions& options, Mapper* mapper,
                     const std::function<void(size_t, size_t)>& progress,
                     const MappingSession::FrameHook& hook) {
  struct stat st;
  if (::stat(log_path.c_str(), &st) != 0) throw Error("log " + log_path + " does not exist");
  lcm::LogFile log(log_path, "r");
  if (!log.good()) throw Error("cannot open log " + log_path);
  const auto start = std::chrono::steady_clock::now();
  MappingSession session(options, mapper);
  if (hook) session.setFrameHook(hook);
  int64_t events = 0;
  int64_t newest = INT64_MIN;
  while (!session.done()) {
    const lcm::LogEvent* e = log.readNextEvent();
    if (!e) break;
    ++events;
    newest = std::max(newest, e->timestamp);
    session.handle(e->channel, e->data, static_cast<size_t>(e->datalen), newest);
    if (progress && events % 8 == 0) {
      progress(static_cast<size_t>(std::ftell(log.getFilePtr())), static_cast<size_t>(st.st_size));
    }
  }
  session.flush();
  if (progress) progress(static_cast<size_t>(st.st_size), static_cast<size_t>(st.st_size));
  OfflineReport report;
  static_cast<SessionStats&>(report) = session.stats();
  report.events = events;
  report.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return report;
}

}  // namespace panmap

#include "panmap/lcm/log_info.h"

#include <sys/stat.h>

#include <algorithm>
#include <cstdio>
#include <iomanip>
#include <map>
#include <sstream>

#include <lcm/lcm-cpp.hpp>
#include <nlohmann/json.hpp>

#include "panmap/core/error.h"
#include "panmap/lcm/log_bytes.h"
#include "panmap/lcm/message_types.h"

namespace panmap {

double ChannelInfo::rateHz() const {
  const size_t decoded = count - failures;
  const size_t n = decoded > 0 ? decoded : count;
  if (n < 2 || last_utime <= first_utime) return 0.0;
  return static_cast<double>(n - 1) * 1e6 / static_cast<double>(last_utime - first_utime);
}

bool LogInfo::allDecoded() const {
  if (truncated || skipped_bytes > 0) return false;
  for (const ChannelInfo& c : channels) {
    if (c.failures > 0) return false;
  }
  return true;
}

LogInfo inspectLog(const std::string& path, bool deep,
                   const std::function<void(size_t, size_t)>& progress) {
  struct stat st;
  if (::stat(path.c_str(), &st) != 0) throw Error("log " + path + " does not exist");
  if (!S_ISREG(st.st_mode)) throw Error("log " + path + " is not a regular file");
  const auto file_size = static_cast<size_t>(st.st_size);
  lcm::LogFile log(path, "r");
  if (!log.good()) throw Error("cannot open log " + path);

  LogInfo info;
  info.path = path;
  std::map<std::string, ChannelInfo> channels;
  LogByteAccount bytes;
  // A header claiming more bytes than are left is the damaged end (and would crash liblcm).
  while (nextEventFits(log.getFilePtr(), file_size)) {
    const lcm::LogEvent* event = log.readNextEvent();
    if (!event) break;
    ++info.events;
    bytes.addEvent(LogByteAccount::eventBytes(event->channel.size(), event->datalen),
                   std::ftell(log.getFilePtr()));
    ChannelInfo& c = channels[event->channel];
    c.channel = event->channel;
    const MessageCheck check = checkMessage(event->data, static_cast<size_t>(event->datalen), deep);
    if (c.count == 0) {
      c.type = check.type;
    } else if (c.type != check.type) {
      c.type.clear();  // mixed types on one channel
    }
    // Times from the messages that decoded; until one has, from the logger's clock.
    const size_t decoded = c.count - c.failures;
    if (check.ok) {
      if (decoded == 0) c.first_utime = check.utime;
      c.last_utime = check.utime;
    } else if (decoded == 0) {
      if (c.count == 0) c.first_utime = event->timestamp;
      c.last_utime = event->timestamp;
    }
    ++c.count;
    c.bytes += static_cast<size_t>(event->datalen);
    if (!check.ok) {
      if (c.failures == 0)
        c.first_error = "event " + std::to_string(event->eventnum) + ": " + check.error;
      ++c.failures;
    }
    if (progress && info.events % 16 == 0) {
      progress(static_cast<size_t>(std::ftell(log.getFilePtr())), file_size);
    }
  }
  info.readable_bytes = bytes.readableBytes();
  info.skipped_bytes = bytes.skippedBytes();
  info.truncated = bytes.truncated(file_size);
  for (auto& kv : channels) info.channels.push_back(kv.second);
  return info;
}

std::string logInfoToJson(const LogInfo& info) {
  nlohmann::json root;
  root["path"] = info.path;
  root["events"] = info.events;
  root["truncated"] = info.truncated;
  root["skipped_bytes"] = info.skipped_bytes;
  root["readable_bytes"] = info.readable_bytes;
  root["all_decoded"] = info.allDecoded();
  nlohmann::json channels = nlohmann::json::array();
  for (const ChannelInfo& c : info.channels) {
    channels.push_back({{"channel", c.channel},
                        {"type", c.type},
                        {"count", c.count},
                        {"rate_hz", c.rateHz()},
                        {"mean_bytes", c.meanBytes()},
                        {"first_utime", c.first_utime},
                        {"last_utime", c.last_utime},
                        {"decode_failures", c.failures},
                        {"first_error", c.first_error}});
  }
  root["channels"] = channels;
  // Channel names are bytes: one that is not UTF-8 made dump() throw and --json print nothing.
  return root.dump(2, ' ', false, nlohmann::json::error_handler_t::replace);
}

std::string logInfoToTable(const LogInfo& info) {
  // Columns as wide as their longest entry (PANMAP_POSE_CORRECTION ran into the type), with
  // control bytes of a channel name shown as '?' (a newline in one broke the table).
  auto printable = [](std::string text) {
    for (char& ch : text) {
      if (static_cast<unsigned char>(ch) < 0x20 || ch == 0x7F) ch = '?';
    }
    return text;
  };
  int channel_width = 16, type_width = 20;
  for (const ChannelInfo& c : info.channels) {
    channel_width = std::max(channel_width, static_cast<int>(c.channel.size()) + 2);
    type_width = std::max(type_width, static_cast<int>(c.type.size()) + 2);
  }
  std::ostringstream out;
  out << std::left << std::setw(channel_width) << "channel" << std::setw(type_width) << "type"
      << std::right << std::setw(8) << "count" << std::setw(10) << "rate_hz" << std::setw(12)
      << "mean_bytes" << std::setw(18) << "first_utime" << std::setw(18) << "last_utime"
      << "  decoded\n";
  for (const ChannelInfo& c : info.channels) {
    out << std::left << std::setw(channel_width) << printable(c.channel) << std::setw(type_width)
        << (c.type.empty() ? "?" : c.type) << std::right << std::setw(8) << c.count << " "
        << std::setw(9) << std::fixed << std::setprecision(2) << c.rateHz() << " " << std::setw(11)
        << std::setprecision(0) << c.meanBytes() << std::setw(18) << c.first_utime << std::setw(18)
        << c.last_utime << "  "
        << (c.failures ? std::to_string(c.count - c.failures) + "/" + std::to_string(c.count)
                       : std::string("all"))
        << "\n";
    if (c.failures) out << "  first failure: " << c.first_error << "\n";
  }
  out << info.events << " events";
  if (info.truncated) {
    out << "; unreadable after byte " << info.readable_bytes << " of "
        << "the file (truncated or corrupt)";
  }
  if (info.skipped_bytes)
    out << "; " << info.skipped_bytes << " bytes between events are not events";
  out << "\n";
  return out.str();
}

}  // namespace panmap

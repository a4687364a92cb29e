// panmap-occupancy-probe: asks an occupancy tree what a planner would. Takes the tree from
// the next PANMAP_OCTOMAP message (or a .bt file), decodes it with OctoMap and answers
// "what is at this point" (free / occupied / unknown) and "is this straight segment free"
// (free / blocked at x y z / unknown at x y z: the first cell from A that is not known free).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include <lcm/lcm-cpp.hpp>
#include "cli_checks.h"

#include "panmap/core/error.h"
#include "panmap/lcm/channels.h"
#include "panmap/lcm/decode.h"
#include "panmap/occupancy/occupancy_query.h"
#include "panmap/occupancy/octree_io.h"
#include "panmap/octomap_t.hpp"

namespace {

// Keeps the first message on the channel: the decoded tree, or why it could not be decoded.
class TreeReceiver {
 public:
  // Called from LCM's C code: nothing may escape.
  void onMessage(const lcm::ReceiveBuffer* buffer, const std::string& channel) {
    if (done_) return;
    done_ = true;
    try {
      panmap::octomap_t msg;
      if (!panmap::decodeExactly(buffer->data, buffer->data_size, &msg)) {
        error_ = "malformed message on " + channel + " (not a panmap.octomap_t)";
        return;
      }
      if (msg.tree_type != "OcTree") {
        error_ = "message on " + channel + " holds a '" + msg.tree_type + "', not an OcTree";
        return;
      }
      if (!msg.binary) {
        error_ = "message on " + channel +
                 " holds a full (non-binary) tree; only binary trees "
                 "are supported";
        return;
      }
      tree_ = panmap::treeFromBinaryData(std::string(msg.data.begin(), msg.data.end()),
                                         msg.resolution_m);
      utime_ = msg.utime;
    } catch (const std::exception& e) {
      error_ = "malformed message on " + channel + ": " + e.what();
    } catch (...) {
      error_ = "malformed message on " + channel;
    }
  }

  bool done() const { return done_; }
  const std::string& error() const { return error_; }
  std::unique_ptr<octomap::OcTree> takeTree() { return std::move(tree_); }
  int64_t utime() const { return utime_; }

 private:
  bool done_ = false;
  std::string error_;
  std::unique_ptr<octomap::OcTree> tree_;
  int64_t utime_ = 0;
};

std::unique_ptr<octomap::OcTree> receiveTree(const std::string& url, const std::string& channel,
                                             double timeout_s) {
  lcm::LCM lcm(url);
  if (!lcm.good()) throw panmap::Error("cannot open LCM URL '" + url + "'");
  TreeReceiver receiver;
  lcm.subscribe(channel, &TreeReceiver::onMessage, &receiver);
  using Clock = std::chrono::steady_clock;
  const Clock::time_point deadline =
      Clock::now() + std::chrono::microseconds(static_cast<int64_t>(timeout_s * 1e6));
  bool stopped = false;  // LCM gave up, e.g. at the end of a file:// log
  while (!receiver.done() && !stopped) {
    const auto left_ms =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left_ms <= 0) break;
    stopped = lcm.handleTimeout(static_cast<int>(std::min<int64_t>(left_ms, 1000))) < 0;
  }
  if (!receiver.done()) {
    std::ostringstream s;
    s << "no message on " << channel;
    if (stopped) {
      s << " before LCM stopped delivering (end of a file:// log?)";
    } else {
      s << " within " << timeout_s << " s";
    }
    throw panmap::Error(s.str());
  }
  if (!receiver.error().empty()) throw panmap::Error(receiver.error());
  std::fprintf(stderr, "panmap-occupancy-probe: tree from %s (utime %lld)\n", channel.c_str(),
               static_cast<long long>(receiver.utime()));
  return receiver.takeTree();
}

std::string formatPoint(const Eigen::Vector3d& p) {
  std::ostringstream s;
  s << p.x() << " " << p.y() << " " << p.z();
  return s.str();
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Answers occupancy questions the way a planner asks them, from the next PANMAP_OCTOMAP "
      "message or from a .bt file. Prints one line per question: --point gives free, occupied "
      "or unknown; --segment gives free, 'blocked at x y z' or 'unknown at x y z' (centre of "
      "the first cell from A that is not known free; unknown is never taken as free)."};
  std::string file, url, channel = panmap::kChannelOctomap;
  double timeout_s = 5.0;
  std::vector<double> point, segment;
  auto* file_opt = app.add_option("--file", file, "read this .bt file instead of listening");
  auto* url_opt = app.add_option("--lcm-url", url, "LCM URL (default: LCM_DEFAULT_URL or LCM's)");
  auto* channel_opt =
      app.add_option("--channel", channel, "channel of the tree")->capture_default_str();
  auto* timeout_opt =
      app.add_option("--timeout-s", timeout_s, "give up when no message arrives in this time")
          ->capture_default_str()
          ->check(panmap::cli::positive());
  file_opt->excludes(url_opt)->excludes(channel_opt)->excludes(timeout_opt);
  app.add_option("--point", point, "state at this point (world, metres)")
      ->expected(3)
      ->type_name("X Y Z");
  app.add_option("--segment", segment, "is the straight segment A-B free (world, metres)")
      ->expected(6)
      ->type_name("AX AY AZ BX BY BZ");
  std::string compare;
  app.add_option("--compare", compare,
                 "compare the tree cell by cell with this .bt file: prints the share of cells "
                 "known in both whose states agree, and the cells known in only one");
  CLI11_PARSE(app, argc, argv);
  try {
    if (point.empty() && segment.empty() && compare.empty()) {
      throw panmap::Error("nothing to ask: give --point, --segment or --compare (see --help)");
    }
    std::unique_ptr<octomap::OcTree> tree =
        file.empty() ? receiveTree(url, channel, timeout_s) : panmap::readBtFile(file);
    std::vector<std::string> answers;
    if (!compare.empty()) {
      const panmap::OccupancyAgreement a =
          panmap::compareOccupancy(*tree, *panmap::readBtFile(compare));
      // "100 % of 0 cells" would read as agreement.
      if (a.known_in_both == 0) {
        throw panmap::Error("no cell is known in both trees (" + std::to_string(a.only_in_a) +
                            " only here, " + std::to_string(a.only_in_b) + " only in " + compare +
                            "): maps of other places, or in other frames?");
      }
      char line[256];
      std::snprintf(line, sizeof(line),
                    "agree on %.2f %% of %llu cells known in both; known only here %llu, only "
                    "in %s %llu",
                    100.0 * a.agreement(), static_cast<unsigned long long>(a.known_in_both),
                    static_cast<unsigned long long>(a.only_in_a), compare.c_str(),
                    static_cast<unsigned long long>(a.only_in_b));
      answers.push_back(line);
    }
    if (!point.empty()) {
      answers.push_back(panmap::occupancyName(
          panmap::occupancyAt(*tree, Eigen::Vector3d(point[0], point[1], point[2]))));
    }
    if (!segment.empty()) {
      const panmap::SegmentCheck check =
          panmap::checkSegment(*tree, Eigen::Vector3d(segment[0], segment[1], segment[2]),
                               Eigen::Vector3d(segment[3], segment[4], segment[5]));
      switch (check.verdict) {
        case panmap::Occupancy::kFree:
          answers.push_back("free");
          break;
        case panmap::Occupancy::kOccupied:
          answers.push_back("blocked at " + formatPoint(check.where_W));
          break;
        case panmap::Occupancy::kUnknown:
          answers.push_back("unknown at " + formatPoint(check.where_W));
          break;
      }
    }
    for (const std::string& a : answers) std::printf("%s\n", a.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "panmap-occupancy-probe: error: %s\n", e.what());
    return 1;
  }
  return 0;
}

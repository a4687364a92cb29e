#include "panmap/recovery/resume.h"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "panmap/core/error.h"
#include "panmap/recovery/autosave.h"

namespace panmap {
namespace {

// (frame id, utime) of the frames journaled after `utime`, by utime: frames mapped again by a
// resumed run (a replayed log) appear once.
std::vector<std::pair<int64_t, int64_t>> journalAfter(const std::string& path, int64_t utime,
                                                      bool* readable) {
  std::map<int64_t, int64_t> by_utime;
  std::ifstream in(path);
  // A journal that is gone or holds no frame line cannot say nothing was lost.
  *readable = false;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;  // '#': a run marker
    std::istringstream fields(line);
    int64_t id = 0, t = 0;
    if (!(fields >> id >> t)) continue;  // a line cut by the crash
    *readable = true;
    if (t > utime) by_utime.emplace(t, id);
  }
  std::vector<std::pair<int64_t, int64_t>> out;
  for (const auto& [t, id] : by_utime) out.emplace_back(id, t);
  return out;
}

}  // namespace

ResumePoint resumeFrom(const std::string& dir, const std::vector<std::string>& also) {
  std::vector<std::string> snapshots = listResumeCandidates(dir);
  // A map file written after the newest snapshot holds more: a mapper killed while it wrote
  // its final outputs had map.panmap whole (written first), and resuming from the snapshot
  // before it lost every frame since and then overwrote it. Snapshots of one run grow with
  // time, so the newest file is the fullest; ties keep the snapshots' order.
  std::vector<std::pair<std::filesystem::file_time_type, std::string>> dated;
  for (const std::string& path : snapshots) {
    std::error_code error;
    dated.emplace_back(std::filesystem::last_write_time(path, error), path);
  }
  for (const std::string& path : also) {
    std::error_code error;
    if (!std::filesystem::is_regular_file(path, error)) continue;
    dated.emplace_back(std::filesystem::last_write_time(path, error), path);
  }
  std::stable_sort(dated.begin(), dated.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  snapshots.clear();
  for (const auto& [time, path] : dated) snapshots.push_back(path);
  if (snapshots.empty()) {
    throw Error(dir + ": no autosave-NNNNNN.panmap snapshot to resume from" +
                (also.empty() ? std::string() : " and no " + also.front()) +
                " (a run stopped before its first snapshot saved nothing: start it without "
                "--resume)");
  }
  ResumePoint point;
  for (const std::string& path : snapshots) {
    try {
      point.mapper = Mapper::load(path);
      point.path = path;
      break;
    } catch (const std::exception& e) {
      point.refused.push_back(e.what());
    }
  }
  if (!point.mapper) {
    std::string why;
    for (const std::string& r : point.refused) why += (why.empty() ? "" : "; ") + r;
    throw Error(dir + ": no snapshot loads (" + why + ")");
  }
  point.frames = point.mapper->framesIntegrated();
  const std::vector<StampedPose>& trajectory = point.mapper->trajectory();
  if (!trajectory.empty()) {
    point.last_utime = trajectory.back().utime;
    point.last_frame_id = trajectory.back().frame_id;
  }
  point.lost = journalAfter(dir + "/frames.journal", point.last_utime, &point.journal_read);
  return point;
}

std::string describeResume(const ResumePoint& point) {
  std::ostringstream out;
  out << "resumed from " << point.path << ": " << point.frames << " frames";
  if (point.last_frame_id >= 0) {
    out << " (last frame " << point.last_frame_id << ", utime " << point.last_utime << ")";
  }
  if (!point.journal_read) {
    out << "; the frame journal is missing or unreadable: frames lost since it are not known";
  } else if (point.lost.empty()) {
    out << "; no frame integrated after it was lost";
  } else {
    out << "; lost " << point.lost.size() << " frames integrated after it (frames "
        << point.lost.front().first << "-" << point.lost.back().first << ")";
  }
  if (!point.refused.empty()) {
    out << "; " << point.refused.size() << " newer snapshot(s) refused: " << point.refused.front();
  }
  return out.str();
}

}  // namespace panmap

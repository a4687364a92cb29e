#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "panmap/mapper/mapper.h"

namespace panmap {

/// Where a resumed run starts, and what the crash cost.
struct ResumePoint {
  std::unique_ptr<Mapper> mapper;
  std::string path;                  ///< the snapshot resumed from
  std::vector<std::string> refused;  ///< newer snapshots that did not load, with the error
  int64_t frames = 0;                ///< frames the snapshot holds
  int64_t last_utime = INT64_MIN;    ///< its newest frame (INT64_MIN: none)
  int64_t last_frame_id = -1;
  /// Frames the journal shows integrated after the snapshot: (frame id, utime), lost.
  std::vector<std::pair<int64_t, int64_t>> lost;
  bool journal_read = false;  ///< the journal held frame lines (else `lost` says nothing)
};

/// Loads the newest snapshot of an autosave folder that reads cleanly, a complete .partial one
/// included (a corrupt or truncated newer one is refused with its error and the next older
/// one tried; the checksum tells a complete partial file from a cut one), and reads the frame
/// journal to list the frames lost since it. `also`: other map files that may be newer (the
/// output folder's map.panmap, written by an export or a final export cut short after the last
/// snapshot); those that exist join the snapshots, newest modification time first. Throws Error
/// naming the folder when nothing loads, listing each one's error.
ResumePoint resumeFrom(const std::string& dir, const std::vector<std::string>& also = {});

/// One line for users: the snapshot, its frames, and the frames lost ("frames 812-845").
std::string describeResume(const ResumePoint& point);

}  // namespace panmap

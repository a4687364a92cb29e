#pragma once

#include <condition_variable>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "panmap/mapper/mapper.h"

namespace panmap {

class AtomicFileWriter;

/// Periodic map snapshots for crash recovery. The mapper is streamed into a temporary file on
/// the thread that owns it, between frames (where it is consistent; the data goes to the page
/// cache, never whole into memory); a background thread makes it durable (fsync) and renames
/// it into place, so the disk never stalls mapping. A journal lists every integrated frame, so
/// a resume can say which frames the crash cost.
class Autosaver {
 public:
  /// Where and how often.
  struct Config {
    std::string dir;         ///< snapshots: dir/autosave-NNNNNN.panmap; journal: dir/frames.journal
    double period_s = 60.0;  ///< stream time (frame utimes) between snapshots; 0: never
    int keep = 2;            ///< newest snapshots kept, older ones removed
    /// With a loop-closure frame store: true when the frame of a utime is in it. A snapshot
    /// waits until the store holds its newest frame (the store's writer runs behind on a
    /// thread of its own): a map resumed from a snapshot ahead of its store could not be
    /// repaired. Empty: no store.
    std::function<bool(int64_t utime)> frame_stored;
    /// How long a snapshot waits for the store before it is taken anyway (counted).
    double store_wait_s = 30.0;
    /// The file a resumed run loaded (ResumePoint::path), or empty. The other .partial files of
    /// the folder, left by earlier crashes, are removed at the start: they piled up, crash
    /// after crash, until a run finished (85 MB after three).
    std::string resumed_from;
    /// Throws Error naming the bad field.
    void check() const;
  };

  /// What the autosaver has done.
  struct Stats {
    int64_t written = 0;       ///< snapshots on disk
    int64_t waited_busy = 0;   ///< due while the previous one was still being written
    double waited_ms = 0.0;    ///< mapping time spent waiting for those writes
    int64_t failed = 0;        ///< writes that failed (disk full, ...), with last_error
    bool last_failed = false;  ///< the newest snapshot failed: crash recovery is behind
    std::string last_path;
    std::string last_error;
    size_t last_bytes = 0;
    double last_serialize_ms = 0.0;  ///< streaming the map to the file, on the mapping thread
    double last_write_ms = 0.0;      ///< fsync and rename, on the background thread
    /// Snapshots taken while the frame store still lacked their newest frame (store_wait_s).
    int64_t ahead_of_store = 0;
  };

  /// Creates the folder; continues the numbering of snapshots already there (a resumed run).
  /// Throws Error naming the folder when it cannot be created.
  explicit Autosaver(const Config& config);
  /// Waits for the snapshot being written.
  ~Autosaver();
  Autosaver(const Autosaver&) = delete;
  Autosaver& operator=(const Autosaver&) = delete;

  /// Call after every integrated frame, on the thread that owns the mapper: journals the frame
  /// and snapshots the map once period_s of stream time has passed since the last snapshot
  /// (or since the first frame).
  void afterFrame(const Mapper& mapper, int64_t frame_id, int64_t utime);
  /// Snapshots now, whatever the period (e.g. before a planned stop).
  void snapshotNow(const Mapper& mapper);
  /// Blocks until the snapshot in flight is on disk.
  void wait();
  /// Removes the snapshots, partial ones, the journal and the folder if that leaves it empty
  /// (after the final outputs are safely written); later frames are not journaled.
  void clear();
  /// Counters so far (thread-safe).
  Stats stats() const;

 private:
  void writerLoop();

  Config config_;
  std::FILE* journal_ = nullptr;
  int64_t next_number_ = 1;
  int64_t last_snapshot_utime_ = INT64_MIN;
  int64_t last_frame_utime_ = INT64_MIN;  ///< the newest frame journaled

  mutable std::mutex mutex_;
  std::condition_variable cv_;
  std::unique_ptr<AtomicFileWriter> pending_;  ///< a snapshot waiting to be made durable
  bool writing_ = false;
  bool stop_ = false;
  Stats stats_;
  std::thread writer_;
};

/// The snapshot file of a given number in an autosave folder.
std::string autosavePath(const std::string& dir, int64_t number);

/// Snapshot files of an autosave folder, newest (highest number) first.
std::vector<std::string> listAutosaves(const std::string& dir);

/// What a resume may load, newest first: the snapshots and the .partial files a crash left
/// behind. A process killed after streaming a snapshot but before its fsync and rename leaves
/// a complete .partial (its checksum tells), which costs less than the previous snapshot.
std::vector<std::string> listResumeCandidates(const std::string& dir);

/// Removes what a finished run no longer needs from an autosave folder: its resume candidates,
/// its journal and the folder itself when that leaves it empty. Throws Error naming a file that
/// cannot be removed.
void clearAutosaveFolder(const std::string& dir);

}  // namespace panmap

#include "panmap/recovery/autosave.h"

#include <cerrno>
#include <chrono>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <regex>

#include "panmap/core/error.h"
#include "panmap/io/atomic_file.h"

namespace panmap {
namespace {

double msSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

// Snapshot files of a folder, newest first; with `partial`, also the .partial files a crash
// left (after the complete file of the same number).
std::vector<std::pair<int64_t, std::string>> numberedAutosaves(const std::string& dir,
                                                               bool partial = false) {
  namespace fs = std::filesystem;
  static const std::regex name_re(R"(autosave-(\d+)\.panmap)");
  static const std::regex any_re(R"(autosave-(\d+)\.panmap(\.partial)?)");
  std::vector<std::pair<int64_t, std::string>> out;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    std::smatch m;
    if (std::regex_match(name, m, partial ? any_re : name_re)) {
      out.emplace_back(std::stoll(m[1].str()), entry.path().string());
    }
  }
  std::sort(out.rbegin(), out.rend());
  return out;
}

}  // namespace

void Autosaver::Config::check() const {
  if (dir.empty()) throw Error("autosave: no folder");
  if (!(period_s >= 0.0 && std::isfinite(period_s))) throw Error("autosave: period_s must be >= 0");
  if (keep < 1) throw Error("autosave: keep must be at least 1");
  if (!(store_wait_s >= 0.0 && std::isfinite(store_wait_s))) {
    throw Error("autosave: store_wait_s must be >= 0");
  }
}

std::string autosavePath(const std::string& dir, int64_t number) {
  char name[64];
  std::snprintf(name, sizeof(name), "autosave-%06" PRId64 ".panmap", number);
  return dir + "/" + name;
}

std::vector<std::string> listAutosaves(const std::string& dir) {
  std::vector<std::string> out;
  for (const auto& [number, path] : numberedAutosaves(dir)) out.push_back(path);
  return out;
}

std::vector<std::string> listResumeCandidates(const std::string& dir) {
  std::vector<std::string> out;
  for (const auto& [number, path] : numberedAutosaves(dir, true)) out.push_back(path);
  return out;
}

Autosaver::Autosaver(const Config& config) : config_(config) {
  config_.check();
  std::error_code ec;
  std::filesystem::create_directories(config_.dir, ec);
  if (ec) throw Error("cannot create autosave folder " + config_.dir + ": " + ec.message());
  const auto existing = numberedAutosaves(config_.dir, true);
  if (!existing.empty()) next_number_ = existing.front().first + 1;
  if (!config_.resumed_from.empty()) {
    for (const auto& [number, path] : existing) {
      const bool partial = path.size() > 8 && path.compare(path.size() - 8, 8, ".partial") == 0;
      std::error_code error;  // spelt differently, the resumed file must still be kept
      const bool resumed = std::filesystem::equivalent(path, config_.resumed_from, error);
      if (partial && !error && !resumed) std::remove(path.c_str());
    }
  }
  const std::string journal = config_.dir + "/frames.journal";
  journal_ = std::fopen(journal.c_str(), "a");
  if (!journal_) throw Error("cannot open " + journal);
  // A marker per run: a resume reads only the frames journaled since the last one.
  std::fprintf(journal_, "# run, next snapshot %" PRId64 "\n", next_number_);
  std::fflush(journal_);
  writer_ = std::thread(&Autosaver::writerLoop, this);
}

Autosaver::~Autosaver() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  cv_.notify_all();
  if (writer_.joinable()) writer_.join();
  if (journal_) std::fclose(journal_);
}

void Autosaver::afterFrame(const Mapper& mapper, int64_t frame_id, int64_t utime) {
  // One write per frame: survives kill -9 (the kernel holds it), not a power cut, which is all
  // the journal is for (saying which frames were lost).
  if (journal_) {
    std::fprintf(journal_, "%" PRId64 " %" PRId64 "\n", frame_id, utime);
    std::fflush(journal_);
  }
  last_frame_utime_ = utime;
  if (config_.period_s <= 0.0) return;
  if (last_snapshot_utime_ == INT64_MIN) {
    last_snapshot_utime_ = utime;
    return;
  }
  if (static_cast<double>(utime - last_snapshot_utime_) < config_.period_s * 1e6) return;
  last_snapshot_utime_ = utime;
  snapshotNow(mapper);
}

void Autosaver::snapshotNow(const Mapper& mapper) {
  {
    // A disk slower than the period makes mapping wait rather than skip a snapshot: the bound
    // on what a crash costs (one period) holds, and at most one map copy is in memory.
    std::unique_lock<std::mutex> lock(mutex_);
    if (writing_ || pending_) {
      const auto start = std::chrono::steady_clock::now();
      cv_.wait(lock, [&] { return !pending_ && !writing_; });
      ++stats_.waited_busy;
      stats_.waited_ms += msSince(start);
    }
  }
  if (config_.frame_stored && last_frame_utime_ != INT64_MIN) {
    // Rarely more than a few frames behind (13 ms each); a failing store is not waited for
    // long, and its failures are counted where they happen.
    const auto deadline =
        std::chrono::steady_clock::now() +
        std::chrono::milliseconds(static_cast<int64_t>(config_.store_wait_s * 1e3));
    while (!config_.frame_stored(last_frame_utime_) &&
           std::chrono::steady_clock::now() < deadline) {
      std::this_thread::sleep_for(std::chrono::milliseconds(2));
    }
    if (!config_.frame_stored(last_frame_utime_)) {
      std::lock_guard<std::mutex> lock(mutex_);
      ++stats_.ahead_of_store;
    }
  }
  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<AtomicFileWriter> file;
  try {
    // Created in here: a folder gone or a full disk fails the snapshot, not the frame. A folder
    // removed under a running mapper (its output folder deleted, then made again by an export)
    // is made again, journal included: without, every later snapshot failed.
    std::error_code ignored;
    if (std::filesystem::create_directories(config_.dir, ignored) && journal_) {
      std::fclose(journal_);
      journal_ = std::fopen((config_.dir + "/frames.journal").c_str(), "a");
      if (journal_) {
        std::fprintf(journal_, "# folder made again, next snapshot %" PRId64 "\n", next_number_);
        std::fflush(journal_);
      }
    }
    file = std::make_unique<AtomicFileWriter>(autosavePath(config_.dir, next_number_++));
    mapper.serialize(file.get());
  } catch (const std::exception& e) {
    std::lock_guard<std::mutex> lock(mutex_);
    ++stats_.failed;
    stats_.last_error = e.what();
    stats_.last_failed = true;
    std::fprintf(stderr, "panmap: autosave failed: %s\n", e.what());
    return;  // the partial file goes with `file`
  }
  const double serialize_ms = msSince(start);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_ = std::move(file);
    stats_.last_serialize_ms = serialize_ms;
  }
  cv_.notify_all();
}

void Autosaver::wait() {
  std::unique_lock<std::mutex> lock(mutex_);
  cv_.wait(lock, [&] { return !pending_ && !writing_; });
}

void Autosaver::clear() {
  wait();
  if (journal_) std::fclose(journal_);
  journal_ = nullptr;  // frames after this are not journaled: nothing is left to resume from
  clearAutosaveFolder(config_.dir);
}

void clearAutosaveFolder(const std::string& dir) {
  std::vector<std::string> paths = listResumeCandidates(dir);
  paths.push_back(dir + "/frames.journal");
  for (const std::string& path : paths) {
    if (std::remove(path.c_str()) != 0 && errno != ENOENT) {
      throw Error("cannot remove " + path + ": " + std::strerror(errno));
    }
  }
  // The folder too, when nothing else is in it: an autosave/ left in a finished output folder
  // with an empty journal read as a run that had not ended.
  std::error_code ignored;
  std::filesystem::remove(dir, ignored);
}

Autosaver::Stats Autosaver::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

void Autosaver::writerLoop() {
  for (;;) {
    std::unique_ptr<AtomicFileWriter> file;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      cv_.wait(lock, [&] { return stop_ || pending_; });
      if (!pending_) return;  // stopping with nothing left to write
      file = std::move(pending_);
      writing_ = true;
    }
    const std::string path = file->path();
    const auto start = std::chrono::steady_clock::now();
    std::string error;
    size_t bytes = 0;
    try {
      file->commit();
      std::error_code ec;
      bytes = static_cast<size_t>(std::filesystem::file_size(path, ec));
      // Only once the new one is safe: drop those beyond `keep`.
      const auto all = numberedAutosaves(config_.dir);
      for (size_t i = static_cast<size_t>(config_.keep); i < all.size(); ++i) {
        std::remove(all[i].second.c_str());
      }
    } catch (const std::exception& e) {
      error = e.what();
    }
    file.reset();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      writing_ = false;
      stats_.last_failed = !error.empty();
      if (error.empty()) {
        ++stats_.written;
        stats_.last_path = path;
        stats_.last_bytes = bytes;
        stats_.last_write_ms = msSince(start);
      } else {
        ++stats_.failed;
        stats_.last_error = error;
      }
    }
    if (!error.empty()) std::fprintf(stderr, "panmap: autosave failed: %s\n", error.c_str());
    cv_.notify_all();
  }
}

}  // namespace panmap

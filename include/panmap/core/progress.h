#pragma once

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <string>

namespace panmap {

/// A progress line for long command-line work: rewritten in place on a terminal, a line
/// every 10 % otherwise (so CI logs stay short). Prints to stderr.
class ProgressLine {
 public:
  /// @param label what is progressing ("import"); @param unit what is counted ("frames")
  ProgressLine(std::string label, std::string unit, bool enabled = true);
  /// Reports `done` of `total` items.
  void update(size_t done, size_t total);
  /// Text appended to the line from the next update on (e.g. a second rate).
  void setNote(std::string note) { note_ = std::move(note); }
  /// Ends the line (call once when done).
  void finish();

 private:
  std::string label_;
  std::string unit_;
  std::string note_;
  bool enabled_;
  bool tty_;
  int last_decile_ = -1;
  bool printed_ = false;
  std::chrono::steady_clock::time_point start_;
  std::chrono::steady_clock::time_point last_print_;
};

}  // namespace panmap

#include "panmap/core/progress.h"

#include <unistd.h>

namespace panmap {

ProgressLine::ProgressLine(std::string label, std::string unit, bool enabled)
    : label_(std::move(label)),
      unit_(std::move(unit)),
      enabled_(enabled),
      tty_(::isatty(STDERR_FILENO) != 0),
      start_(std::chrono::steady_clock::now()),
      last_print_(start_) {}

void ProgressLine::update(size_t done, size_t total) {
  if (!enabled_ || total == 0) return;
  const auto now = std::chrono::steady_clock::now();
  const int decile = static_cast<int>(10 * done / total);
  if (tty_) {
    if (done != total && now - last_print_ < std::chrono::milliseconds(100)) return;
  } else if (decile == last_decile_) {
    return;
  }
  last_decile_ = decile;
  last_print_ = now;
  const double elapsed_s = std::chrono::duration<double>(now - start_).count();
  const double rate = elapsed_s > 0.0 ? done / elapsed_s : 0.0;
  const double eta_s = rate > 0.0 ? (total - done) / rate : 0.0;
  std::fprintf(stderr, "%s%s: %zu/%zu %s (%3.0f%%) %.1f %s/s ETA %.0f s%s%s%s",
               tty_ ? "\r" : "", label_.c_str(), done, total, unit_.c_str(),
               100.0 * done / total, rate, unit_.c_str(), eta_s, note_.empty() ? "" : ", ",
               note_.c_str(), tty_ ? "  " : "\n");
  std::fflush(stderr);
  printed_ = true;
}

void ProgressLine::finish() {
  if (enabled_ && printed_ && tty_) std::fprintf(stderr, "\n");
  printed_ = false;
}

}  // namespace panmap

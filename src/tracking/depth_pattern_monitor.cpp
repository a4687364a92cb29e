#include "panmap/tracking/depth_pattern_monitor.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "panmap/core/error.h"

namespace panmap {

void DepthPatternMonitor::Config::check() const {
  if (frames < 0) throw Error("tracking depth_check_frames must be >= 0 (0: no check)");
  if (!(max_pattern_m > 0.0 && std::isfinite(max_pattern_m))) {
    throw Error("tracking max_depth_pattern_m must be > 0");
  }
  if (min_cell_points < 1) throw Error("depth pattern min_cell_points must be >= 1");
  if (min_cell_frames < 1) throw Error("depth pattern min_cell_frames must be >= 1");
  if (min_cells < 2) throw Error("depth pattern min_cells must be >= 2");
}

DepthPatternMonitor::DepthPatternMonitor(const Config& config, int cells) : config_(config) {
  config_.check();
  if (cells < config_.min_cells) {
    throw Error("depth pattern monitor needs at least " + std::to_string(config_.min_cells) +
                " cells, got " + std::to_string(cells));
  }
  for (int h = 0; h < 2; ++h) {
    cell_mean_sum_m_[h].assign(static_cast<size_t>(cells), 0.0);
    cell_frames_[h].assign(static_cast<size_t>(cells), 0);
  }
  if (config_.frames == 0) verdict_ = Verdict::kTrusted;
}

DepthPatternMonitor::Verdict DepthPatternMonitor::add(const std::vector<double>& cell_sum_m,
                                                      const std::vector<int>& cell_count) {
  const size_t cells = cell_frames_[0].size();
  if (cell_sum_m.size() != cells || cell_count.size() != cells) {
    throw Error("depth pattern monitor: " + std::to_string(cell_sum_m.size()) + " cell sums and " +
                std::to_string(cell_count.size()) + " counts for " + std::to_string(cells) +
                " cells");
  }
  if (verdict_ != Verdict::kPending) return verdict_;
  const int half = frames_ < config_.frames / 2 ? 0 : 1;
  for (size_t c = 0; c < cells; ++c) {
    if (cell_count[c] < config_.min_cell_points || !std::isfinite(cell_sum_m[c])) continue;
    cell_mean_sum_m_[half][c] += cell_sum_m[c] / cell_count[c];
    ++cell_frames_[half][c];
  }
  ++frames_;
  if (frames_ < config_.frames || cellsInBothHalves() < config_.min_cells) return verdict_;
  verdict_ = patternRmsM() > config_.max_pattern_m ? Verdict::kUncalibrated : Verdict::kTrusted;
  return verdict_;
}

int DepthPatternMonitor::cellsInBothHalves() const {
  int cells = 0;
  for (size_t c = 0; c < cell_frames_[0].size(); ++c) {
    cells += cell_frames_[0][c] >= config_.min_cell_frames &&
             cell_frames_[1][c] >= config_.min_cell_frames;
  }
  return cells;
}

double DepthPatternMonitor::patternRmsM() const {
  std::vector<double> first, second;
  for (size_t c = 0; c < cell_frames_[0].size(); ++c) {
    if (cell_frames_[0][c] < config_.min_cell_frames ||
        cell_frames_[1][c] < config_.min_cell_frames) {
      continue;
    }
    first.push_back(cell_mean_sum_m_[0][c] / cell_frames_[0][c]);
    second.push_back(cell_mean_sum_m_[1][c] / cell_frames_[1][c]);
  }
  const size_t n = first.size();
  if (n < 2) return std::numeric_limits<double>::quiet_NaN();
  double mean_first = 0.0, mean_second = 0.0;
  for (size_t i = 0; i < n; ++i) mean_first += first[i], mean_second += second[i];
  mean_first /= static_cast<double>(n);
  mean_second /= static_cast<double>(n);
  double covariance = 0.0;
  for (size_t i = 0; i < n; ++i) covariance += (first[i] - mean_first) * (second[i] - mean_second);
  return std::sqrt(std::max(0.0, covariance / static_cast<double>(n)));
}

DepthPatternMonitor::State DepthPatternMonitor::state() const {
  State state;
  state.verdict = verdict_;
  state.frames = frames_;
  for (int h = 0; h < 2; ++h) {
    state.cell_mean_sum_m[h] = cell_mean_sum_m_[h];
    state.cell_frames[h] = cell_frames_[h];
  }
  return state;
}

void DepthPatternMonitor::restore(const State& state) {
  for (int h = 0; h < 2; ++h) {
    if (state.cell_mean_sum_m[h].size() != cell_frames_[h].size() ||
        state.cell_frames[h].size() != cell_frames_[h].size()) {
      throw Error("depth pattern monitor: saved state has " +
                  std::to_string(state.cell_frames[h].size()) + " cells, expected " +
                  std::to_string(cell_frames_[h].size()));
    }
  }
  verdict_ = state.verdict;
  frames_ = state.frames;
  for (int h = 0; h < 2; ++h) {
    cell_mean_sum_m_[h] = state.cell_mean_sum_m[h];
    cell_frames_[h] = state.cell_frames[h];
  }
}

const char* DepthPatternMonitor::name(Verdict verdict) {
  switch (verdict) {
    case Verdict::kPending:
      return "pending";
    case Verdict::kTrusted:
      return "trusted";
    case Verdict::kUncalibrated:
      return "uncalibrated";
  }
  return "unknown";
}

}  // namespace panmap

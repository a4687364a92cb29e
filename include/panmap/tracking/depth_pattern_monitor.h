#pragma once

#include <cstdint>
#include <vector>

namespace panmap {

/// Decides whether a depth sensor can be trusted to refine poses, from the first frames it
/// aligns. A real depth camera carries an error pattern fixed to the image (a Kinect: 3-18 mm
/// at 0.5-3.5 m, docs/MAPPING.md "Depth calibration"). No frame then agrees with the map that
/// averages many viewpoints, and aligning a frame to it moves a good pose by centimetres: it
/// makes a good SLAM trajectory worse. Rendered depth with random noise has no such pattern.
///
/// Each aligned frame gives the mean disagreement of its depth with the map along the rays,
/// per image cell, after the fit (the part no rigid motion explains). The pattern is what the
/// first and the second half of the frames agree on: the covariance over the cells of the two
/// halves' cell means, whose square root is the RMS of a pattern fixed to the image, while
/// random noise and the disagreements that change with the viewpoint (a drifting map seen from
/// elsewhere) fall out of it. Measured after 30 frames refined as usual (MapperConfig::
/// depth_check): 2.28-2.41 mm on 7-Scenes' Kinect at 1 and 2 cm, with or without injected
/// drift, and 0.00-0.29 mm on the 18 rendered sequences with SLAM-like poses of the accuracy
/// suite. The limit comes from rendered scenes with a fraction of that Kinect's pattern added
/// (scripts/bench/depth_pattern.py, docs/DEPTH_CHECK.md): past about 0.5 mm, refinement moved
/// perfect poses by more than issue 20's 0.2 cm beyond what it did without the pattern.
/// Mistaking a real sensor for a clean one is what makes good poses worse.
class DepthPatternMonitor {
 public:
  struct Config {
    /// Aligned frames to judge from (0: no check, the depth is trusted).
    int frames = 30;
    /// A pattern of more than this RMS marks the depth as uncalibrated, metres.
    double max_pattern_m = 0.0005;
    /// A cell's mean counts in a frame when this many points agreed with the map there.
    int min_cell_points = 10;
    /// A cell enters the pattern when this many frames of each half gave it a mean.
    int min_cell_frames = 3;
    /// The verdict needs at least this many such cells.
    int min_cells = 12;
    /// Throws Error naming the bad field.
    void check() const;
  };

  enum class Verdict : int8_t {
    kPending,      ///< still collecting frames
    kTrusted,      ///< no fixed pattern above the limit: refinement may correct poses
    kUncalibrated  ///< a fixed pattern above the limit: poses are kept as given
  };

  /// @param cells number of image cells the residuals come in
  DepthPatternMonitor(const Config& config, int cells);

  /// Adds one aligned frame's per-cell sums and counts of along-ray distances (metres), as
  /// AlignmentResult carries them: frames before frames / 2 to the first half, the rest to the
  /// second. Decides once `frames` frames and `min_cells` cells are in; while too few cells
  /// are, the second half keeps growing. Frames after the verdict are ignored. Throws Error
  /// when the sizes do not match `cells`.
  Verdict add(const std::vector<double>& cell_sum_m, const std::vector<int>& cell_count);

  /// The verdict so far.
  Verdict verdict() const { return verdict_; }
  /// Frames added before the verdict.
  int frames() const { return frames_; }
  /// The fixed pattern's RMS, metres: the square root of the covariance over the cells of the
  /// two halves' cell means (0 when negative); NaN before two cells have min_cell_frames frames
  /// in both halves.
  double patternRmsM() const;

  /// The state to save with a map, and its restoration (a map loaded to continue mapping keeps
  /// its verdict).
  struct State {
    Verdict verdict = Verdict::kPending;
    int frames = 0;
    /// Per half (first, second) and cell: sum over the half's frames of the frame's cell mean.
    std::vector<double> cell_mean_sum_m[2];
    std::vector<int> cell_frames[2];  ///< per half and cell: frames that gave a mean
  };
  /// The current state.
  State state() const;
  /// Restores a saved state. Throws Error when its sizes do not match this monitor's cells.
  void restore(const State& state);

  /// Short name of a verdict: "pending", "trusted", "uncalibrated".
  static const char* name(Verdict verdict);

 private:
  /// Cells with min_cell_frames frames in both halves.
  int cellsInBothHalves() const;

  Config config_;
  Verdict verdict_ = Verdict::kPending;
  int frames_ = 0;
  std::vector<double> cell_mean_sum_m_[2];
  std::vector<int> cell_frames_[2];
};

}  // namespace panmap

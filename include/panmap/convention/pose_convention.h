#pragma once

#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/frame.h"

namespace panmap {

/// Where the reader of the poses expects a quaternion's scalar.
enum class QuaternionInput {
  kNone,         ///< the rotations were matrices
  kScalarLast,   ///< TUM files: qx qy qz qw
  kScalarFirst,  ///< pose_t's orientation: w x y z
};

/// How a pose source's numbers become camera-to-world poses of the optical frame in metres. A
/// user's own trajectory can be written world-to-camera, with its quaternion's scalar at the
/// other end, in millimetres, or of a ROS camera_link; each gives a map of doubled walls with
/// nothing said (found by a newcomer probe).
struct PoseConvention {
  /// Scale of the translation, metres per unit (1, 0.01 for cm, 0.001 for mm).
  double translation_scale = 1.0;
  /// The quaternion's scalar sat at the other end from where the reader expects it (w x y z
  /// in a TUM file, x y z w in a pose_t, as Eigen's coeffs() gives them).
  bool scalar_moved = false;
  /// The source holds T_C_W (world-to-camera), not T_W_C.
  bool inverted = false;
  /// How the reader read the quaternion (scalar_moved needs it; kNone: no quaternions).
  QuaternionInput quaternions = QuaternionInput::kNone;
  /// The pose is of a camera body frame as ROS names it (x forward, y left, z up: a
  /// camera_link, not its optical frame x right, y down, z forward).
  bool body_frame = false;

  /// T_W_C from a pose as the reader parsed it (its quaternion order, camera-to-world, the
  /// source's units).
  Eigen::Isometry3d apply(const Eigen::Isometry3d& T_as_read) const;
  /// "camera-to-world, quaternion x y z w, metres" and the like.
  std::string describe() const;
  /// True when apply() returns its input.
  bool isIdentity() const {
    return translation_scale == 1.0 && !scalar_moved && !inverted && !body_frame;
  }
};

/// What the user fixed; unset fields are chosen from the depth images.
struct PoseConventionChoice {
  std::optional<double> translation_scale;
  std::optional<bool> scalar_moved;
  std::optional<bool> inverted;
  std::optional<bool> body_frame;
};

/// Parameters of the check.
struct PoseConventionConfig {
  int pixel_step = 8;             ///< every how many pixels a frame's depth is sampled
  double tolerance_m = 0.03;      ///< a point agrees when its depth is within this
  double tolerance_per_m = 0.02;  ///< ... plus this much per metre of depth (noise ~ z^2)
  double min_agreement = 0.5;     ///< below this the winner is no evidence
  double min_gain = 0.15;         ///< the winner must agree on this much more (share)
  /// Other units are tried only when the camera, read in metres, moves faster than this
  /// (median over the pairs, by the frames' utimes).
  double max_speed_m_per_s = 5.0;
  /// Throws Error naming the bad field.
  void check() const;
};

/// One frame of the check: its depth and the pose as the reader parsed it.
struct PoseSample {
  RgbdFrame frame;
  Eigen::Isometry3d T_as_read = Eigen::Isometry3d::Identity();
};

/// The check's outcome.
struct PoseConventionVerdict {
  PoseConvention convention;       ///< what to apply
  double agreement_as_read = 0.0;  ///< share of sampled points two frames agree on, as read
  double agreement_chosen = 0.0;   ///< the same under `convention`
  int pairs = 0;                   ///< frame pairs compared
  bool changed = false;            ///< `convention` differs from the file as read
  std::string note;                ///< one line for the user
};

/// Which of the candidate conventions makes the depth of frame pairs agree: for each pair
/// (first, second) of `samples`, every pixel_step-th pixel of the first frame is carried into
/// the second by the candidate's poses and agrees when the second frame's depth there is the
/// same within the tolerance. The file as read is kept unless another candidate agrees clearly
/// more (min_agreement, min_gain): a camera that barely moves cannot tell.
/// @param quaternions how the reader read the rotations (kNone: scalar_moved is not tried)
PoseConventionVerdict detectPoseConvention(const std::vector<PoseSample>& samples,
                                           const std::vector<std::pair<int, int>>& pairs,
                                           QuaternionInput quaternions,
                                           const PoseConventionChoice& fixed,
                                           const PoseConventionConfig& config = {});

/// Share of `first`'s sampled depth points that land on `second`'s depth within the tolerance
/// when carried by T_W_C1 and T_W_C2 (0 when `first` has no valid depth).
double depthAgreement(const RgbdFrame& first, const Eigen::Isometry3d& T_W_C1,
                      const RgbdFrame& second, const Eigen::Isometry3d& T_W_C2,
                      const PoseConventionConfig& config = {});

}  // namespace panmap

#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/labelled_mesh.h"
#include "panmap/core/pose.h"
#include "panmap/io/tum_trajectory.h"

namespace panmap {

/// Parameters of the survey path planner.
struct SurveyConfig {
  int num_frames = 300;      ///< poses to produce
  double rate_hz = 30.0;     ///< frame rate
  double speed_mps = 0.35;   ///< walking speed along the path, metres per second
  double clearance_m = 0.3;  ///< minimum distance of the camera to any surface, metres
  /// In a room with under 1 m^2 of floor clearance_m from its surfaces (ScanNet bathrooms), the
  /// survey walks closer to them, down to this (SurveyPath::clearance_m says how close).
  double min_clearance_m = 0.1;
  double min_height_m = 1.2;  ///< camera height band above the floor, metres
  double max_height_m = 1.7;
  double max_yaw_rate_dps = 45.0;    ///< head-like turning rate limit, degrees per second
  double max_pitch_rate_dps = 20.0;  ///< degrees per second
  double grid_m = 0.05;              ///< free-space grid cell, metres
  int num_waypoints = 10;            ///< tour stops spread over the free space, at least
  /// Free floor per stop: a floor larger than num_waypoints times this gets one stop per this
  /// much of it (at most kMaxSurveyStops), so a large scene is walked at least as densely as
  /// the sparsest room the defaults were set on (box room 1, the demo's: 10 stops over 52 m^2
  /// of free floor; every room of the suites keeps its 10). 0: num_waypoints alone.
  double area_per_stop_m2 = 6.0;
  double view_min_m = 0.8;  ///< preferred distance to the object being looked at
  double view_max_m = 3.5;
  double min_look_s = 1.5;  ///< keep looking at a target at least this long, seconds
  /// Times the walk passes every area, 1..20, as a handheld scan revisits: the loop through the
  /// stops forward in odd laps and backward in even ones, the head preferring objects it has not
  /// looked at from about where it stands (20 degrees) to those looked at least, so later laps
  /// see the other sides. 1 walks the one loop over and over with the head schedule of before.
  int laps = 1;
  /// Walls (NYU40 class 1) hide the objects behind them: the head only turns to objects it can
  /// see. Off for single rooms, whose trajectories were measured without the test; on for
  /// buildings, where most objects are behind a wall.
  bool walls_block_view = false;
  /// Throws Error naming the bad field.
  void check() const;
};

/// Most stops a survey spreads (SurveyConfig::area_per_stop_m2), whatever the floor.
constexpr int kMaxSurveyStops = 400;

/// The walk of a survey: `laps` rounds of one loop through the stops, one after the other.
struct SurveyPath {
  /// World x, y of the walk, metres; closed: the last point leads back to the first.
  std::vector<Eigen::Vector2d> points;
  std::vector<double> lap_start_m;  ///< arc length at which each lap starts, metres (0 first)
  double length_m = 0.0;            ///< arc length of the whole walk, back to its start, metres
  /// Distance the walk keeps from every surface, metres: SurveyConfig::clearance_m, less in a
  /// room too small to walk at it.
  double clearance_m = 0.0;
  /// Floor of the free region the walk keeps to, m^2 (0 for a walk through given stops).
  double free_area_m2 = 0.0;
  /// World x, y of the stops in visiting order (the walk's own or the given ones).
  std::vector<Eigen::Vector2d> stops;
};

/// Plans a smooth survey of a labelled mesh (z up): a loop through free space at least
/// clearance_m from every surface, at min..max height above the floor, turning to look at
/// the labelled objects from several sides. The camera walks planSurveyPath's walk at
/// speed_mps from its start and starts over at its end: laps the frames do not reach are left
/// out. Deterministic for a seed. Throws Error when the mesh has no free space large enough to
/// walk in, even at min_clearance_m.
std::vector<StampedPose> planSurvey(const LabelledMesh& mesh, const SurveyConfig& config,
                                    uint64_t seed);

/// planSurvey through given stops (world x, y, visited in order; the walk closes back to the
/// first) instead of stops it spreads itself. num_frames = 0 walks the loop once. Where a stop
/// is not within 0.5 m of free space or cannot be reached from the one before at clearance_m,
/// the walk keeps the largest lower clearance down to min_clearance_m at which every stop is
/// (planSurveyPathThrough's clearance_m says which); throws Error naming the stop when none is.
std::vector<StampedPose> planSurveyThrough(const LabelledMesh& mesh, SurveyConfig config,
                                           const std::vector<Eigen::Vector2d>& stops,
                                           uint64_t seed);

/// The walk planSurveyThrough follows for the same arguments.
SurveyPath planSurveyPathThrough(const LabelledMesh& mesh, const SurveyConfig& config,
                                 const std::vector<Eigen::Vector2d>& stops);

/// The walk planSurvey follows for the same mesh, config and seed (to tell its laps apart).
SurveyPath planSurveyPath(const LabelledMesh& mesh, const SurveyConfig& config, uint64_t seed);

/// Frames a survey takes to walk the whole of `path` (every lap, back to its start) at
/// config.speed_mps and config.rate_hz: num_frames for a survey that leaves no lap out. At
/// least 2.
int framesToWalk(const SurveyPath& path, const SurveyConfig& config);

/// Smallest distance from any trajectory position to the mesh's vertices, metres (the mesh
/// is dense, so this bounds the distance to its surfaces within half an edge length).
double minClearance(const std::vector<StampedPose>& trajectory, const LabelledMesh& mesh);

}  // namespace panmap

#include "panmap/sim/trajectory.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <queue>
#include <sstream>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"
#include "panmap/core/nearest_point.h"
#include "panmap/core/random.h"

namespace panmap {

void SurveyConfig::check() const {
  if (num_frames < 1) throw Error("survey num_frames must be >= 1");
  if (!(rate_hz > 0)) throw Error("survey rate_hz must be > 0");
  if (!(speed_mps > 0)) throw Error("survey speed_mps must be > 0");
  if (!(clearance_m >= 0)) throw Error("survey clearance_m must be >= 0");
  if (!(min_clearance_m >= 0)) throw Error("survey min_clearance_m must be >= 0");
  if (!(min_height_m > 0 && max_height_m >= min_height_m)) {
    throw Error("survey heights need 0 < min_height_m <= max_height_m");
  }
  if (!(max_yaw_rate_dps > 0 && max_pitch_rate_dps > 0)) throw Error("survey rates must be > 0");
  if (!(grid_m > 0)) throw Error("survey grid_m must be > 0");
  if (num_waypoints < 2) throw Error("survey num_waypoints must be >= 2");
  if (!(area_per_stop_m2 >= 0)) throw Error("survey area_per_stop_m2 must be >= 0");
  if (!(view_max_m > view_min_m)) throw Error("survey view_max_m must exceed view_min_m");
  if (laps < 1 || laps > 20) throw Error("survey laps must be in [1, 20]");
}

namespace {

// Occupancy of the camera's height band and the floor, on a 2D grid over the mesh.
struct FreeSpace {
  Eigen::Vector2d origin;  // world x, y of cell (0, 0)'s corner
  double cell = 0.05;
  cv::Mat safe;         // CV_8U, 1 where the camera may stand
  cv::Mat clearance_m;  // CV_32F, distance to the nearest obstacle cell, metres
  cv::Mat walls;        // CV_8U, 1 where a wall crosses the camera's height band (or empty)
  double floor_z = 0.0;
  double keep_m = 0.0;   // the clearance the walk keeps (SurveyPath::clearance_m)
  double area_m2 = 0.0;  // floor of the safe region

  // Cell of a world point, or false when it is off the grid.
  bool cellOf(const Eigen::Vector2d& p, int* i, int* j) const {
    *i = static_cast<int>(std::floor((p.x() - origin.x()) / cell));
    *j = static_cast<int>(std::floor((p.y() - origin.y()) / cell));
    return *i >= 0 && *j >= 0 && *i < safe.cols && *j < safe.rows;
  }

  Eigen::Vector2d centre(int i, int j) const {
    return origin + Eigen::Vector2d((i + 0.5) * cell, (j + 0.5) * cell);
  }
};

// A walk needs this much floor at the configured clearance; below it the clearance is lowered.
constexpr double kWalkArea_m2 = 1.0;
// Where even min_clearance_m leaves less than kWalkArea_m2, at least this much (a person turning
// on the spot in a toilet room) still gives a survey.
constexpr double kSmallestWalkArea_m2 = 0.25;

// The free space at one clearance: the largest connected region of the floor where the camera
// stays `clearance` from every surface of its height band (area_m2 0 when there is none).
FreeSpace freeSpaceAt(const LabelledMesh& mesh, const SurveyConfig& config, double clearance) {
  FreeSpace fs;
  fs.keep_m = clearance;
  fs.cell = config.grid_m;
  std::vector<float> zs;
  zs.reserve(mesh.vertices.size());
  Eigen::Vector2d lo(1e30, 1e30), hi(-1e30, -1e30);
  for (const auto& v : mesh.vertices) {
    zs.push_back(v.z());
    lo = lo.cwiseMin(v.head<2>().cast<double>());
    hi = hi.cwiseMax(v.head<2>().cast<double>());
  }
  if (zs.empty()) throw Error("survey: the mesh has no vertices");
  std::nth_element(zs.begin(), zs.begin() + zs.size() / 100, zs.end());
  fs.floor_z = zs[zs.size() / 100];  // robust against a few stray vertices below the floor
  fs.origin = lo - Eigen::Vector2d::Constant(fs.cell);
  const int nx = static_cast<int>(std::ceil((hi.x() - lo.x()) / fs.cell)) + 3;
  const int ny = static_cast<int>(std::ceil((hi.y() - lo.y()) / fs.cell)) + 3;
  cv::Mat occupied = cv::Mat::zeros(ny, nx, CV_8U);
  cv::Mat floor = cv::Mat::zeros(ny, nx, CV_8U);
  if (config.walls_block_view) fs.walls = cv::Mat::zeros(ny, nx, CV_8U);
  bool wall_face = false;
  const double band_lo = fs.floor_z + config.min_height_m - clearance;
  const double band_hi = fs.floor_z + config.max_height_m + clearance;
  auto mark = [&](const Eigen::Vector3f& p) {
    const int i = static_cast<int>((p.x() - fs.origin.x()) / fs.cell);
    const int j = static_cast<int>((p.y() - fs.origin.y()) / fs.cell);
    if (i < 0 || j < 0 || i >= nx || j >= ny) return;
    if (p.z() >= band_lo && p.z() <= band_hi) {
      occupied.at<uint8_t>(j, i) = 1;
      if (wall_face) fs.walls.at<uint8_t>(j, i) = 1;
    }
    if (p.z() < fs.floor_z + 0.1) floor.at<uint8_t>(j, i) = 1;
  };
  // Sample every triangle densely enough that no cell it crosses is missed.
  for (const auto& f : mesh.faces) {
    wall_face = !fs.walls.empty() && !mesh.semantic.empty() && mesh.semantic[f[0]] == 1;
    const Eigen::Vector3f& a = mesh.vertices[f[0]];
    const Eigen::Vector3f& b = mesh.vertices[f[1]];
    const Eigen::Vector3f& c = mesh.vertices[f[2]];
    const float zmin = std::min({a.z(), b.z(), c.z()}), zmax = std::max({a.z(), b.z(), c.z()});
    if (zmax < band_lo && zmin > fs.floor_z + 0.1) continue;
    if (zmin > band_hi) continue;
    const float edge = std::max({(b - a).norm(), (c - a).norm(), (c - b).norm()});
    const int n = std::max(1, static_cast<int>(std::ceil(edge / (0.5 * fs.cell))));
    for (int i = 0; i <= n; ++i) {
      for (int j = 0; i + j <= n; ++j) {
        const float s = static_cast<float>(i) / n, t = static_cast<float>(j) / n;
        mark(a + s * (b - a) + t * (c - a));
      }
    }
  }
  // Inside the room = over the floor; obstacles block the floor beneath them, so close gaps.
  cv::Mat inside;
  cv::morphologyEx(floor, inside, cv::MORPH_CLOSE,
                   cv::getStructuringElement(cv::MORPH_RECT, cv::Size(5, 5)));
  cv::Mat free_cells = (occupied == 0) / 255;
  cv::distanceTransform(free_cells, fs.clearance_m, cv::DIST_L2, cv::DIST_MASK_PRECISE);
  fs.clearance_m *= fs.cell;
  const double margin = clearance + fs.cell;  // the grid hides up to a cell
  fs.safe = (fs.clearance_m >= margin) & (inside > 0) & (occupied == 0);
  fs.safe /= 255;
  // Keep the largest connected free region: the room the camera walks in.
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(fs.safe, labels, stats, centroids, 8);
  int best = -1, best_area = 0;
  for (int k = 1; k < n; ++k) {
    if (stats.at<int>(k, cv::CC_STAT_AREA) > best_area) {
      best_area = stats.at<int>(k, cv::CC_STAT_AREA);
      best = k;
    }
  }
  if (best < 0) return fs;
  fs.area_m2 = best_area * fs.cell * fs.cell;
  fs.safe = (labels == best) / 255;
  return fs;
}

// The clearance to try after c: a third less (0.3, 0.2, 0.13), then min_clearance_m (directly
// once within 1 cm of it); c itself when there is none lower.
double lowerClearance(double c, const SurveyConfig& config) {
  if (c <= config.min_clearance_m) return c;
  const double next = c * 2.0 / 3.0;
  return next < config.min_clearance_m + 0.01 ? config.min_clearance_m : next;
}

// The free space at clearance_m, or, in a room too small to walk at it (a 2 x 1.5 m bathroom
// leaves 1 m^2 at 0.3 m), at the largest clearance down to min_clearance_m that leaves
// kWalkArea_m2: a scanner walks closer to the walls in a small room rather than not at all.
FreeSpace buildFreeSpace(const LabelledMesh& mesh, const SurveyConfig& config) {
  FreeSpace fs = freeSpaceAt(mesh, config, config.clearance_m);
  if (fs.area_m2 >= kWalkArea_m2) return fs;
  const double first_area = fs.area_m2;
  for (double c = config.clearance_m; lowerClearance(c, config) < c;) {
    c = lowerClearance(c, config);
    fs = freeSpaceAt(mesh, config, c);
    if (fs.area_m2 >= kWalkArea_m2) return fs;
  }
  if (fs.area_m2 >= kSmallestWalkArea_m2) return fs;
  std::ostringstream msg;
  msg << "survey: only " << first_area << " m^2 of floor is " << config.clearance_m
      << " m clear of surfaces at heights " << config.min_height_m << "-" << config.max_height_m
      << " m";
  if (config.min_clearance_m < config.clearance_m) {
    msg << " (" << fs.area_m2 << " m^2 at " << config.min_clearance_m << " m)";
  }
  msg << "; no room to walk";
  throw Error(msg.str());
}

using Cell = std::pair<int, int>;  // (i, j) = (column, row)

// Cheapest path on safe cells, preferring open space (cost grows near obstacles).
std::vector<Cell> shortestPath(const FreeSpace& fs, Cell from, Cell to) {
  const int nx = fs.safe.cols, ny = fs.safe.rows;
  std::vector<float> dist(static_cast<size_t>(nx) * ny, 1e30f);
  std::vector<int> parent(dist.size(), -1);
  using Item = std::pair<float, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  const int start = from.second * nx + from.first, goal = to.second * nx + to.first;
  dist[start] = 0.0f;
  queue.push({0.0f, start});
  while (!queue.empty()) {
    const auto [d, idx] = queue.top();
    queue.pop();
    if (idx == goal) break;
    if (d > dist[idx]) continue;
    const int i = idx % nx, j = idx / nx;
    for (int dj = -1; dj <= 1; ++dj) {
      for (int di = -1; di <= 1; ++di) {
        if (!di && !dj) continue;
        const int ni = i + di, nj = j + dj;
        if (ni < 0 || nj < 0 || ni >= nx || nj >= ny || !fs.safe.at<uint8_t>(nj, ni)) continue;
        const float step = (di && dj) ? 1.41421356f : 1.0f;
        const float open = fs.clearance_m.at<float>(nj, ni);
        const float cost = step * (1.0f + 0.5f / std::max(open, 0.05f));
        const int nidx = nj * nx + ni;
        if (d + cost < dist[nidx]) {
          dist[nidx] = d + cost;
          parent[nidx] = idx;
          queue.push({d + cost, nidx});
        }
      }
    }
  }
  std::vector<Cell> path;
  if (parent[goal] < 0 && goal != start) return path;
  for (int idx = goal; idx != -1; idx = parent[idx]) path.push_back({idx % nx, idx / nx});
  std::reverse(path.begin(), path.end());
  return path;
}

// Stops to spread over the free space: num_waypoints, and on a larger floor one per
// area_per_stop_m2 of it. With 10 over any floor, a 152 m^2 floor of four rooms was walked past
// 10 places: 61 of its 222 things were seen from 3 viewpoints (155 with 51 stops).
int stopCount(const FreeSpace& fs, const SurveyConfig& config) {
  if (config.area_per_stop_m2 <= 0.0) return config.num_waypoints;
  const double by_area = std::ceil(fs.area_m2 / config.area_per_stop_m2);
  return std::max(config.num_waypoints,
                  static_cast<int>(std::min<double>(by_area, kMaxSurveyStops)));
}

// Tour stops spread over the free space by farthest-point sampling.
std::vector<Cell> chooseWaypoints(const FreeSpace& fs, int count, Rng* rng) {
  std::vector<Cell> cells;
  for (int j = 0; j < fs.safe.rows; ++j) {
    for (int i = 0; i < fs.safe.cols; ++i) {
      if (fs.safe.at<uint8_t>(j, i)) cells.push_back({i, j});
    }
  }
  std::vector<Cell> stops = {cells[rng->below(cells.size())]};
  std::vector<double> nearest(cells.size(), 1e30);
  while (static_cast<int>(stops.size()) < count) {
    size_t best = 0;
    for (size_t k = 0; k < cells.size(); ++k) {
      const double di = cells[k].first - stops.back().first;
      const double dj = cells[k].second - stops.back().second;
      nearest[k] = std::min(nearest[k], di * di + dj * dj);
      if (nearest[k] > nearest[best]) best = k;
    }
    if (nearest[best] < 4.0) break;  // the space is smaller than `count` stops
    stops.push_back(cells[best]);
  }
  // Visit order: nearest neighbour from the first stop.
  std::vector<Cell> tour = {stops.front()};
  std::vector<bool> used(stops.size(), false);
  used[0] = true;
  for (size_t n = 1; n < stops.size(); ++n) {
    size_t best = 0;
    double best_d = 1e30;
    for (size_t k = 0; k < stops.size(); ++k) {
      if (used[k]) continue;
      const double di = stops[k].first - tour.back().first,
                   dj = stops[k].second - tour.back().second;
      if (di * di + dj * dj < best_d) {
        best_d = di * di + dj * dj;
        best = k;
      }
    }
    used[best] = true;
    tour.push_back(stops[best]);
  }
  return tour;
}

// The walk through the waypoints: `laps` rounds of the loop, odd ones backward, smoothed and
// closed, as world x, y points.
SurveyPath planWalk(const FreeSpace& fs, const std::vector<Cell>& stops, int laps) {
  std::vector<Cell> lap;
  for (size_t k = 0; k < stops.size(); ++k) {
    const auto leg = shortestPath(fs, stops[k], stops[(k + 1) % stops.size()]);
    if (leg.empty()) {
      throw Error("survey: stop " + std::to_string((k + 1) % stops.size()) +
                  " cannot be reached from stop " + std::to_string(k) + " on free floor");
    }
    lap.insert(lap.end(), leg.begin(), leg.empty() ? leg.end() : leg.end() - 1);
  }
  // A backward lap starts where the forward one ended (its first cell) and retraces it, so the
  // same surfaces come back into view from the other side.
  std::vector<Cell> cells = lap;
  std::vector<size_t> lap_begin = {0};
  for (int k = 1; k < laps && !lap.empty(); ++k) {
    lap_begin.push_back(cells.size());
    if (k % 2 == 1) {
      cells.push_back(lap.front());
      cells.insert(cells.end(), lap.rbegin(), lap.rend() - 1);
    } else {
      cells.insert(cells.end(), lap.begin(), lap.end());
    }
  }
  std::vector<Eigen::Vector2d> points;
  for (const Cell& c : cells) points.push_back(fs.centre(c.first, c.second));
  if (points.size() < 4) throw Error("survey: the free space is too small for a loop");
  // Moving-average smoothing on the closed loop; a smoothed point must stay on a safe cell.
  const int half = std::max(1, static_cast<int>(0.4 / fs.cell));
  for (int pass = 0; pass < 3; ++pass) {
    std::vector<Eigen::Vector2d> smooth(points.size());
    const int n = static_cast<int>(points.size());
    for (int k = 0; k < n; ++k) {
      Eigen::Vector2d sum = Eigen::Vector2d::Zero();
      for (int d = -half; d <= half; ++d) sum += points[static_cast<size_t>(((k + d) % n + n) % n)];
      smooth[k] = sum / (2 * half + 1);
      const int i = static_cast<int>((smooth[k].x() - fs.origin.x()) / fs.cell);
      const int j = static_cast<int>((smooth[k].y() - fs.origin.y()) / fs.cell);
      if (i < 0 || j < 0 || i >= fs.safe.cols || j >= fs.safe.rows || !fs.safe.at<uint8_t>(j, i)) {
        smooth[k] = points[k];
      }
    }
    points = smooth;
  }
  // Smoothing can stack points; zero-length segments would have no heading.
  SurveyPath path;
  std::vector<size_t> origin;  // index in `cells` of each kept point
  for (size_t k = 0; k < points.size(); ++k) {
    if (path.points.empty() || (points[k] - path.points.back()).norm() > 1e-4) {
      path.points.push_back(points[k]);
      origin.push_back(k);
    }
  }
  while (path.points.size() > 1 && (path.points.front() - path.points.back()).norm() <= 1e-4) {
    path.points.pop_back();
    origin.pop_back();
  }
  if (path.points.size() < 4) throw Error("survey: the free space is too small for a loop");
  std::vector<double> arc = {0.0};
  for (size_t k = 1; k <= path.points.size(); ++k) {
    arc.push_back(arc.back() + (path.points[k % path.points.size()] - path.points[k - 1]).norm());
  }
  path.length_m = arc.back();
  path.clearance_m = fs.keep_m;
  for (const Cell& stop : stops) path.stops.push_back(fs.centre(stop.first, stop.second));
  for (size_t begin : lap_begin) {
    const size_t k = std::lower_bound(origin.begin(), origin.end(), begin) - origin.begin();
    path.lap_start_m.push_back(arc[k]);
  }
  return path;
}

double wrapAngle(double a) {
  while (a > M_PI) a -= 2 * M_PI;
  while (a < -M_PI) a += 2 * M_PI;
  return a;
}

struct Target {
  Eigen::Vector3d centre;
  int looks = 0;
  std::vector<double> bearings;  // horizontal direction it was looked at from, each look
};

// Looks from bearings closer than this count as the same viewpoint (SynthConfig's default for
// distinct views).
constexpr double kSameViewRad = 20.0 * M_PI / 180.0;

// Earlier looks at the target from about this bearing.
int looksFrom(const Target& tg, double bearing) {
  int n = 0;
  for (double b : tg.bearings) n += std::abs(wrapAngle(b - bearing)) < kSameViewRad ? 1 : 0;
  return n;
}

std::vector<Target> objectTargets(const LabelledMesh& mesh) {
  std::map<int32_t, std::pair<Eigen::Vector3d, int>> sums;
  for (size_t v = 0; v < mesh.vertices.size() && !mesh.instance.empty(); ++v) {
    const int32_t id = mesh.instance[v];
    const int32_t cls = mesh.semantic.empty() ? 0 : mesh.semantic[v];
    if (id <= 0 || isStuffClass(cls)) continue;
    // Eigen vectors are not zero-initialised: start each sum explicitly.
    auto& s = sums.try_emplace(id, Eigen::Vector3d::Zero(), 0).first->second;
    s.first += mesh.vertices[v].cast<double>();
    ++s.second;
  }
  std::vector<Target> targets;
  for (const auto& [id, s] : sums) {
    if (s.second >= 20) targets.push_back({s.first / s.second, 0, {}});
  }
  return targets;
}

// True when a wall of the free-space grid lies between the eye and the target (seen from
// above). The last 15 cm before the target are not tested: a picture shares its wall's cells.
bool wallBetween(const FreeSpace& fs, const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  if (fs.walls.empty()) return false;
  const Eigen::Vector2d a = eye.head<2>(), b = target.head<2>();
  const double length = (b - a).norm();
  // Half-cell steps cannot step over an axis-aligned line of wall cells.
  for (double s = 0.0; s < length - 0.15; s += 0.5 * fs.cell) {
    int i = 0, j = 0;
    if (fs.cellOf(a + (b - a) * (s / length), &i, &j) && fs.walls.at<uint8_t>(j, i)) return true;
  }
  return false;
}

// The camera walking the closed loop at speed_mps, head turning to the objects (the stops'
// draws have been taken from `rng` already: the rest of the stream picks the looks).
std::vector<StampedPose> posesAlong(const LabelledMesh& mesh, const FreeSpace& fs,
                                    const std::vector<Eigen::Vector2d>& loop,
                                    const SurveyConfig& config, Rng* rng_ptr) {
  Rng& rng = *rng_ptr;
  std::vector<double> arc = {0.0};
  for (size_t k = 1; k <= loop.size(); ++k)
    arc.push_back(arc.back() + (loop[k % loop.size()] - loop[k - 1]).norm());
  const double loop_length = arc.back();
  std::vector<Target> targets = objectTargets(mesh);

  const double dt = 1.0 / config.rate_hz;
  const double max_dyaw = config.max_yaw_rate_dps * M_PI / 180.0 * dt;
  const double max_dpitch = config.max_pitch_rate_dps * M_PI / 180.0 * dt;
  const double mid = 0.5 * (config.min_height_m + config.max_height_m);
  const double amp = 0.4 * (config.max_height_m - config.min_height_m);
  const double phase = rng.uniform(0.0, 2 * M_PI);
  std::vector<StampedPose> out;
  double yaw = 0.0, pitch = -0.2, look_timer = 1e9;
  int target = -1;
  size_t seg = 0;
  for (int k = 0; k < config.num_frames; ++k) {
    const double t = k * dt;
    const double s = std::fmod(t * config.speed_mps, loop_length);
    if (s < arc[seg]) seg = 0;
    while (seg + 1 < arc.size() - 1 && arc[seg + 1] <= s) ++seg;
    const Eigen::Vector2d& a = loop[seg];
    const Eigen::Vector2d& b = loop[(seg + 1) % loop.size()];
    const double frac = (s - arc[seg]) / std::max(1e-9, arc[seg + 1] - arc[seg]);
    const Eigen::Vector2d xy = a + frac * (b - a);
    const Eigen::Vector2d heading = (b - a).normalized();
    const double z = fs.floor_z + mid + amp * std::sin(2 * M_PI * t / 20.0 + phase);
    const Eigen::Vector3d eye(xy.x(), xy.y(), z);

    // Pick what to look at: an object at a comfortable distance, not too far off the walking
    // direction, looked at least recently; keep it for at least min_look_s.
    look_timer += dt;
    auto suitable = [&](const Target& tg, double* score) {
      const Eigen::Vector3d d = tg.centre - eye;
      const double range = d.head<2>().norm();
      const double off =
          std::abs(wrapAngle(std::atan2(d.y(), d.x()) - std::atan2(heading.y(), heading.x())));
      if (range < config.view_min_m * 0.5 || range > config.view_max_m * 1.5 || off > 0.6 * M_PI)
        return false;
      if (wallBetween(fs, eye, tg.centre)) return false;
      // Revisiting surveys prefer what was not looked at from here: the laps exist for new
      // viewpoints (a single lap keeps the head schedule its rooms were measured with).
      const int seen = config.laps > 1 ? looksFrom(tg, std::atan2(d.y(), d.x())) : tg.looks;
      *score = -seen - 0.3 * std::abs(range - 0.5 * (config.view_min_m + config.view_max_m)) -
               0.5 * off + 0.01 * rng.uniform();
      return true;
    };
    double dummy = 0.0;
    if (target < 0 || look_timer >= config.min_look_s || !suitable(targets[target], &dummy)) {
      if (look_timer >= config.min_look_s || target < 0) {
        int best = -1;
        double best_score = -1e30, score = 0.0;
        for (size_t i = 0; i < targets.size(); ++i) {
          if (suitable(targets[i], &score) && score > best_score) {
            best_score = score;
            best = static_cast<int>(i);
          }
        }
        if (best != target && best >= 0) {
          target = best;
          ++targets[best].looks;
          const Eigen::Vector3d d = targets[best].centre - eye;
          targets[best].bearings.push_back(std::atan2(d.y(), d.x()));
          look_timer = 0.0;
        } else if (best < 0) {
          target = -1;
        }
      }
    }
    double want_yaw = std::atan2(heading.y(), heading.x());
    double want_pitch = -0.25;
    if (target >= 0) {
      const Eigen::Vector3d d = targets[target].centre - eye;
      want_yaw = std::atan2(d.y(), d.x());
      want_pitch = std::clamp(std::atan2(d.z(), d.head<2>().norm()), -0.9, 0.25);
    }
    if (!std::isfinite(want_yaw) || !std::isfinite(want_pitch)) {
      want_yaw = yaw;  // keep looking where we look; never let a NaN into the trajectory
      want_pitch = pitch;
    }
    if (k == 0) {
      yaw = want_yaw;
      pitch = want_pitch;
    } else {
      yaw = wrapAngle(yaw + std::clamp(wrapAngle(want_yaw - yaw), -max_dyaw, max_dyaw));
      pitch += std::clamp(want_pitch - pitch, -max_dpitch, max_dpitch);
    }
    const Eigen::Vector3d forward(std::cos(pitch) * std::cos(yaw), std::cos(pitch) * std::sin(yaw),
                                  std::sin(pitch));
    const Eigen::Vector3d right = forward.cross(Eigen::Vector3d::UnitZ()).normalized();
    StampedPose pose;
    pose.utime = static_cast<int64_t>(std::llround(t * 1e6));
    pose.T_W_C.linear().col(0) = right;
    pose.T_W_C.linear().col(1) = forward.cross(right);
    pose.T_W_C.linear().col(2) = forward;
    pose.T_W_C.translation() = eye;
    if (!pose.T_W_C.matrix().allFinite()) {
      throw Error("survey: non-finite pose at frame " + std::to_string(k) + " (planner bug)");
    }
    out.push_back(pose);
  }
  return out;
}

// Free-space cells of the stops: the nearest safe cell within 0.5 m of each.
std::vector<Cell> stopCells(const FreeSpace& fs, const std::vector<Eigen::Vector2d>& stops) {
  const int reach = static_cast<int>(std::ceil(0.5 / fs.cell));
  std::vector<Cell> cells;
  for (size_t k = 0; k < stops.size(); ++k) {
    if (!stops[k].allFinite()) throw Error("survey: stop " + std::to_string(k) + " is not finite");
    // Far off the grid: no cell can be near (and the cell index must not overflow).
    const Eigen::Vector2d grid = (stops[k] - fs.origin) / fs.cell;
    if (grid.minCoeff() < -reach || grid.x() > fs.safe.cols + reach ||
        grid.y() > fs.safe.rows + reach) {
      std::ostringstream msg;
      msg << "survey: stop " << k << " at (" << stops[k].x() << ", " << stops[k].y()
          << ") is outside the mesh";
      throw Error(msg.str());
    }
    int i0 = 0, j0 = 0;
    fs.cellOf(stops[k], &i0, &j0);
    Cell best{-1, -1};
    int best_d = std::numeric_limits<int>::max();
    for (int dj = -reach; dj <= reach; ++dj) {
      for (int di = -reach; di <= reach; ++di) {
        const int i = i0 + di, j = j0 + dj;
        if (i < 0 || j < 0 || i >= fs.safe.cols || j >= fs.safe.rows) continue;
        if (!fs.safe.at<uint8_t>(j, i) || di * di + dj * dj > reach * reach) continue;
        if (di * di + dj * dj < best_d) {
          best_d = di * di + dj * dj;
          best = {i, j};
        }
      }
    }
    if (best.first < 0) {
      std::ostringstream msg;
      msg << "survey: stop " << k << " at (" << stops[k].x() << ", " << stops[k].y()
          << ") is not within 0.5 m of floor the camera can walk on";
      throw Error(msg.str());
    }
    cells.push_back(best);
  }
  if (cells.size() < 2) throw Error("survey: a walk needs at least 2 stops");
  return cells;
}

// The walk through given stops at the configured clearance or, where a stop has no free floor
// within 0.5 m or cannot be reached from the one before at it, at the largest lower clearance
// (down to min_clearance_m) at which every stop has and can: a doorway that an opened door
// and a tall object beside it narrow, a stop in a corner. The free space it was planned on
// goes to `fs`. Throws the error of the configured clearance when no clearance works.
SurveyPath walkThrough(const LabelledMesh& mesh, const SurveyConfig& config,
                       const std::vector<Eigen::Vector2d>& stops, FreeSpace* fs) {
  *fs = buildFreeSpace(mesh, config);
  try {
    return planWalk(*fs, stopCells(*fs, stops), config.laps);
  } catch (const Error&) {
    for (double c = fs->keep_m; lowerClearance(c, config) < c;) {
      c = lowerClearance(c, config);
      FreeSpace lower = freeSpaceAt(mesh, config, c);
      if (lower.area_m2 < kSmallestWalkArea_m2) continue;
      try {
        SurveyPath path = planWalk(lower, stopCells(lower, stops), config.laps);
        *fs = std::move(lower);
        return path;
      } catch (const Error&) {
        // Not at this clearance either; stops that none can help (not finite, far outside the
        // mesh) end with the error of the first.
      }
    }
    throw;
  }
}

}  // namespace

std::vector<StampedPose> planSurvey(const LabelledMesh& mesh, const SurveyConfig& config,
                                    uint64_t seed) {
  config.check();
  Rng rng(hashSeed(seed, 0x5u));
  const FreeSpace fs = buildFreeSpace(mesh, config);
  const std::vector<Eigen::Vector2d> loop =
      planWalk(fs, chooseWaypoints(fs, stopCount(fs, config), &rng), config.laps).points;
  return posesAlong(mesh, fs, loop, config, &rng);
}

std::vector<StampedPose> planSurveyThrough(const LabelledMesh& mesh, SurveyConfig config,
                                           const std::vector<Eigen::Vector2d>& stops,
                                           uint64_t seed) {
  const bool once = config.num_frames == 0;
  if (once) config.num_frames = 1;
  config.check();
  Rng rng(hashSeed(seed, 0x5u));
  FreeSpace fs;
  const SurveyPath path = walkThrough(mesh, config, stops, &fs);
  if (once) config.num_frames = framesToWalk(path, config);
  return posesAlong(mesh, fs, path.points, config, &rng);
}

SurveyPath planSurveyPathThrough(const LabelledMesh& mesh, const SurveyConfig& config,
                                 const std::vector<Eigen::Vector2d>& stops) {
  SurveyConfig checked = config;
  if (checked.num_frames == 0) checked.num_frames = 1;
  checked.check();
  FreeSpace fs;
  return walkThrough(mesh, checked, stops, &fs);
}

SurveyPath planSurveyPath(const LabelledMesh& mesh, const SurveyConfig& config, uint64_t seed) {
  config.check();
  // The same stream as planSurvey's: its first draws choose the stops.
  Rng rng(hashSeed(seed, 0x5u));
  const FreeSpace fs = buildFreeSpace(mesh, config);
  SurveyPath path = planWalk(fs, chooseWaypoints(fs, stopCount(fs, config), &rng), config.laps);
  path.free_area_m2 = fs.area_m2;
  return path;
}

int framesToWalk(const SurveyPath& path, const SurveyConfig& config) {
  const double frames = std::ceil(path.length_m / config.speed_mps * config.rate_hz);
  // A walk too long for an int of frames is no survey anyone renders.
  if (!(frames < 1e9)) throw Error("survey: the walk is too long to render");
  return std::max(2, static_cast<int>(frames));
}

double minClearance(const std::vector<StampedPose>& trajectory, const LabelledMesh& mesh) {
  double best = std::numeric_limits<double>::infinity();
  const NearestPointIndex index(&mesh.vertices);
  for (const StampedPose& p : trajectory) {
    const Eigen::Vector3f q = p.T_W_C.translation().cast<float>();
    const int64_t i = index.nearest(q);
    if (i >= 0) best = std::min(best, static_cast<double>((mesh.vertices[i] - q).norm()));
  }
  return best;
}

}  // namespace panmap

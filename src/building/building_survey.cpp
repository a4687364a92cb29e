#include <algorithm>
#include <vector>

#include "panmap/building/building.h"

namespace panmap {

SurveyConfig buildingSurveyConfig() {
  SurveyConfig config;
  config.num_frames = 0;
  config.rate_hz = 5.0;
  config.speed_mps = 0.5;
  // Doors are 0.8-0.9 m wide and the open panel takes its thickness: 0.3 m would leave no
  // free cell in the doorway.
  config.clearance_m = 0.25;
  // An opened door can leave a narrower way into its room than the closed one did (its panel
  // beside a shower curtain or a tall cabinet): the walk squeezes past, down to this, rather
  // than leaving the room out (planSurveyThrough lowers the clearance only where it must).
  config.min_clearance_m = 0.05;
  config.walls_block_view = true;
  return config;
}

std::vector<Eigen::Vector2d> buildingSurveyStops(const Building& building) {
  const double mid_y = 0.5 * building.corridor.sizes().y();
  std::vector<Eigen::Vector2d> stops = {{building.corridor.min().x() + 0.8, mid_y}};
  for (const BuildingRoom& room : building.rooms) {
    const Eigen::Vector2d door = room.door.center().cast<double>();
    stops.push_back({door.x(), mid_y});
    // The room's largest walkway strip: its near end, middle and far end from the door.
    const Eigen::AlignedBox2f* strip = nullptr;
    for (const auto& box : room.clear_floor) {
      if (!strip || box.volume() > strip->volume()) strip = &box;
    }
    if (strip) {
      const Eigen::Vector2d c = strip->center().cast<double>();
      const Eigen::Vector2d size = strip->sizes().cast<double>();
      const int axis = size.x() >= size.y() ? 0 : 1;
      const double reach = std::max(0.0, 0.5 * size[axis] - 0.3);
      Eigen::Vector2d a = c, b = c;
      a[axis] -= reach;
      b[axis] += reach;
      if ((a - door).norm() > (b - door).norm()) std::swap(a, b);
      stops.push_back(a);
      stops.push_back(c);
      stops.push_back(b);
    }
    stops.push_back({door.x(), mid_y});
  }
  return stops;
}

std::vector<StampedPose> planBuildingSurvey(const Building& building, const SurveyConfig& config,
                                            uint64_t seed) {
  return planSurveyThrough(building.mesh, config, buildingSurveyStops(building), seed);
}

}  // namespace panmap

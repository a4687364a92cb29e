#pragma once

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/labelled_mesh.h"
#include "panmap/core/pose.h"
#include "panmap/sim/procedural_room.h"
#include "panmap/sim/trajectory.h"

namespace panmap {

/// Parameters of the building generator: one floor, a straight corridor with procedural rooms
/// on both sides, each room's door opened onto the corridor.
struct BuildingConfig {
  int min_rooms = 20;                 ///< at least this many rooms, >= 1
  double min_floor_area_m2 = 1000.0;  ///< rooms are added until rooms + corridor reach this
  int max_rooms = 200;                ///< give up (Error) beyond this many rooms
  float corridor_width_m = 2.4f;      ///< >= 1.5 m
  float corridor_ceiling_m = 2.5f;    ///< above every door (>= 2.3 m)
  float wall_thickness_m = 0.15f;     ///< between rooms and between a room and the corridor
  /// Every room (RoomStyle, sizes, mesh density). Rooms are rectangles: l_shape_probability
  /// is ignored. The default rooms are 4-9 m wide, so 20 of them and the corridor pass 1000 m2.
  RoomConfig room = defaultRoom();
  /// Throws Error naming the bad field.
  void check() const;
  /// RoomConfig with sides of 4-9 m.
  static RoomConfig defaultRoom();
};

/// One room of a building, world frame.
struct BuildingRoom {
  uint64_t seed = 0;          ///< generateRoom's seed of the room before it was opened
  Eigen::AlignedBox2f floor;  ///< the room's floor rectangle, metres
  Eigen::AlignedBox2f door;   ///< the doorway's footprint through the wall, metres
  bool north = true;          ///< on the +y side of the corridor
  /// The room's walkway (ProceduralRoom::clear_floor), turned and moved into place.
  std::vector<Eigen::AlignedBox2f> clear_floor;
  int32_t first_instance = 0;  ///< its instances are first_instance .. last_instance
  int32_t last_instance = 0;
};

/// A generated floor: the labelled mesh and what is in it.
///
/// Conventions: z up, floor at z = 0; the corridor runs along x over [0, length] x
/// [0, corridor_width]; rooms line it on both sides, walls `wall_thickness_m` thick. Instance
/// ids are unique across the building (every room's walls, floor and ceiling are instances of
/// their own, as in a room); the corridor's walls, floor and ceiling come first (1, 2, 3).
struct Building {
  LabelledMesh mesh;
  std::vector<RoomObject> objects;  ///< every instance of the mesh, world frame
  std::vector<BuildingRoom> rooms;  ///< in the order the survey visits them
  Eigen::AlignedBox2f corridor;
  double floor_area_m2 = 0.0;  ///< rooms and corridor (walls excluded)
};

/// Generates a building. The same seed and config give the identical mesh. Throws Error when a
/// room does not generate (see generateRoom) or max_rooms do not reach the area.
Building generateBuilding(uint64_t seed, const BuildingConfig& config = BuildingConfig());

/// The survey config a building is walked with: 5 Hz, 0.5 m/s, walls hiding what is behind
/// them, 0.25 m clearance (doors are 0.8-0.9 m wide), one pass (num_frames = 0).
SurveyConfig buildingSurveyConfig();

/// Stops of a survey through the building: along the corridor from its west end, into every
/// room through its door (the middle and both ends of its longest walkway strip) and out again.
std::vector<Eigen::Vector2d> buildingSurveyStops(const Building& building);

/// A walk through every room of the building: planSurveyThrough the stops above.
std::vector<StampedPose> planBuildingSurvey(const Building& building, const SurveyConfig& config,
                                            uint64_t seed);

}  // namespace panmap

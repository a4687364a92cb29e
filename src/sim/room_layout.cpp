#include "panmap/sim/internal/room_layout.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <set>
#include <vector>

#include "panmap/core/classes.h"

namespace panmap {
namespace internal {
namespace room {
namespace {

constexpr float kCorridorM = 0.9f;    // clear walkway kept between furniture bands
constexpr float kMaxBandM = 2.1f;     // deepest furniture band along a wall (a bed, head on)
constexpr float kIslandMinM = 2.2f;   // smallest island zone worth a central table
constexpr float kClearanceM = 0.03f;  // gap between separately placed groups
constexpr float kStepM = 0.05f;       // lattice of candidate positions
constexpr float kCameraClearanceM = 0.3f;
constexpr std::array<float, 3> kCameraHeightsM = {1.2f, 1.5f, 1.7f};
constexpr float kFreeCellM = 0.1f;
// The generator keeps more free space than the 30 % it promises, so that other samplings of
// the same boxes (the tests', a trajectory planner's) still find it.
constexpr float kMinFreeFraction = 0.4f;

}  // namespace

Layout::Layout(const RoomShape& shape, float ceiling_m, float band_m, bool island)
    : shape_(shape), ceiling_m_(ceiling_m), band_m_(band_m) {
  for (size_t i = 0; i < shape.polygon.size(); ++i) {
    const Vector2f a = shape.polygon[i];
    const Vector2f d = shape.polygon[(i + 1) % shape.polygon.size()] - a;
    WallSegment w;
    w.start = a;
    w.length_m = d.norm();
    // Walls are axis-aligned: the unit axis along the longer component.
    w.along = std::abs(d.x()) >= std::abs(d.y()) ? Vector2f(d.x() > 0.0f ? 1.0f : -1.0f, 0.0f)
                                                 : Vector2f(0.0f, d.y() > 0.0f ? 1.0f : -1.0f);
    w.inward = Vector2f(-w.along.y(), w.along.x());
    walls_.push_back(w);
  }
  for (const Box2& arm : shape.arms) core_.push_back(eroded(arm, band_m));
  if (island) island_zone_ = eroded(core_.front(), kCorridorM);
  cells_x_ = static_cast<int>(std::ceil(shape.width_m / kFreeCellM));
  cells_y_ = static_cast<int>(std::ceil(shape.depth_m / kFreeCellM));
  state_.assign(static_cast<size_t>(cells_x_) * cells_y_, kOutside);
  for (int j = 0; j < cells_y_; ++j) {
    for (int i = 0; i < cells_x_; ++i) {
      const Vector2f c = cellCentre(i, j);
      if (!shape.contains(c, 0.0f)) continue;
      ++floor_cells_;
      const bool near_wall = shape.distanceToWalls(c) < kCameraClearanceM + 0.02f;
      state_[j * cells_x_ + i] = near_wall ? kBlocked : kFree;
      free_cells_ += near_wall ? 0 : 1;
    }
  }
}

bool Layout::placeOnWall(RoomRng* rng, const Module& module) {
  if (module.empty()) return false;
  const float width = module.footprint().max().x();
  std::vector<size_t> order(walls_.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  rng->shuffle(&order);
  for (size_t w : order) {
    const WallSegment& wall = walls_[w];
    const float lo = module.end_margin_m;
    const float hi = wall.length_m - width - module.end_margin_m;
    if (hi < lo) continue;
    const int steps = static_cast<int>((hi - lo) / kStepM) + 1;
    const int start = rng->uniformInt(0, steps - 1);
    for (int t = 0; t < steps; ++t) {
      float s = lo + static_cast<float>((start + t) % steps) * kStepM;
      // Flush with the far corner rather than a slit a sensor cannot see into.
      if (hi - s < 0.01f) s = hi;
      Frame frame;
      frame.origin = wall.start + s * wall.along;
      frame.along = wall.along;
      frame.inward = wall.inward;
      if (tryCommit(module.transformed(frame), false)) return true;
    }
  }
  return false;
}

bool Layout::placeIsland(RoomRng* rng, Module module) {
  if (!hasIslandZone() || module.empty()) return false;
  const int first_turn = rng->uniformInt(0, 1);
  for (int t = 0; t < 2; ++t) {
    Module turned = module;
    turned.rotate(first_turn + t);
    turned.normalise(true);
    const Vector2f size = turned.footprint().sizes();
    const Vector2f room = island_zone_.sizes() - size;
    if (room.x() < 0.0f || room.y() < 0.0f) continue;
    const int nx = static_cast<int>(room.x() / kStepM) + 1;
    const int ny = static_cast<int>(room.y() / kStepM) + 1;
    const int start = rng->uniformInt(0, nx * ny - 1);
    for (int k = 0; k < nx * ny; ++k) {
      const int idx = (start + k) % (nx * ny);
      Frame frame;
      frame.origin = island_zone_.min() + Vector2f(static_cast<float>(idx % nx) * kStepM,
                                                   static_cast<float>(idx / nx) * kStepM);
      if (tryCommit(turned.transformed(frame), true)) {
        island_placed_ = true;
        return true;
      }
    }
  }
  return false;
}

std::set<int32_t> Layout::evaluatedClassesPresent() const {
  std::set<int32_t> present;
  const std::vector<int32_t>& eval = evaluatedClasses();
  for (const Item& item : items_) {
    if (std::find(eval.begin(), eval.end(), item.semantic) != eval.end()) {
      present.insert(item.semantic);
    }
  }
  return present;
}

std::vector<Box2> Layout::clearFloor() const {
  if (!island_placed_) return core_;
  const Box2& c = core_.front();
  const Box2& z = island_zone_;
  return {Box2(c.min(), Vector2f(c.max().x(), z.min().y())),
          Box2(Vector2f(c.min().x(), z.max().y()), c.max()),
          Box2(Vector2f(c.min().x(), z.min().y()), Vector2f(z.min().x(), z.max().y())),
          Box2(Vector2f(z.max().x(), z.min().y()), Vector2f(c.max().x(), z.max().y()))};
}

Vector2f Layout::cellCentre(int i, int j) const {
  return Vector2f((static_cast<float>(i) + 0.5f) * kFreeCellM,
                  (static_cast<float>(j) + 0.5f) * kFreeCellM);
}

bool Layout::fits(const Module& world, bool island) const {
  for (const Item& item : world.items) {
    for (const Part& p : item.parts) {
      const Box2 r = xy(p.box);
      if (!shape_.containsRect(r)) return false;
      if (p.box.min().z() < -kTolM || p.box.max().z() > ceiling_m_ - 0.05f) return false;
      if (island) {
        if (!island_zone_.contains(r)) return false;
      } else {
        for (const Box2& c : core_) {
          if (!c.isEmpty() && overlaps2(r, c, 0.0f)) return false;
        }
      }
    }
    const Box3 b = item.bounds();
    for (const Box3& other : blockers_) {
      if (overlaps3(b, other, kClearanceM)) return false;
    }
  }
  for (const Box3& r : world.reserved) {
    if (!shape_.containsRect(xy(r))) return false;
    for (const Box3& other : blockers_) {
      if (overlaps3(r, other, kClearanceM)) return false;
    }
  }
  return true;
}

bool Layout::freeSpaceAfter(const Module& world, std::vector<int>* newly) const {
  const float reach = kCameraClearanceM + 0.02f;
  for (const Item& item : world.items) {
    const Box3 b = item.bounds();
    if (b.max().z() < kCameraHeightsM.front() - reach) continue;
    const int i0 = std::max(0, static_cast<int>((b.min().x() - reach) / kFreeCellM));
    const int j0 = std::max(0, static_cast<int>((b.min().y() - reach) / kFreeCellM));
    const int i1 = std::min(cells_x_ - 1, static_cast<int>((b.max().x() + reach) / kFreeCellM));
    const int j1 = std::min(cells_y_ - 1, static_cast<int>((b.max().y() + reach) / kFreeCellM));
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) {
        if (state_[j * cells_x_ + i] != kFree) continue;
        const Vector2f c = cellCentre(i, j);
        for (float z : kCameraHeightsM) {
          if (b.exteriorDistance(Vector3f(c.x(), c.y(), z)) < reach) {
            newly->push_back(j * cells_x_ + i);
            break;
          }
        }
      }
    }
  }
  std::sort(newly->begin(), newly->end());
  newly->erase(std::unique(newly->begin(), newly->end()), newly->end());
  return static_cast<float>(free_cells_ - static_cast<int>(newly->size())) >=
         kMinFreeFraction * static_cast<float>(floor_cells_);
}

bool Layout::tryCommit(const Module& world, bool island) {
  if (!fits(world, island)) return false;
  std::vector<int> newly;
  if (!freeSpaceAfter(world, &newly)) return false;
  for (int c : newly) state_[c] = kBlocked;
  free_cells_ -= static_cast<int>(newly.size());
  for (const Item& item : world.items) {
    items_.push_back(item);
    blockers_.push_back(item.bounds());
  }
  for (const Box3& r : world.reserved) {
    blockers_.push_back(r);
    reserved_.push_back(r);
  }
  return true;
}

std::unique_ptr<Layout> furnish(const RoomShape& shape, float ceiling_m, const RoomConfig& config,
                                RoomRng* rng) {
  // A central table needs a corridor on each side; it only goes into large rectangles.
  const float min_arm = shape.minArmM();
  const bool island = !shape.lShaped() &&
                      min_arm >= 2.0f * 1.0f + 2.0f * kCorridorM + kIslandMinM && rng->chance(0.6);
  const float band = island
                         ? std::min(kMaxBandM, 0.5f * (min_arm - 2.0f * kCorridorM - kIslandMinM))
                         : std::clamp(0.5f * (min_arm - kCorridorM), 0.3f, kMaxBandM);
  auto layout = std::make_unique<Layout>(shape, ceiling_m, band, island);
  const BuildContext ctx = layout->context();

  // Compulsory: a door, the hard cases (touching cabinets, a chair under a table), a window.
  if (!placeSome(layout.get(), rng, [&] { return buildDoor(rng, ctx); })) return nullptr;
  bool table = false;
  if (layout->hasIslandZone()) {
    table = layout->placeIsland(rng, buildIslandTableGroup(rng, true)) ||
            layout->placeIsland(rng, buildIslandTableGroup(rng, false));
  }
  auto table_group = [&] { return buildTableGroup(rng, ctx); };
  auto cabinets = [&] { return buildCabinets(rng, ctx); };
  if (!table && !placeSome(layout.get(), rng, table_group, 6)) return nullptr;
  if (!placeSome(layout.get(), rng, cabinets, 6)) return nullptr;
  if (!placeSome(layout.get(), rng, [&] { return buildWindow(rng, ctx, true); }) &&
      !placeSome(layout.get(), rng, [&] { return buildWindow(rng, ctx, false); })) {
    return nullptr;
  }
  if (config.style == RoomStyle::kScanNetLike) {
    return furnishScanNetLike(layout.get(), rng, config) ? std::move(layout) : nullptr;
  }

  // Optional groups in random order until the drawn number of classes is reached (the
  // pictures, placed last, add one).
  std::vector<Group> groups = {Group::kCounter,   Group::kFridge, Group::kDesk,
                               Group::kBookshelf, Group::kSofa,   Group::kBed,
                               Group::kBath,      Group::kToilet, Group::kOther};
  rng->shuffle(&groups);
  const int target =
      rng->uniformInt(config.min_classes, static_cast<int>(evaluatedClasses().size()));
  for (Group g : groups) {
    if (static_cast<int>(layout->evaluatedClassesPresent().size()) + 1 >= target) break;
    placeSome(layout.get(), rng, [&] { return buildGroup(g, rng, ctx); });
  }
  if (rng->chance(0.6)) placeSome(layout.get(), rng, [&] { return buildBoxes(rng, ctx); });
  if (rng->chance(0.5)) placeSome(layout.get(), rng, [&] { return buildOtherFurniture(rng, ctx); });
  const int pictures = rng->uniformInt(1, 3);
  int placed = 0;
  for (int i = 0; i < pictures; ++i) {
    placed += placeSome(layout.get(), rng, [&] { return buildPicture(rng, ctx); }) ? 1 : 0;
  }
  if (placed == 0) return nullptr;
  if (static_cast<int>(layout->evaluatedClassesPresent().size()) < config.min_classes) {
    return nullptr;
  }
  return layout;
}

}  // namespace room
}  // namespace internal
}  // namespace panmap

#include "panmap/sim/internal/room_clutter.h"

#include <algorithm>
#include <set>
#include <vector>

#include "panmap/sim/internal/room_loose_items.h"
#include "panmap/sim/internal/room_mesh.h"

namespace panmap {
namespace internal {
namespace room {
namespace {

constexpr int kTriesPerSpot = 8;
// Instances kept for the unannotated piles, and loose things a room gets at least.
constexpr int kPileReserve = 10;
constexpr int kMinLoose = 12;
// Small things (under 0.3 m) on surfaces, monitors' neighbours included, at least.
constexpr int kMinSmall = 10;

// Classes whose box tops carry loose things.
bool carries(int32_t c) {
  return c == kTable || c == kDesk || c == kCounter || c == kCabinet || c == kDresser ||
         c == kNightStand || c == kBookshelf || c == kShelves || c == kBed || c == kSofa ||
         c == kOtherFurniture || c == kRefrigerator;
}

// Classes whose feet and sides clutter gets pushed against.
bool standsOnFloor(int32_t c) {
  return c == kCabinet || c == kBed || c == kChair || c == kSofa || c == kTable ||
         c == kBookshelf || c == kCounter || c == kDesk || c == kDresser || c == kNightStand ||
         c == kRefrigerator || c == kToilet || c == kBathtub || c == kOtherFurniture || c == kBox;
}

// A box top something can be put on.
struct Surface {
  Box3 part;
  int32_t semantic = 0;
};

// `local` turned by quarter turns about z, its bounds moved back to start at the origin.
Item turned(const Item& local, int quarter_turns) {
  Item out = local;
  for (Part& p : out.parts) p.box = rotateQuarter(p.box, quarter_turns);
  const Vector3f lo = out.bounds().min();
  for (Part& p : out.parts) p.box.translate(Vector3f(-lo.x(), -lo.y(), 0.0f));
  return out;
}

Item moved(Item item, const Vector3f& offset) {
  for (Part& p : item.parts) p.box.translate(offset);
  return item;
}

// Places loose items in a layout; every position comes from `rng` in a fixed order.
class Placer {
 public:
  Placer(Layout* layout, RoomRng* rng) : layout_(layout), rng_(rng) {
    for (const Item& item : layout->items()) {
      for (const Part& p : item.parts) {
        const Vector3f s = p.box.sizes();
        if (carries(item.semantic) && !p.cylinder && s.x() >= 0.1f && s.y() >= 0.1f &&
            p.box.max().z() >= 0.2f && p.box.max().z() <= layout->ceilingM() - 0.3f) {
          surfaces_.push_back(Surface{p.box, item.semantic});
        }
        if (standsOnFloor(item.semantic) && !p.cylinder && p.box.min().z() <= kTolM &&
            s.z() >= 0.08f) {
          feet_.push_back(p.box);
        }
      }
      // The monitor's foot is its first part (buildDesk).
      if (item.name == "monitor") monitors_.push_back(item.parts.front().box);
    }
  }

  /// Surfaces loose things can stand on.
  bool hasSurfaces() const { return !surfaces_.empty(); }
  /// Feet of monitors.
  const std::vector<Box3>& monitors() const { return monitors_; }
  /// A random surface.
  const Surface& pickSurface() {
    return surfaces_[rng_->uniformInt(0, static_cast<int>(surfaces_.size()) - 1)];
  }

  /// On the surface's top, turned at random, anywhere or pushed to one of its edges (against a
  /// wall where the furniture stands at one, against a neighbour where it has one).
  bool onSurface(const Item& local, const Surface& s) {
    for (int t = 0; t < kTriesPerSpot; ++t) {
      const Item item = turned(local, rng_->uniformInt(0, 3));
      const Vector3f size = item.bounds().sizes();
      const float room_x = s.part.sizes().x() - size.x(), room_y = s.part.sizes().y() - size.y();
      const float u = rng_->uniform(0.0f, 1.0f), v = rng_->uniform(0.0f, 1.0f);
      const int edge = rng_->uniformInt(0, 5);
      if (room_x < 0.0f || room_y < 0.0f) continue;
      float x = s.part.min().x() + u * room_x, y = s.part.min().y() + v * room_y;
      if (edge == 0) x = s.part.min().x();
      if (edge == 1) x = s.part.max().x() - size.x();
      if (edge == 2) y = s.part.min().y();
      if (edge == 3) y = s.part.max().y() - size.y();
      if (layout_->placeLoose(moved(item, Vector3f(x, y, s.part.max().z())))) return true;
    }
    return false;
  }

  /// Standing at z0 pushed against a random side of `anchor`, its back to it.
  bool against(const Item& local, const Box3& anchor, float z0) {
    for (int t = 0; t < kTriesPerSpot; ++t) {
      if (againstOnce(local, anchor, z0)) return true;
    }
    return false;
  }

  /// On the floor against a random side of a random piece of furniture.
  bool againstFurniture(const Item& local) {
    for (int t = 0; t < kTriesPerSpot && !feet_.empty(); ++t) {
      const Box3 foot = feet_[rng_->uniformInt(0, static_cast<int>(feet_.size()) - 1)];
      if (againstOnce(local, foot, 0.0f)) return true;
    }
    return false;
  }

  /// On the floor with its back to a random wall, now and then in a corner.
  bool atWall(const Item& local) {
    const std::vector<WallSegment>& walls = layout_->walls();
    const float width = local.bounds().sizes().x();
    for (int t = 0; t < kTriesPerSpot; ++t) {
      const WallSegment& w = walls[rng_->uniformInt(0, static_cast<int>(walls.size()) - 1)];
      const float u = rng_->uniform(0.0f, 1.0f);
      const int corner = rng_->uniformInt(0, 3);
      if (w.length_m < width) continue;
      float s = u * (w.length_m - width);
      if (corner == 0) s = 0.0f;
      if (corner == 1) s = w.length_m - width;
      Frame frame;
      frame.origin = w.start + s * w.along;
      frame.along = w.along;
      frame.inward = w.inward;
      Module m;
      m.items.push_back(local);
      if (layout_->placeLoose(m.transformed(frame).items.front())) return true;
    }
    return false;
  }

 private:
  // One try of against(): a side and a place along it.
  bool againstOnce(const Item& local, const Box3& anchor, float z0) {
    static constexpr int kBackTurns[4] = {3, 1, 0, 2};
    const int side = rng_->uniformInt(0, 3);
    const float u = rng_->uniform(0.0f, 1.0f);
    const Item item = turned(local, kBackTurns[side]);
    const Vector3f size = item.bounds().sizes();
    const float along_x = anchor.min().x() + u * anchor.sizes().x() - 0.5f * size.x();
    const float along_y = anchor.min().y() + u * anchor.sizes().y() - 0.5f * size.y();
    Vector3f at;
    switch (side) {
      case 0:
        at = Vector3f(anchor.max().x(), along_y, z0);
        break;
      case 1:
        at = Vector3f(anchor.min().x() - size.x(), along_y, z0);
        break;
      case 2:
        at = Vector3f(along_x, anchor.max().y(), z0);
        break;
      default:
        at = Vector3f(along_x, anchor.min().y() - size.y(), z0);
    }
    return layout_->placeLoose(moved(item, at));
  }

  Layout* layout_;
  RoomRng* rng_;
  std::vector<Surface> surfaces_;
  std::vector<Box3> feet_;
  std::vector<Box3> monitors_;
};

int annotatedInstances(const Layout& layout) {
  int n = 3;  // wall, floor, ceiling
  for (const Item& item : layout.items()) n += item.semantic > 0 ? 1 : 0;
  return n;
}

int allInstances(const Layout& layout) { return 3 + static_cast<int>(layout.items().size()); }

// Unannotated piles until a drawn share of the vertices is class 0; returns the share reached.
// The estimate leaves out the floor the piles hide, so the mesh ends a little above it.
double addPiles(Layout* layout, Placer* placer, RoomRng* rng, float max_edge_m) {
  const RoomShape& shape = layout->shape();
  const float ceiling = layout->ceilingM();
  const int64_t annotated_vertices = countVertices(shape, ceiling, max_edge_m, layout->items(), 0);
  const double share = rng->uniform(0.06f, 0.085f);
  int64_t clutter_vertices = 0;
  for (int attempt = 0; attempt < 60 && allInstances(*layout) < kMaxInstances &&
                        clutter_vertices < share * (annotated_vertices + clutter_vertices);
       ++attempt) {
    const int where = rng->uniformInt(0, 9);
    bool placed = false;
    if (where < 8) {
      const Item pile = buildPile(rng, 1.0f, 0.8f);
      placed = where < 4 ? placer->atWall(pile) : placer->againstFurniture(pile);
    } else if (placer->hasSurfaces()) {
      const Surface s = placer->pickSurface();
      placed = placer->onSurface(buildPile(rng, 0.5f, 0.35f), s);
    }
    if (placed) {
      clutter_vertices +=
          countVertices(shape, ceiling, max_edge_m, layout->items(), layout->items().size() - 1);
    }
  }
  return static_cast<double>(clutter_vertices) /
         static_cast<double>(annotated_vertices + clutter_vertices);
}

}  // namespace

bool addLooseObjects(Layout* layout, RoomRng* rng, float max_edge_m) {
  Placer placer(layout, rng);
  // Separate statements: the order of the draws is part of the room a seed gives.
  const int most = kMaxInstances - kPileReserve;
  const int drawn_target = rng->uniformInt(44, most);
  const int target =
      std::min(std::max(drawn_target, annotatedInstances(*layout) + kMinLoose), most);
  const int at_furniture = rng->uniformInt(4, 6);
  const int at_walls = rng->uniformInt(3, 4);
  const int small_target = rng->uniformInt(kMinSmall, kMinSmall + 4);

  // Things on desks against the monitor's foot: masks and segments bleed across them.
  for (const Box3& foot : placer.monitors()) {
    const int n = rng->uniformInt(1, 2);
    int placed = 0;
    for (int attempt = 0; placed < n && attempt < 6 * n; ++attempt) {
      placed += placer.against(buildDeskObject(rng), foot, foot.min().z()) ? 1 : 0;
    }
  }
  // Small things first: they are what a ScanNet scan has most of and a network misses most.
  int small = 0;
  for (const Item& item : layout->items()) small += isSmall(item) ? 1 : 0;
  for (int attempt = 0; placer.hasSurfaces() && small < small_target &&
                        annotatedInstances(*layout) < most && attempt < 6 * small_target;
       ++attempt) {
    const Surface s = placer.pickSurface();
    small += placer.onSurface(buildSmallObject(rng, s.semantic), s) ? 1 : 0;
  }
  // Clutter on the floor, pushed against furniture and walls.
  int placed_at_furniture = 0, placed_at_walls = 0;
  for (int attempt = 0; placed_at_furniture < at_furniture && annotatedInstances(*layout) < most &&
                        attempt < 5 * at_furniture;
       ++attempt) {
    // Every other one small: shoes, a box, a bag by the bed or under the desk.
    const Item item = attempt % 2 == 0 ? buildSmallFloorObject(rng) : buildFloorObject(rng);
    placed_at_furniture += placer.againstFurniture(item) ? 1 : 0;
  }
  for (int attempt = 0;
       placed_at_walls < at_walls && annotatedInstances(*layout) < most && attempt < 5 * at_walls;
       ++attempt) {
    const Item item = attempt % 2 == 0 ? buildSmallFloorObject(rng) : buildFloorObject(rng);
    placed_at_walls += placer.atWall(item) ? 1 : 0;
  }
  // Things on surfaces up to the drawn number of instances.
  for (int attempt = 0;
       placer.hasSurfaces() && annotatedInstances(*layout) < target && attempt < 6 * target;
       ++attempt) {
    const Surface s = placer.pickSurface();
    placer.onSurface(buildSurfaceObject(rng, s.semantic), s);
  }

  const double reached = addPiles(layout, &placer, rng, max_edge_m);

  std::set<int32_t> classes = {kWall, kFloor, kCeiling};
  for (const Item& item : layout->items()) {
    if (item.semantic > 0) classes.insert(item.semantic);
  }
  return annotatedInstances(*layout) >= kMinInstances && allInstances(*layout) <= kMaxInstances &&
         static_cast<int>(classes.size()) >= kMinClasses && reached >= kMinUnannotated;
}

}  // namespace room
}  // namespace internal
}  // namespace panmap

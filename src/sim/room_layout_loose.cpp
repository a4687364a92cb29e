// Loose items in a layout: unlike modules, which keep a clearance from everything, they may
// rest on and touch what is there, as clutter in a real room does.
#include <cmath>
#include <vector>

#include "panmap/sim/internal/room_layout.h"

namespace panmap {
namespace internal {
namespace room {
namespace {

// A gap between two surfaces narrower than this is a slit no depth sensor sees into: its faces
// would be ground-truth vertices nothing can observe. Loose items touch or keep this much.
constexpr float kMinGapM = 0.01f;
// Faces placed against each other meet to float round-off; anything more is an overlap or a gap.
constexpr float kTouchM = 1e-5f;

bool slit(float gap) { return gap > kTouchM && gap < kMinGapM; }

float gap3(const Box3& a, const Box3& b) {
  return (a.min() - b.max()).cwiseMax(b.min() - a.max()).cwiseMax(0.0f).norm();
}

float gap2(const Box2& a, const Box2& b) {
  return (a.min() - b.max()).cwiseMax(b.min() - a.max()).cwiseMax(0.0f).norm();
}

}  // namespace

bool Layout::placeLoose(const Item& item) {
  if (item.parts.empty()) return false;
  // The walkway stays clear of the item's box, not just of its parts (a pile around a corner).
  for (const Box2& c : clearFloor()) {
    if (!c.isEmpty() && overlaps2(xy(item.bounds()), c, 0.0f)) return false;
  }
  for (const Part& p : item.parts) {
    if (!shape_.containsRect(xy(p.box))) return false;
    if (p.box.min().z() < -kTolM || p.box.max().z() > ceiling_m_ - 0.05f) return false;
    if (!clearOf(p.box, p.cylinder)) return false;
  }
  if (!supported(item)) return false;
  Module world;
  world.items.push_back(item);
  std::vector<int> newly;
  if (!freeSpaceAfter(world, &newly)) return false;
  for (int c : newly) state_[c] = kBlocked;
  free_cells_ -= static_cast<int>(newly.size());
  items_.push_back(item);
  blockers_.push_back(item.bounds());
  return true;
}

bool Layout::clearOf(const Box3& box, bool cylinder) const {
  // A cylinder's facets next to the line where it touches a side are a slit of their own.
  auto side_by_side = [&](bool round, float gap, float z0, float z1) {
    return round && gap <= kTouchM && box.min().z() < z1 - kTolM && z0 < box.max().z() - kTolM;
  };
  for (const Item& item : items_) {
    for (const Part& q : item.parts) {
      // Overlaps of float round-off (a face computed as a - s + s) count as touching.
      const float gap = gap3(box, q.box);
      if (overlaps3(box, q.box, -kTouchM) || slit(gap) ||
          side_by_side(cylinder || q.cylinder, gap, q.box.min().z(), q.box.max().z())) {
        return false;
      }
    }
  }
  for (const Box3& r : reserved_) {
    if (overlaps3(box, r, 0.0f)) return false;
  }
  const Box2 r = xy(box);
  for (const WallSegment& w : walls_) {
    Box2 wall(w.start);
    wall.extend(w.start + w.length_m * w.along);
    const float gap = gap2(r, wall);
    if (slit(gap) || side_by_side(cylinder, gap, 0.0f, ceiling_m_)) return false;
  }
  return true;
}

bool Layout::supported(const Item& item) const {
  const float z0 = item.bounds().min().z();
  if (z0 <= kTolM) return true;
  for (const Part& p : item.parts) {
    // Parts higher up rest on the item's own lower parts.
    if (p.box.min().z() > z0 + kTolM) continue;
    const Box2 r = xy(p.box);
    bool on = false;
    for (const Item& other : items_) {
      for (const Part& q : other.parts) {
        if (q.cylinder || std::abs(q.box.max().z() - z0) > kTolM) continue;
        const Box2 top = xy(q.box);
        on = (r.min().array() >= top.min().array() - kTolM).all() &&
             (r.max().array() <= top.max().array() + kTolM).all();
        if (on) break;
      }
      if (on) break;
    }
    if (!on) return false;
  }
  return true;
}

}  // namespace room
}  // namespace internal
}  // namespace panmap

#pragma once

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "panmap/core/image.h"

namespace panmap {
namespace internal {
namespace room {

using Box2 = Eigen::AlignedBox2f;
using Box3 = Eigen::AlignedBox3f;
using Eigen::Vector2f;
using Eigen::Vector3f;

// NYU40 ids of what the generator builds.
constexpr int32_t kWall = 1, kFloor = 2, kCabinet = 3, kBed = 4, kChair = 5, kSofa = 6, kTable = 7,
                  kDoor = 8, kWindow = 9, kBookshelf = 10, kPicture = 11, kCounter = 12, kDesk = 14,
                  kCurtain = 16, kPillow = 18, kCeiling = 22, kBooks = 23, kRefrigerator = 24,
                  kShowerCurtain = 28, kBox = 29, kNightStand = 32, kToilet = 33, kSink = 34,
                  kLamp = 35, kBathtub = 36, kOtherFurniture = 39, kOtherProp = 40;
// Only ScanNet-like rooms have these; class 0 is unannotated clutter.
constexpr int32_t kUnannotated = 0, kShelves = 15, kDresser = 17, kMirror = 19, kClothes = 21,
                  kTelevision = 25, kPaper = 26, kTowel = 27, kWhiteboard = 30, kBag = 37;

// Slack of geometric comparisons, metres: coordinates come from float sums of sizes.
constexpr float kTolM = 1e-4f;

/// One solid piece of an object: a box, or a vertical cylinder inscribed in it.
struct Part {
  Box3 box;
  bool cylinder = false;  ///< a vertical cylinder inscribed in `box` (square in x-y)
};

/// The box with corners (x0, y0, z0) and (x1, y1, z1).
Part cuboid(float x0, float y0, float z0, float x1, float y1, float z1);

/// The vertical cylinder of radius r around (cx, cy) from z0 to z1.
Part cylinder(float cx, float cy, float r, float z0, float z1);

/// `b` rotated about the z axis through the origin by quarter turns (counter-clockwise).
Box3 rotateQuarter(const Box3& b, int quarter_turns);

/// One object (one instance in the mesh) made of parts.
struct Item {
  int32_t semantic = 0;
  std::string name;
  Rgb8 color;
  std::vector<Part> parts;
  /// The union of the parts' boxes.
  Box3 bounds() const {
    Box3 b;
    for (const Part& p : parts) b.extend(p.box);
    return b;
  }
};

/// An item of class `semantic` without parts yet.
Item makeItem(int32_t semantic, const char* name, const Rgb8& color);

/// A local placement frame: x along a wall, y into the room (both unit axis vectors).
struct Frame {
  Vector2f origin = Vector2f::Zero();
  Vector2f along = Vector2f::UnitX();
  Vector2f inward = Vector2f::UnitY();
  /// `b` from frame to world coordinates (z unchanged).
  Box3 apply(const Box3& b) const {
    const Vector2f a = origin + b.min().x() * along + b.min().y() * inward;
    const Vector2f c = origin + b.max().x() * along + b.max().y() * inward;
    return Box3(Vector3f(std::min(a.x(), c.x()), std::min(a.y(), c.y()), b.min().z()),
                Vector3f(std::max(a.x(), c.x()), std::max(a.y(), c.y()), b.max().z()));
  }
};

/// Objects placed together (a table and its chairs), in a local frame whose y = 0 is the wall.
struct Module {
  std::vector<Item> items;
  std::vector<Box3> reserved;  ///< kept empty but not built: a door's swing
  float end_margin_m = 0.0f;   ///< kept from the ends of the wall segment

  /// True when the builder could not fit anything.
  bool empty() const { return items.empty(); }
  /// The x-y bounds of every part and reserved box.
  Box2 footprint() const {
    Box2 f;
    for (const Item& item : items) {
      for (const Part& p : item.parts) f.extend(Box2(p.box.min().head<2>(), p.box.max().head<2>()));
    }
    for (const Box3& r : reserved) f.extend(Box2(r.min().head<2>(), r.max().head<2>()));
    return f;
  }
  /// Calls f(Box3*) on every part's and reserved box.
  template <typename F>
  void forEachBox(F f) {
    for (Item& item : items) {
      for (Part& p : item.parts) f(&p.box);
    }
    for (Box3& r : reserved) f(&r);
  }
  /// Moves every box by (dx, dy) in x-y.
  void translate(float dx, float dy) {
    forEachBox([&](Box3* b) { b->translate(Vector3f(dx, dy, 0.0f)); });
  }
  /// Turns every box about the origin by quarter turns (counter-clockwise).
  void rotate(int quarter_turns) {
    forEachBox([&](Box3* b) { *b = rotateQuarter(*b, quarter_turns); });
  }
  /// Moves the footprint's lower x (and y) bound to 0.
  void normalise(bool y_too) {
    const Box2 f = footprint();
    translate(-f.min().x(), y_too ? -f.min().y() : 0.0f);
  }
  /// A copy with every box in world coordinates.
  Module transformed(const Frame& frame) const {
    Module out = *this;
    out.forEachBox([&](Box3* b) { *b = frame.apply(*b); });
    return out;
  }
};

/// True when the x-y rectangles overlap or come closer than `gap`.
bool overlaps2(const Box2& a, const Box2& b, float gap);

/// True when the boxes overlap or come closer than `gap` along every axis.
bool overlaps3(const Box3& a, const Box3& b, float gap);

/// The x-y rectangle of a box.
Box2 xy(const Box3& b);

/// `b` shrunk by d on every side (empty when d exceeds half a side).
Box2 eroded(const Box2& b, float d);

}  // namespace room
}  // namespace internal
}  // namespace panmap

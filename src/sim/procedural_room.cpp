#include "panmap/sim/procedural_room.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <set>
#include <sstream>
#include <utility>

#include "panmap/core/classes.h"
#include "panmap/core/error.h"

namespace panmap {

namespace {

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
constexpr int kMaxAttempts = 40;
// Hidden-face test: a surface sample pushed this far along its normal that lands inside a
// solid (or outside the room) cannot be seen.
constexpr float kPushM = 0.002f;
constexpr float kTolM = 1e-4f;
constexpr double kPi = 3.14159265358979323846;

// ---- Random numbers ----------------------------------------------------------------------

uint64_t splitMix64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

// std::mt19937_64's output is fixed by the standard, its distributions are not: every value
// is made here from the raw 64-bit words so a seed gives the same room with any library.
class Rng {
 public:
  explicit Rng(uint64_t seed) : engine_(seed) {}
  double uniform() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  float uniform(float lo, float hi) {
    return lo + static_cast<float>(uniform() * (static_cast<double>(hi) - lo));
  }
  // Inclusive range.
  int uniformInt(int lo, int hi) {
    return lo + static_cast<int>(engine_() % static_cast<uint64_t>(hi - lo + 1));
  }
  bool chance(double p) { return uniform() < p; }
  template <typename T>
  void shuffle(std::vector<T>* v) {
    for (size_t i = v->size(); i > 1; --i) std::swap((*v)[i - 1], (*v)[engine_() % i]);
  }

 private:
  std::mt19937_64 engine_;
};

uint8_t channel(int v) { return static_cast<uint8_t>(std::clamp(v, 0, 255)); }

Rgb8 tint(Rng* rng, int r, int g, int b, int spread) {
  const int dr = rng->uniformInt(-spread, spread);
  const int dg = rng->uniformInt(-spread, spread);
  const int db = rng->uniformInt(-spread, spread);
  return Rgb8{channel(r + dr), channel(g + dg), channel(b + db)};
}

Rgb8 tint(Rng* rng, const Rgb8& c, int spread) { return tint(rng, c.r, c.g, c.b, spread); }

Rgb8 anyColour(Rng* rng) { return tint(rng, 130, 130, 130, 100); }

// ---- Objects as boxes and cylinders ------------------------------------------------------

struct Part {
  Box3 box;
  bool cylinder = false;  // a vertical cylinder inscribed in `box` (square in x-y)
};

Part cuboid(float x0, float y0, float z0, float x1, float y1, float z1) {
  return Part{Box3(Vector3f(x0, y0, z0), Vector3f(x1, y1, z1)), false};
}

Part cylinder(float cx, float cy, float r, float z0, float z1) {
  return Part{Box3(Vector3f(cx - r, cy - r, z0), Vector3f(cx + r, cy + r, z1)), true};
}

// Rotation about the z axis through the origin by quarter turns (counter-clockwise).
Box3 rotateQuarter(const Box3& b, int quarter_turns) {
  const int k = ((quarter_turns % 4) + 4) % 4;
  auto rot = [k](float x, float y) {
    switch (k) {
      case 1:
        return Vector2f(-y, x);
      case 2:
        return Vector2f(-x, -y);
      case 3:
        return Vector2f(y, -x);
      default:
        return Vector2f(x, y);
    }
  };
  const Vector2f a = rot(b.min().x(), b.min().y());
  const Vector2f c = rot(b.max().x(), b.max().y());
  return Box3(Vector3f(std::min(a.x(), c.x()), std::min(a.y(), c.y()), b.min().z()),
              Vector3f(std::max(a.x(), c.x()), std::max(a.y(), c.y()), b.max().z()));
}

struct Item {
  int32_t semantic = 0;
  std::string name;
  Rgb8 color;
  std::vector<Part> parts;
  Box3 bounds() const {
    Box3 b;
    for (const Part& p : parts) b.extend(p.box);
    return b;
  }
};

Item makeItem(int32_t semantic, const char* name, const Rgb8& color) {
  Item item;
  item.semantic = semantic;
  item.name = name;
  item.color = color;
  return item;
}

// A local placement frame: x along a wall, y into the room (both unit axis vectors).
struct Frame {
  Vector2f origin = Vector2f::Zero();
  Vector2f along = Vector2f::UnitX();
  Vector2f inward = Vector2f::UnitY();
  Box3 apply(const Box3& b) const {
    const Vector2f a = origin + b.min().x() * along + b.min().y() * inward;
    const Vector2f c = origin + b.max().x() * along + b.max().y() * inward;
    return Box3(Vector3f(std::min(a.x(), c.x()), std::min(a.y(), c.y()), b.min().z()),
                Vector3f(std::max(a.x(), c.x()), std::max(a.y(), c.y()), b.max().z()));
  }
};

// Objects placed together (a table and its chairs), in a local frame whose y = 0 is the wall.
struct Module {
  std::vector<Item> items;
  std::vector<Box3> reserved;  // kept empty but not built: a door's swing
  float end_margin_m = 0.0f;   // kept from the ends of the wall segment

  bool empty() const { return items.empty(); }
  Box2 footprint() const {
    Box2 f;
    for (const Item& item : items) {
      for (const Part& p : item.parts) f.extend(Box2(p.box.min().head<2>(), p.box.max().head<2>()));
    }
    for (const Box3& r : reserved) f.extend(Box2(r.min().head<2>(), r.max().head<2>()));
    return f;
  }
  template <typename F>
  void forEachBox(F f) {
    for (Item& item : items) {
      for (Part& p : item.parts) f(&p.box);
    }
    for (Box3& r : reserved) f(&r);
  }
  void translate(float dx, float dy) {
    forEachBox([&](Box3* b) { b->translate(Vector3f(dx, dy, 0.0f)); });
  }
  void rotate(int quarter_turns) {
    forEachBox([&](Box3* b) { *b = rotateQuarter(*b, quarter_turns); });
  }
  // Moves the footprint's lower x (and y) bound to 0.
  void normalise(bool y_too) {
    const Box2 f = footprint();
    translate(-f.min().x(), y_too ? -f.min().y() : 0.0f);
  }
  Module transformed(const Frame& frame) const {
    Module out = *this;
    out.forEachBox([&](Box3* b) { *b = frame.apply(*b); });
    return out;
  }
};

bool overlaps2(const Box2& a, const Box2& b, float gap) {
  return a.min().x() < b.max().x() + gap && b.min().x() < a.max().x() + gap &&
         a.min().y() < b.max().y() + gap && b.min().y() < a.max().y() + gap;
}

bool overlaps3(const Box3& a, const Box3& b, float gap) {
  for (int k = 0; k < 3; ++k) {
    if (!(a.min()[k] < b.max()[k] + gap && b.min()[k] < a.max()[k] + gap)) return false;
  }
  return true;
}

Box2 xy(const Box3& b) { return Box2(b.min().head<2>(), b.max().head<2>()); }

Box2 eroded(const Box2& b, float d) {
  return Box2(b.min() + Vector2f::Constant(d), b.max() - Vector2f::Constant(d));
}

// ---- Floor plan --------------------------------------------------------------------------

struct RoomShape {
  float width_m = 0.0f;  // bounding rectangle [0, W] x [0, D]
  float depth_m = 0.0f;
  Box2 notch;                     // the corner cut out of an L (empty for a rectangle)
  std::vector<Box2> arms;         // maximal rectangles, their union is the floor
  std::vector<Box2> tiles;        // disjoint rectangles, their union is the floor
  std::vector<Vector2f> polygon;  // counter-clockwise

  bool lShaped() const { return !notch.isEmpty(); }
  bool contains(const Vector2f& p, float tol) const {
    if (p.x() < -tol || p.y() < -tol || p.x() > width_m + tol || p.y() > depth_m + tol) {
      return false;
    }
    if (!lShaped()) return true;
    return !(p.x() > notch.min().x() + tol && p.x() < notch.max().x() - tol &&
             p.y() > notch.min().y() + tol && p.y() < notch.max().y() - tol);
  }
  bool containsRect(const Box2& r) const {
    if (r.min().x() < -kTolM || r.min().y() < -kTolM || r.max().x() > width_m + kTolM ||
        r.max().y() > depth_m + kTolM) {
      return false;
    }
    return !lShaped() || !overlaps2(r, notch, 0.0f);
  }
  float minArmM() const {
    float m = std::max(width_m, depth_m);
    for (const Box2& a : arms) m = std::min({m, a.sizes().x(), a.sizes().y()});
    return m;
  }
  float distanceToWalls(const Vector2f& p) const {
    float best = std::numeric_limits<float>::max();
    for (size_t i = 0; i < polygon.size(); ++i) {
      const Vector2f a = polygon[i];
      const Vector2f ab = polygon[(i + 1) % polygon.size()] - a;
      const float t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0f, 1.0f);
      best = std::min(best, (a + t * ab - p).norm());
    }
    return best;
  }
};

// Rectangles of sides in [min, max]; an L cuts a corner off a rectangle of sides >= 5 m so
// that both arms stay at least 3 m wide.
RoomShape drawShape(Rng* rng, const RoomConfig& config) {
  const bool want_l = rng->chance(config.l_shape_probability);
  const float l_min = std::max(config.min_width_m, 5.0f);
  const bool l_shape = want_l && config.max_width_m >= l_min;
  const float lo = l_shape ? l_min : config.min_width_m;
  RoomShape s;
  s.width_m = rng->uniform(lo, config.max_width_m);
  s.depth_m = rng->uniform(lo, config.max_width_m);
  const float w = s.width_m, d = s.depth_m;
  const Box2 all(Vector2f(0.0f, 0.0f), Vector2f(w, d));
  std::vector<Vector2f> corners = {{0.0f, 0.0f}, {w, 0.0f}, {w, d}, {0.0f, d}};
  if (!l_shape) {
    s.polygon = corners;
    s.arms = {all};
    s.tiles = {all};
    return s;
  }
  const int c = rng->uniformInt(0, 3);
  const float nx = rng->uniform(std::max(1.5f, 0.3f * w), std::min(w - 3.0f, 0.6f * w));
  const float ny = rng->uniform(std::max(1.5f, 0.3f * d), std::min(d - 3.0f, 0.6f * d));
  const bool high_x = c == 1 || c == 2;
  const bool high_y = c == 2 || c == 3;
  s.notch = Box2(Vector2f(high_x ? w - nx : 0.0f, high_y ? d - ny : 0.0f),
                 Vector2f(high_x ? w : nx, high_y ? d : ny));
  const Box2 arm_x(Vector2f(high_x ? 0.0f : nx, 0.0f), Vector2f(high_x ? w - nx : w, d));
  const Box2 arm_y(Vector2f(0.0f, high_y ? 0.0f : ny), Vector2f(w, high_y ? d - ny : d));
  s.arms = {arm_x, arm_y};
  s.tiles = {arm_x, Box2(Vector2f(s.notch.min().x(), arm_y.min().y()),
                         Vector2f(s.notch.max().x(), arm_y.max().y()))};
  // The cut corner becomes three vertices: the polygon stays counter-clockwise.
  const Vector2f corner = corners[c];
  const Vector2f to_prev = (corners[(c + 3) % 4] - corner).normalized();
  const Vector2f to_next = (corners[(c + 1) % 4] - corner).normalized();
  const Vector2f a = corner + to_prev * (to_prev.x() != 0.0f ? nx : ny);
  const Vector2f b = corner + to_next * (to_next.x() != 0.0f ? nx : ny);
  for (int i = 0; i < 4; ++i) {
    if (i != c) {
      s.polygon.push_back(corners[i]);
      continue;
    }
    // The inner corner copies coordinates rather than computing a + b - corner, which can be
    // off by an ulp and tilt the walls.
    s.polygon.push_back(a);
    s.polygon.push_back(
        Vector2f(a.x() != corner.x() ? a.x() : b.x(), a.y() != corner.y() ? a.y() : b.y()));
    s.polygon.push_back(b);
  }
  return s;
}

// ---- Furniture catalogue -----------------------------------------------------------------
// Every builder returns objects in wall coordinates (x along the wall, y into the room, z up,
// the wall at y = 0), or an empty module when it cannot fit in `max_depth_m`.

struct BuildContext {
  float max_depth_m = 0.0f;  // band depth available from the wall
  float ceiling_m = 0.0f;
};

Module buildDoor(Rng* rng, const BuildContext& ctx) {
  const float w = rng->uniform(0.8f, 0.9f);
  const float h = std::min(rng->uniform(2.0f, 2.1f), ctx.ceiling_m - 0.15f);
  const float t = rng->uniform(0.035f, 0.05f);  // proud of the wall: a separate depth surface
  Item door = makeItem(kDoor, "door", tint(rng, 150, 105, 65, 35));
  door.parts.push_back(cuboid(0.0f, 0.0f, 0.0f, w, t, h));
  const float hx = rng->chance(0.5) ? 0.06f : w - 0.18f;
  door.parts.push_back(cuboid(hx, t, 0.98f, hx + 0.12f, t + 0.05f, 1.01f));
  Module m;
  m.items.push_back(door);
  m.reserved.push_back(Box3(Vector3f(0.0f, t, 0.0f), Vector3f(w, t + w, h)));
  m.end_margin_m = 0.1f;
  if (t + w > ctx.max_depth_m) return Module();
  return m;
}

Module buildWindow(Rng* rng, const BuildContext& ctx, bool curtains) {
  const float ww = rng->uniform(0.8f, 1.6f);
  const float sill = rng->uniform(0.85f, 1.0f);
  const float wh = std::min(rng->uniform(1.0f, 1.4f), ctx.ceiling_m - 0.3f - sill);
  Module m;
  Item window = makeItem(kWindow, "window", tint(rng, 175, 200, 225, 20));
  window.parts.push_back(cuboid(0.0f, 0.0f, sill, ww, 0.03f, sill + wh));
  window.parts.push_back(cuboid(-0.03f, 0.0f, sill - 0.03f, ww + 0.03f, 0.12f, sill));
  m.items.push_back(window);
  if (curtains) {
    const float z0 = rng->chance(0.5) ? 0.02f : sill - 0.2f;
    const float z1 = std::min(sill + wh + 0.12f, ctx.ceiling_m - 0.05f);
    const Rgb8 base = anyColour(rng);
    for (int side = 0; side < 2; ++side) {
      const float cw = rng->uniform(0.25f, 0.45f);
      const float x0 = side == 0 ? -0.08f - cw : ww + 0.08f;
      Item c = makeItem(kCurtain, "curtain", tint(rng, base, 15));
      c.parts.push_back(cuboid(x0, 0.06f, z0, x0 + cw, 0.09f, z1));
      m.items.push_back(c);
    }
  }
  m.normalise(false);
  m.end_margin_m = 0.05f;
  return m;
}

Module buildPicture(Rng* rng, const BuildContext& ctx) {
  const float pw = rng->uniform(0.3f, 1.0f);
  const float ph = rng->uniform(0.25f, 0.7f);
  const float top = std::min(rng->uniform(1.4f, 1.7f) + 0.5f * ph, ctx.ceiling_m - 0.15f);
  Item picture = makeItem(kPicture, "picture", anyColour(rng));
  picture.parts.push_back(cuboid(0.0f, 0.0f, top - ph, pw, 0.02f, top));
  Module m;
  m.items.push_back(picture);
  m.end_margin_m = 0.1f;
  return m;
}

// 2-4 cabinets side by side whose bodies touch: same-class instances without a depth edge.
Module buildCabinets(Rng* rng, const BuildContext& ctx) {
  const int n = rng->uniformInt(2, 4);
  const float cw = rng->uniform(0.4f, 0.6f);
  const float cd = std::min(rng->uniform(0.45f, 0.6f), ctx.max_depth_m - 0.03f);
  if (cd < 0.35f) return Module();
  const bool tall = rng->chance(0.35);
  const float h =
      tall ? std::min(rng->uniform(1.8f, 2.0f), ctx.ceiling_m - 0.2f) : rng->uniform(0.8f, 0.86f);
  const Rgb8 base = rng->chance(0.5) ? Rgb8{205, 180, 145} : Rgb8{230, 230, 225};
  Module m;
  for (int i = 0; i < n; ++i) {
    const float x0 = static_cast<float>(i) * cw;
    const float x1 = static_cast<float>(i + 1) * cw;
    Item c = makeItem(kCabinet, "cabinet", tint(rng, base, 25));
    c.parts.push_back(cuboid(x0, 0.0f, 0.0f, x1, cd - 0.02f, h));
    c.parts.push_back(cuboid(x0 + 0.01f, cd - 0.02f, 0.08f, x1 - 0.01f, cd, h - 0.02f));
    const float hx = i % 2 == 0 ? x1 - 0.06f : x0 + 0.04f;
    const float hz = tall ? 1.0f : h - 0.15f;
    c.parts.push_back(cuboid(hx, cd, hz - 0.07f, hx + 0.02f, cd + 0.025f, hz + 0.07f));
    m.items.push_back(c);
  }
  return m;
}

// A counter whose top has a hole the sink's basin sits in: the sink is inside the counter's box.
Module buildCounter(Rng* rng, const BuildContext& ctx) {
  const float cd = 0.6f;
  if (cd > ctx.max_depth_m) return Module();
  const float lc = rng->uniform(1.2f, 2.4f);
  const float top = rng->uniform(0.85f, 0.88f);
  const float body_top = top - 0.18f;
  const float sw = rng->uniform(0.45f, 0.6f);
  const float xs = rng->uniform(0.15f, lc - sw - 0.15f);
  const float sy0 = 0.1f, sy1 = 0.5f, r = 0.03f, rim = top + 0.02f;
  Item counter = makeItem(kCounter, "counter", tint(rng, 185, 180, 170, 35));
  counter.parts.push_back(cuboid(0.0f, 0.0f, 0.0f, lc, cd, body_top));
  counter.parts.push_back(cuboid(0.0f, 0.0f, body_top, xs, cd, top));
  counter.parts.push_back(cuboid(xs + sw, 0.0f, body_top, lc, cd, top));
  counter.parts.push_back(cuboid(xs, 0.0f, body_top, xs + sw, sy0, top));
  counter.parts.push_back(cuboid(xs, sy1, body_top, xs + sw, cd, top));
  Item sink = makeItem(kSink, "sink", tint(rng, 232, 232, 238, 12));
  sink.parts.push_back(cuboid(xs, sy0, body_top, xs + r, sy1, rim));
  sink.parts.push_back(cuboid(xs + sw - r, sy0, body_top, xs + sw, sy1, rim));
  sink.parts.push_back(cuboid(xs + r, sy0, body_top, xs + sw - r, sy0 + r, rim));
  sink.parts.push_back(cuboid(xs + r, sy1 - r, body_top, xs + sw - r, sy1, rim));
  sink.parts.push_back(cuboid(xs + r, sy0 + r, body_top, xs + sw - r, sy1 - r, body_top + 0.04f));
  const float fx = xs + 0.5f * sw;
  sink.parts.push_back(cylinder(fx, 0.05f, 0.015f, top, top + 0.22f));
  sink.parts.push_back(cuboid(fx - 0.012f, 0.05f, top + 0.18f, fx + 0.012f, 0.2f, top + 0.21f));
  Module m;
  m.items = {counter, sink};
  return m;
}

Module buildFridge(Rng* rng, const BuildContext& ctx) {
  const float fw = rng->uniform(0.6f, 0.75f);
  const float fd = rng->uniform(0.65f, 0.72f);
  if (fd + 0.03f > ctx.max_depth_m) return Module();
  const float fh = std::min(rng->uniform(1.7f, 1.9f), ctx.ceiling_m - 0.2f);
  const float split = 0.62f * fh;
  Item f = makeItem(kRefrigerator, "refrigerator",
                    rng->chance(0.7) ? tint(rng, 225, 225, 228, 10) : tint(rng, 70, 70, 75, 15));
  f.parts.push_back(cuboid(0.0f, 0.0f, 0.0f, fw, fd - 0.03f, fh));
  f.parts.push_back(cuboid(0.005f, fd - 0.03f, 0.03f, fw - 0.005f, fd, split - 0.005f));
  f.parts.push_back(cuboid(0.005f, fd - 0.03f, split + 0.005f, fw - 0.005f, fd, fh - 0.005f));
  f.parts.push_back(cuboid(fw - 0.07f, fd, split - 0.5f, fw - 0.05f, fd + 0.03f, split - 0.1f));
  f.parts.push_back(cuboid(fw - 0.07f, fd, split + 0.1f, fw - 0.05f, fd + 0.03f, split + 0.4f));
  Module m;
  m.items.push_back(f);
  m.end_margin_m = 0.02f;
  return m;
}

Item makeTable(Rng* rng, const char* name, float x0, float y0, float l, float w, float top_z) {
  Item t = makeItem(kTable, name, tint(rng, 165, 120, 75, 35));
  t.parts.push_back(cuboid(x0, y0, top_z - 0.03f, x0 + l, y0 + w, top_z));
  const bool round_legs = rng->chance(0.5);
  for (float lx : {x0 + 0.04f, x0 + l - 0.09f}) {
    for (float ly : {y0 + 0.04f, y0 + w - 0.09f}) {
      t.parts.push_back(round_legs ? cylinder(lx + 0.025f, ly + 0.025f, 0.025f, 0.0f, top_z - 0.03f)
                                   : cuboid(lx, ly, 0.0f, lx + 0.05f, ly + 0.05f, top_z - 0.03f));
    }
  }
  return t;
}

constexpr float kChairW = 0.44f, kChairD = 0.44f, kSeatZ = 0.45f;

// A four-legged chair with a back; its front edge is centred at (x, y) and it faces -y turned
// by `quarter_turns` (1: faces +x, 2: +y, 3: -x).
Item makeChair(Rng* rng, float x, float y, int quarter_turns, const Rgb8& base) {
  const float w = kChairW, d = kChairD, leg = 0.03f;
  const float back = rng->uniform(0.8f, 0.86f);
  Item c = makeItem(kChair, "chair", tint(rng, base, 20));
  c.parts.push_back(cuboid(-0.5f * w, 0.0f, kSeatZ - 0.03f, 0.5f * w, d, kSeatZ));
  for (float lx : {-0.5f * w, 0.5f * w - leg}) {
    for (float ly : {0.0f, d - leg}) {
      c.parts.push_back(cuboid(lx, ly, 0.0f, lx + leg, ly + leg, kSeatZ - 0.03f));
    }
  }
  c.parts.push_back(cuboid(-0.5f * w, d - 0.03f, kSeatZ, 0.5f * w, d, back));
  for (Part& p : c.parts) {
    p.box = rotateQuarter(p.box, quarter_turns);
    p.box.translate(Vector3f(x, y, 0.0f));
  }
  return c;
}

Rgb8 chairColour(Rng* rng) { return tint(rng, 140, 95, 60, 50); }

// A table against the wall with chairs on the room side, the first tucked in so that its seat
// is under the table top.
Module buildTableGroup(Rng* rng, const BuildContext& ctx) {
  const float l = rng->uniform(1.2f, 1.6f);
  float w = rng->uniform(0.75f, 0.9f);
  float gap = rng->uniform(0.02f, 0.08f);
  const int n = l >= 1.35f ? 2 : 1;
  std::vector<float> tuck(n);
  tuck[0] = rng->uniform(0.15f, 0.25f);
  for (int i = 1; i < n; ++i)
    tuck[i] = rng->chance(0.5) ? rng->uniform(0.1f, 0.2f) : -rng->uniform(0.0f, 0.15f);
  if (gap + w - *std::min_element(tuck.begin(), tuck.end()) + kChairD > ctx.max_depth_m) {
    w = 0.75f;
    gap = 0.02f;
    std::fill(tuck.begin(), tuck.end(), 0.25f);
    if (gap + w - 0.25f + kChairD > ctx.max_depth_m) return Module();
  }
  Module m;
  m.items.push_back(makeTable(rng, "table", 0.0f, gap, l, w, rng->uniform(0.74f, 0.76f)));
  const Rgb8 base = chairColour(rng);
  const float offset = n == 1 ? 0.0f : std::max(0.26f, std::min(0.25f * l, 0.5f * l - 0.33f));
  for (int i = 0; i < n; ++i) {
    const float x = 0.5f * l + (n == 1 ? 0.0f : (i == 0 ? -offset : offset));
    m.items.push_back(makeChair(rng, x, gap + w - tuck[i], 0, base));
  }
  if (rng->chance(0.35)) {
    m.items.push_back(makeChair(rng, l + rng->uniform(0.05f, 0.15f), gap + 0.5f * w, 3, base));
  }
  m.normalise(false);
  return m;
}

// A table in the middle of the room: chairs tucked in on one side, pulled out on the other.
Module buildIslandTableGroup(Rng* rng, bool end_chairs) {
  const float l = rng->uniform(1.4f, 1.8f);
  const float w = rng->uniform(0.8f, 0.95f);
  Module m;
  m.items.push_back(makeTable(rng, "table", 0.0f, 0.0f, l, w, rng->uniform(0.74f, 0.76f)));
  const Rgb8 base = chairColour(rng);
  const float offset = std::max(0.26f, std::min(0.25f * l, 0.5f * l - 0.33f));
  for (float x : {0.5f * l - offset, 0.5f * l + offset}) {
    m.items.push_back(makeChair(rng, x, rng->uniform(0.15f, 0.25f), 2, base));
    m.items.push_back(makeChair(rng, x, w + rng->uniform(0.05f, 0.2f), 0, base));
  }
  if (end_chairs) {
    m.items.push_back(makeChair(rng, -rng->uniform(0.05f, 0.2f), 0.5f * w, 1, base));
    m.items.push_back(makeChair(rng, l + rng->uniform(0.05f, 0.2f), 0.5f * w, 3, base));
  }
  m.normalise(true);
  return m;
}

// A desk with a monitor standing on it (and sometimes a box) and a chair half under it.
Module buildDesk(Rng* rng, const BuildContext& ctx) {
  const float l = rng->uniform(1.0f, 1.4f);
  const float wd = rng->uniform(0.6f, 0.7f);
  float tuck = rng->uniform(0.05f, 0.2f);
  if (wd - tuck + kChairD > ctx.max_depth_m) tuck = 0.2f;
  if (wd - tuck + kChairD > ctx.max_depth_m) return Module();
  const float top = rng->uniform(0.73f, 0.76f);
  Item desk = makeItem(kDesk, "desk", tint(rng, 180, 150, 110, 40));
  desk.parts.push_back(cuboid(0.0f, 0.0f, top - 0.03f, l, wd, top));
  desk.parts.push_back(cuboid(0.0f, 0.0f, 0.0f, 0.03f, wd, top - 0.03f));
  desk.parts.push_back(cuboid(l - 0.03f, 0.0f, 0.0f, l, wd, top - 0.03f));
  desk.parts.push_back(cuboid(0.03f, 0.0f, 0.35f, l - 0.03f, 0.02f, top - 0.03f));
  const float sw = rng->uniform(0.45f, 0.6f);
  const float sh = rng->uniform(0.3f, 0.36f);
  const float mx = rng->uniform(0.5f * sw + 0.05f, l - 0.5f * sw - 0.05f);
  Item monitor = makeItem(kOtherProp, "monitor", tint(rng, 35, 35, 40, 10));
  monitor.parts.push_back(cuboid(mx - 0.1f, 0.1f, top, mx + 0.1f, 0.3f, top + 0.02f));
  monitor.parts.push_back(cuboid(mx - 0.025f, 0.16f, top + 0.02f, mx + 0.025f, 0.19f, top + 0.2f));
  monitor.parts.push_back(
      cuboid(mx - 0.5f * sw, 0.19f, top + 0.1f, mx + 0.5f * sw, 0.22f, top + 0.1f + sh));
  Module m;
  m.items = {desk, monitor};
  if (rng->chance(0.5)) {
    const float bw = rng->uniform(0.18f, 0.25f);
    const bool left = mx - 0.5f * sw > bw + 0.12f;
    const bool right = mx + 0.5f * sw < l - bw - 0.12f;
    if (left || right) {
      const float bx = left ? 0.05f : l - 0.05f - bw;
      Item box = makeItem(kBox, "box", tint(rng, 180, 140, 90, 30));
      const float bd = rng->uniform(0.18f, 0.3f);
      const float bh = rng->uniform(0.08f, 0.2f);
      box.parts.push_back(cuboid(bx, 0.05f, top, bx + bw, 0.05f + bd, top + bh));
      m.items.push_back(box);
    }
  }
  const float cx = std::clamp(mx, 0.03f + 0.5f * kChairW + 0.02f, l - 0.05f - 0.5f * kChairW);
  m.items.push_back(makeChair(rng, cx, wd - tuck, 0, chairColour(rng)));
  return m;
}

// An open bookshelf; each filled shelf carries one row of touching books (one instance).
Module buildBookshelf(Rng* rng, const BuildContext& ctx) {
  const float bw = rng->uniform(0.6f, 1.0f);
  const float bd = rng->uniform(0.28f, 0.35f);
  if (bd > ctx.max_depth_m) return Module();
  const float bh = std::min(rng->uniform(1.5f, 2.0f), ctx.ceiling_m - 0.2f);
  const int n = rng->uniformInt(3, 5);
  const float t = 0.02f, back = 0.01f, plinth = 0.08f;
  Item shelf = makeItem(kBookshelf, "bookshelf", tint(rng, 115, 85, 55, 35));
  shelf.parts.push_back(cuboid(0.0f, 0.0f, 0.0f, t, bd, bh));
  shelf.parts.push_back(cuboid(bw - t, 0.0f, 0.0f, bw, bd, bh));
  shelf.parts.push_back(cuboid(t, 0.0f, 0.0f, bw - t, back, bh - t));
  shelf.parts.push_back(cuboid(t, 0.0f, bh - t, bw - t, bd, bh));
  shelf.parts.push_back(cuboid(t, back, 0.0f, bw - t, bd, plinth));
  const float pitch = (bh - t - plinth) / static_cast<float>(n);
  std::vector<float> floors = {plinth};
  for (int k = 1; k < n; ++k) {
    const float z = plinth + static_cast<float>(k) * pitch;
    shelf.parts.push_back(cuboid(t, back, z - t, bw - t, bd, z));
    floors.push_back(z);
  }
  Module m;
  m.items.push_back(shelf);
  for (int k = 0; k < n; ++k) {
    const float height = plinth + static_cast<float>(k + 1) * pitch - t - floors[k];
    if (height < 0.2f || !rng->chance(0.75)) continue;
    Item books = makeItem(kBooks, "books", anyColour(rng));
    // Flush against the side or a visible gap: no sub-centimetre slit a sensor cannot see into.
    float x = t + (rng->chance(0.3) ? 0.0f : rng->uniform(0.01f, 0.08f));
    const float end = t + (bw - 2.0f * t) * rng->uniform(0.45f, 0.95f);
    while (true) {
      const float thick = rng->uniform(0.02f, 0.05f);
      if (x + thick > end) break;
      const float bz = rng->uniform(0.15f, std::min(0.3f, height - 0.03f));
      const float by = rng->uniform(0.15f, bd - 0.04f);
      books.parts.push_back(cuboid(x, back, floors[k], x + thick, back + by, floors[k] + bz));
      x += thick;
    }
    if (books.parts.size() >= 2) m.items.push_back(books);
  }
  m.end_margin_m = 0.02f;
  return m;
}

Module buildSofa(Rng* rng, const BuildContext& ctx) {
  const float sl = rng->uniform(1.6f, 2.2f);
  const float sd = rng->uniform(0.85f, 0.95f);
  if (sd > ctx.max_depth_m) return Module();
  const float aw = rng->uniform(0.15f, 0.22f);
  const float back = rng->uniform(0.78f, 0.85f);
  Item sofa = makeItem(kSofa, "sofa", tint(rng, 95, 110, 140, 60));
  sofa.parts.push_back(cuboid(0.0f, 0.0f, 0.0f, sl, 0.2f, back));
  sofa.parts.push_back(cuboid(0.0f, 0.2f, 0.0f, aw, sd, 0.6f));
  sofa.parts.push_back(cuboid(sl - aw, 0.2f, 0.0f, sl, sd, 0.6f));
  sofa.parts.push_back(cuboid(aw, 0.2f, 0.0f, sl - aw, sd - 0.03f, 0.42f));
  Module m;
  m.items.push_back(sofa);
  const float ct_w = rng->uniform(0.5f, 0.6f);
  if (sd + 0.35f + ct_w <= ctx.max_depth_m && rng->chance(0.6)) {
    const float ct_l = std::min(rng->uniform(0.9f, 1.1f), sl);
    m.items.push_back(
        makeTable(rng, "coffee table", 0.5f * (sl - ct_l), sd + 0.35f, ct_l, ct_w, 0.45f));
  }
  return m;
}

// One bed with its head at y = 0: headboard, frame, a mattress inset on it, pillows on top.
void addBed(Rng* rng, float x0, float bw, std::vector<Item>* items) {
  const float hb = 0.05f, bl = 2.0f;
  Item bed = makeItem(kBed, "bed", tint(rng, 120, 135, 180, 60));
  bed.parts.push_back(cuboid(x0, 0.0f, 0.0f, x0 + bw, hb, rng->uniform(0.8f, 0.86f)));
  bed.parts.push_back(cuboid(x0, hb, 0.0f, x0 + bw, hb + bl, 0.3f));
  bed.parts.push_back(cuboid(x0 + 0.02f, hb, 0.3f, x0 + bw - 0.02f, hb + bl - 0.02f, 0.5f));
  items->push_back(bed);
  const int pillows = bw > 1.2f ? 2 : 1;
  const float pw = (bw - 0.1f * static_cast<float>(pillows + 1)) / static_cast<float>(pillows);
  for (int i = 0; i < pillows; ++i) {
    const float px = x0 + 0.1f + static_cast<float>(i) * (pw + 0.1f);
    Item pillow = makeItem(kPillow, "pillow", tint(rng, 230, 230, 235, 20));
    pillow.parts.push_back(cuboid(px, hb + 0.08f, 0.5f, px + pw, hb + 0.48f, 0.62f));
    items->push_back(pillow);
  }
}

// Head against the wall (single, double or two touching singles, with a night stand and lamp)
// where the band is deep enough, else a single or double bed with its long side on the wall.
Module buildBed(Rng* rng, const BuildContext& ctx) {
  Module m;
  const bool head_on = ctx.max_depth_m >= 2.05f && rng->chance(0.7);
  if (head_on) {
    const bool twin = rng->chance(0.5);
    const float bw = twin || rng->chance(0.5) ? rng->uniform(0.9f, 1.0f) : rng->uniform(1.4f, 1.6f);
    addBed(rng, 0.0f, bw, &m.items);
    if (twin) addBed(rng, bw, bw, &m.items);
    if (rng->chance(0.7)) {
      Item stand = makeItem(kNightStand, "night stand", tint(rng, 150, 110, 70, 30));
      stand.parts.push_back(cuboid(-0.5f, 0.0f, 0.0f, -0.05f, 0.4f, 0.55f));
      stand.parts.push_back(cuboid(-0.48f, 0.4f, 0.3f, -0.07f, 0.42f, 0.5f));
      Item lamp = makeItem(kLamp, "lamp", tint(rng, 230, 210, 160, 20));
      lamp.parts.push_back(cylinder(-0.275f, 0.2f, 0.07f, 0.55f, 0.57f));
      lamp.parts.push_back(cylinder(-0.275f, 0.2f, 0.012f, 0.57f, 0.78f));
      lamp.parts.push_back(cylinder(-0.275f, 0.2f, 0.13f, 0.74f, 0.92f));
      m.items.push_back(stand);
      m.items.push_back(lamp);
    }
    m.normalise(false);
    return m;
  }
  const float bw = ctx.max_depth_m >= 1.6f && rng->chance(0.5) ? rng->uniform(1.4f, 1.6f)
                                                               : rng->uniform(0.9f, 1.0f);
  if (bw > ctx.max_depth_m) return Module();
  addBed(rng, 0.0f, bw, &m.items);
  m.rotate(rng->chance(0.5) ? 1 : 3);
  m.normalise(true);
  return m;
}

// A bathtub with a hollow basin and a shower curtain hanging into it from a rod.
Module buildBath(Rng* rng, const BuildContext& ctx) {
  const float tl = rng->uniform(1.5f, 1.7f);
  const float td = rng->uniform(0.7f, 0.8f);
  if (td > ctx.max_depth_m) return Module();
  const float th = rng->uniform(0.55f, 0.6f);
  const float rt = 0.08f;
  Item tub = makeItem(kBathtub, "bathtub", tint(rng, 240, 240, 236, 10));
  tub.parts.push_back(cuboid(0.0f, 0.0f, 0.0f, tl, rt, th));
  tub.parts.push_back(cuboid(0.0f, td - rt, 0.0f, tl, td, th));
  tub.parts.push_back(cuboid(0.0f, rt, 0.0f, rt, td - rt, th));
  tub.parts.push_back(cuboid(tl - rt, rt, 0.0f, tl, td - rt, th));
  tub.parts.push_back(cuboid(rt, rt, 0.0f, tl - rt, td - rt, 0.15f));
  Module m;
  m.items.push_back(tub);
  const float cy = td - rt - 0.04f;
  const float inner = tl - 2.0f * rt - 0.02f;
  const float cw = inner * rng->uniform(0.35f, 1.0f);
  const float x0 = rng->chance(0.5) ? rt + 0.01f : tl - rt - 0.01f - cw;
  Item curtain = makeItem(kShowerCurtain, "shower curtain", tint(rng, 200, 215, 235, 35));
  curtain.parts.push_back(cuboid(x0, cy - 0.015f, 0.35f, x0 + cw, cy, 1.96f));
  curtain.parts.push_back(cuboid(0.0f, cy - 0.02f, 1.96f, tl, cy + 0.005f, 1.98f));
  m.items.push_back(curtain);
  return m;
}

Module buildToilet(Rng* rng, const BuildContext& ctx) {
  if (ctx.max_depth_m < 0.7f) return Module();
  Item t = makeItem(kToilet, "toilet", tint(rng, 245, 245, 243, 6));
  t.parts.push_back(cuboid(0.0f, 0.0f, 0.4f, 0.4f, 0.18f, 0.76f));
  t.parts.push_back(cuboid(0.08f, 0.0f, 0.0f, 0.32f, 0.3f, 0.4f));
  t.parts.push_back(cylinder(0.2f, 0.42f, 0.12f, 0.0f, 0.28f));
  t.parts.push_back(cylinder(0.2f, 0.45f, 0.18f, 0.28f, 0.4f));
  t.parts.push_back(cylinder(0.2f, 0.46f, 0.19f, 0.4f, 0.42f));
  Module m;
  m.items.push_back(t);
  m.end_margin_m = 0.1f;
  return m;
}

// Class 39 clutter: a trash can, an ottoman or a bench.
Module buildOtherFurniture(Rng* rng, const BuildContext& ctx) {
  Module m;
  switch (rng->uniformInt(0, 2)) {
    case 0: {
      const float r = rng->uniform(0.12f, 0.18f);
      Item can = makeItem(kOtherFurniture, "trash can", anyColour(rng));
      can.parts.push_back(cylinder(r, r, r, 0.0f, rng->uniform(0.3f, 0.45f)));
      m.items.push_back(can);
      break;
    }
    case 1: {
      const float s = rng->uniform(0.45f, 0.6f);
      Item ottoman = makeItem(kOtherFurniture, "ottoman", anyColour(rng));
      ottoman.parts.push_back(cuboid(0.0f, 0.0f, 0.0f, s, s, 0.42f));
      m.items.push_back(ottoman);
      break;
    }
    default: {
      const float bl = rng->uniform(1.0f, 1.4f);
      const float bd = rng->uniform(0.35f, 0.4f);
      Item bench = makeItem(kOtherFurniture, "bench", tint(rng, 140, 110, 80, 40));
      bench.parts.push_back(cuboid(0.0f, 0.0f, 0.42f, bl, bd, 0.46f));
      bench.parts.push_back(cuboid(0.0f, 0.0f, 0.0f, 0.04f, bd, 0.42f));
      bench.parts.push_back(cuboid(bl - 0.04f, 0.0f, 0.0f, bl, bd, 0.42f));
      m.items.push_back(bench);
    }
  }
  if (m.footprint().sizes().y() > ctx.max_depth_m) return Module();
  m.end_margin_m = 0.05f;
  return m;
}

// Two cardboard boxes, the smaller standing on the larger.
Module buildBoxes(Rng* rng, const BuildContext& ctx) {
  const float w1 = rng->uniform(0.35f, 0.55f), d1 = rng->uniform(0.3f, 0.45f);
  const float h1 = rng->uniform(0.25f, 0.4f);
  if (d1 > ctx.max_depth_m) return Module();
  const float w2 = w1 * rng->uniform(0.6f, 0.9f), d2 = d1 * rng->uniform(0.6f, 1.0f);
  const float ox = rng->uniform(0.0f, w1 - w2), oy = rng->uniform(0.0f, d1 - d2);
  Item lower = makeItem(kBox, "box", tint(rng, 185, 145, 95, 30));
  lower.parts.push_back(cuboid(0.0f, 0.0f, 0.0f, w1, d1, h1));
  Item upper = makeItem(kBox, "box", tint(rng, 185, 145, 95, 30));
  upper.parts.push_back(cuboid(ox, oy, h1, ox + w2, oy + d2, h1 + rng->uniform(0.15f, 0.3f)));
  Module m;
  m.items = {lower, upper};
  m.end_margin_m = 0.05f;
  return m;
}

// ---- Placement ---------------------------------------------------------------------------

struct WallSegment {
  Vector2f start;
  Vector2f along;   // unit, counter-clockwise around the room
  Vector2f inward;  // unit, into the room
  float length_m = 0.0f;
};

// Places modules in a band of depth `band_m` along the walls (or in a central island zone),
// keeps a corridor of kCorridorM around the middle free of everything and keeps at least
// kMinFreeFraction of the floor free for a camera at kCameraHeightsM.
class Layout {
 public:
  Layout(const RoomShape& shape, float ceiling_m, float band_m, bool island)
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

  BuildContext context() const { return BuildContext{band_m_, ceiling_m_}; }
  bool hasIslandZone() const { return !island_zone_.isEmpty(); }
  const std::vector<Item>& items() const { return items_; }

  // The module in wall coordinates, at a random free position along a random wall.
  bool placeOnWall(Rng* rng, const Module& module) {
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

  // The module (normalised to start at the origin) turned by 0 or 90 degrees, inside the
  // island zone.
  bool placeIsland(Rng* rng, Module module) {
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

  std::set<int32_t> evaluatedClassesPresent() const {
    std::set<int32_t> present;
    const std::vector<int32_t>& eval = evaluatedClasses();
    for (const Item& item : items_) {
      if (std::find(eval.begin(), eval.end(), item.semantic) != eval.end()) {
        present.insert(item.semantic);
      }
    }
    return present;
  }

  // The walkway: the cores (room minus the band) or, around an island, the ring of the core.
  std::vector<Box2> clearFloor() const {
    if (!island_placed_) return core_;
    const Box2& c = core_.front();
    const Box2& z = island_zone_;
    return {Box2(c.min(), Vector2f(c.max().x(), z.min().y())),
            Box2(Vector2f(c.min().x(), z.max().y()), c.max()),
            Box2(Vector2f(c.min().x(), z.min().y()), Vector2f(z.min().x(), z.max().y())),
            Box2(Vector2f(z.max().x(), z.min().y()), Vector2f(c.max().x(), z.max().y()))};
  }

 private:
  enum CellState : uint8_t { kOutside, kFree, kBlocked };

  Vector2f cellCentre(int i, int j) const {
    return Vector2f((static_cast<float>(i) + 0.5f) * kFreeCellM,
                    (static_cast<float>(j) + 0.5f) * kFreeCellM);
  }

  bool fits(const Module& world, bool island) const {
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

  // Cells a camera at kCameraHeightsM could no longer use (closer than the clearance to an
  // object's box), or false when too little free floor would be left.
  bool freeSpaceAfter(const Module& world, std::vector<int>* newly) const {
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

  bool tryCommit(const Module& world, bool island) {
    if (!fits(world, island)) return false;
    std::vector<int> newly;
    if (!freeSpaceAfter(world, &newly)) return false;
    for (int c : newly) state_[c] = kBlocked;
    free_cells_ -= static_cast<int>(newly.size());
    for (const Item& item : world.items) {
      items_.push_back(item);
      blockers_.push_back(item.bounds());
    }
    for (const Box3& r : world.reserved) blockers_.push_back(r);
    return true;
  }

  const RoomShape& shape_;
  float ceiling_m_;
  float band_m_;
  std::vector<WallSegment> walls_;
  std::vector<Box2> core_;
  Box2 island_zone_;
  bool island_placed_ = false;
  std::vector<Item> items_;
  std::vector<Box3> blockers_;
  int cells_x_ = 0, cells_y_ = 0, floor_cells_ = 0, free_cells_ = 0;
  std::vector<uint8_t> state_;
};

enum class Group { kCounter, kFridge, kDesk, kBookshelf, kSofa, kBed, kBath, kToilet, kOther };

Module buildGroup(Group g, Rng* rng, const BuildContext& ctx) {
  switch (g) {
    case Group::kCounter:
      return buildCounter(rng, ctx);
    case Group::kFridge:
      return buildFridge(rng, ctx);
    case Group::kDesk:
      return buildDesk(rng, ctx);
    case Group::kBookshelf:
      return buildBookshelf(rng, ctx);
    case Group::kSofa:
      return buildSofa(rng, ctx);
    case Group::kBed:
      return buildBed(rng, ctx);
    case Group::kBath:
      return buildBath(rng, ctx);
    case Group::kToilet:
      return buildToilet(rng, ctx);
    case Group::kOther:
      return buildOtherFurniture(rng, ctx);
  }
  return Module();
}

// Tries a few freshly drawn variants of a module (sizes differ) along the walls.
template <typename Build>
bool placeSome(Layout* layout, Rng* rng, Build build, int tries = 3) {
  for (int t = 0; t < tries; ++t) {
    if (layout->placeOnWall(rng, build())) return true;
  }
  return false;
}

// One furnishing attempt; nullptr when a compulsory group or `min_classes` does not fit.
std::unique_ptr<Layout> furnish(const RoomShape& shape, float ceiling_m, const RoomConfig& config,
                                Rng* rng) {
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

// ---- Mesh --------------------------------------------------------------------------------

struct Solid {
  Box3 box;
  bool cylinder = false;
  float inner_radius_m = 0.0f;  // of the tessellated cylinder: its sides are chords
};

bool solidContains(const Solid& s, const Vector3f& p, float tol) {
  if (p.z() < s.box.min().z() - tol || p.z() > s.box.max().z() + tol) return false;
  if (!s.cylinder) {
    return p.x() >= s.box.min().x() - tol && p.x() <= s.box.max().x() + tol &&
           p.y() >= s.box.min().y() - tol && p.y() <= s.box.max().y() + tol;
  }
  const Vector2f c = s.box.center().head<2>();
  return (p.head<2>() - c).squaredNorm() <= s.inner_radius_m * s.inner_radius_m;
}

// Tessellates rectangles and vertical cylinders into triangles whose edges are at most
// max_edge_m (square cells of side max_edge / sqrt 2, so the diagonal fits too), leaving out
// the cells nobody can see: those whose samples, pushed kPushM along the normal, all land in
// another solid or outside the room.
class MeshWriter {
 public:
  MeshWriter(const RoomShape& shape, float ceiling_m, float max_edge_m, std::vector<Solid> solids,
             LabelledMesh* mesh)
      : shape_(shape),
        ceiling_m_(ceiling_m),
        cell_m_(max_edge_m / std::sqrt(2.0f)),
        solids_(std::move(solids)),
        mesh_(mesh) {
    for (Solid& s : solids_) {
      const float r = 0.5f * s.box.sizes().x();
      s.inner_radius_m = r * static_cast<float>(std::cos(kPi / segmentsFor(r)));
    }
  }

  void setLabel(int32_t instance, int32_t semantic, const Rgb8& color) {
    instance_ = instance;
    semantic_ = semantic;
    color_ = color;
  }

  // The axis-aligned rectangle with corners p00, p10 = p00 + u and p01 = p00 + v, facing
  // u x v. `self` is the solid it bounds. Grid vertices interpolate each coordinate between the
  // exact corner values, so the edge a face shares with its neighbour has bit-identical
  // vertices and a ray cannot slip between them into the box.
  void addRect(const Vector3f& p00, const Vector3f& p10, const Vector3f& p01, int self) {
    const Vector3f u = p10 - p00, v = p01 - p00;
    if (u.squaredNorm() == 0.0f || v.squaredNorm() == 0.0f) return;
    const Vector3f n = u.cross(v).normalized();
    const int nu = cells(u.norm()), nv = cells(v.norm());
    Box3 region(p00);
    region.extend(p10);
    region.extend(p01);
    region.extend(p10 + v);
    const std::vector<int> near = nearbySolids(region, self);
    std::vector<int32_t> index(static_cast<size_t>(nu + 1) * (nv + 1), -1);
    auto lerp = [](float a, float b, int i, int count) {
      return i == count ? b : a + (b - a) * (static_cast<float>(i) / static_cast<float>(count));
    };
    auto vertex = [&](int i, int j) {
      int32_t& id = index[static_cast<size_t>(j) * (nu + 1) + i];
      if (id < 0) {
        Vector3f p;
        for (int k = 0; k < 3; ++k) {
          p[k] = p10[k] != p00[k]   ? lerp(p00[k], p10[k], i, nu)
                 : p01[k] != p00[k] ? lerp(p00[k], p01[k], j, nv)
                                    : p00[k];
        }
        id = addVertex(p);
      }
      return id;
    };
    // A cell is hidden when the blocked region of the plane just in front of it covers it.
    // That region is a union of axis-aligned rectangles (solids' sections, the outside of a
    // rectilinear room), so testing the centre of every piece the rectangles' edges cut the
    // cell into is exact: a 1 cm gap between two doors keeps the cells behind it.
    int ua = 0, va = 0, na = 0;
    u.cwiseAbs().maxCoeff(&ua);
    v.cwiseAbs().maxCoeff(&va);
    n.cwiseAbs().maxCoeff(&na);
    const float plane = p00[na] + (n[na] > 0.0f ? kPushM : -kPushM);
    const std::vector<float> cuts_u = cuts(ua, near), cuts_v = cuts(va, near);
    auto covered = [&](float u0, float u1, float v0, float v1) {
      std::vector<float> su = between(cuts_u, u0, u1), sv = between(cuts_v, v0, v1);
      for (size_t a = 0; a + 1 < su.size(); ++a) {
        for (size_t b = 0; b + 1 < sv.size(); ++b) {
          Vector3f p;
          p[ua] = 0.5f * (su[a] + su[a + 1]);
          p[va] = 0.5f * (sv[b] + sv[b + 1]);
          p[na] = plane;
          const int by = blocker(p, near);
          if (by == kFree) return false;
          if (by == kOutside || !solids_[by].cylinder) continue;
          // A disc's section is not cut into rectangles: all four corners must be on it.
          for (int corner = 0; corner < 4; ++corner) {
            Vector3f q = p;
            q[ua] = su[a + (corner & 1)];
            q[va] = sv[b + (corner >> 1)];
            if (!solidContains(solids_[by], q, kTolM)) return false;
          }
        }
      }
      return true;
    };
    for (int j = 0; j < nv; ++j) {
      const float va0 = lerp(p00[va], p01[va], j, nv), va1 = lerp(p00[va], p01[va], j + 1, nv);
      for (int i = 0; i < nu; ++i) {
        const float ua0 = lerp(p00[ua], p10[ua], i, nu), ua1 = lerp(p00[ua], p10[ua], i + 1, nu);
        Vector3f centre;
        centre[ua] = 0.5f * (ua0 + ua1);
        centre[va] = 0.5f * (va0 + va1);
        centre[na] = plane;
        if (blocked(centre, near) && covered(std::min(ua0, ua1), std::max(ua0, ua1),
                                             std::min(va0, va1), std::max(va0, va1))) {
          continue;
        }
        const int32_t a = vertex(i, j), b = vertex(i + 1, j), c = vertex(i + 1, j + 1),
                      d = vertex(i, j + 1);
        mesh_->faces.emplace_back(a, b, c);
        mesh_->faces.emplace_back(a, c, d);
      }
    }
  }

  // Sorted coordinates along `axis` where the blocked region can change: the faces of nearby
  // solids and the walls, floor and ceiling.
  std::vector<float> cuts(int axis, const std::vector<int>& near) const {
    std::vector<float> out;
    for (int s : near) {
      out.push_back(solids_[s].box.min()[axis] - kTolM);
      out.push_back(solids_[s].box.max()[axis] + kTolM);
    }
    if (axis == 2) {
      out.push_back(0.0f);
      out.push_back(ceiling_m_);
    } else {
      for (const Vector2f& p : shape_.polygon) out.push_back(p[axis]);
    }
    std::sort(out.begin(), out.end());
    return out;
  }

  // lo, the cuts strictly between lo and hi, hi.
  static std::vector<float> between(const std::vector<float>& cuts, float lo, float hi) {
    std::vector<float> out = {lo};
    for (auto it = std::upper_bound(cuts.begin(), cuts.end(), lo); it != cuts.end() && *it < hi;
         ++it) {
      out.push_back(*it);
    }
    out.push_back(hi);
    return out;
  }

  // The six faces of a box, each facing out.
  void addBox(const Box3& b, int self) {
    const float x0 = b.min().x(), y0 = b.min().y(), z0 = b.min().z();
    const float x1 = b.max().x(), y1 = b.max().y(), z1 = b.max().z();
    addRect({x1, y0, z0}, {x1, y1, z0}, {x1, y0, z1}, self);  // +x
    addRect({x0, y0, z0}, {x0, y0, z1}, {x0, y1, z0}, self);  // -x
    addRect({x0, y1, z0}, {x0, y1, z1}, {x1, y1, z0}, self);  // +y
    addRect({x0, y0, z0}, {x1, y0, z0}, {x0, y0, z1}, self);  // -y
    addRect({x0, y0, z1}, {x1, y0, z1}, {x0, y1, z1}, self);  // +z
    addRect({x0, y0, z0}, {x0, y1, z0}, {x1, y0, z0}, self);  // -z
  }

  // A vertical cylinder inscribed in `b`: side, top and bottom discs.
  void addCylinder(const Box3& b, int self) {
    const Vector2f c = b.center().head<2>();
    const float r = 0.5f * b.sizes().x();
    const float z0 = b.min().z(), z1 = b.max().z();
    const int segments = segmentsFor(r);
    const int nz = cells(z1 - z0);
    const int rings = cells(r);
    const std::vector<int> near = nearbySolids(b, self);
    auto rim = [&](float s, float radius, float z) {
      const double theta = 2.0 * kPi * static_cast<double>(s) / segments;
      return Vector3f(c.x() + radius * static_cast<float>(std::cos(theta)),
                      c.y() + radius * static_cast<float>(std::sin(theta)), z);
    };
    // Side: cells of (segment, height), wrapping around.
    std::vector<int32_t> side(static_cast<size_t>(segments) * (nz + 1), -1);
    auto sideVertex = [&](int s, int j) {
      int32_t& id = side[static_cast<size_t>(j) * segments + (s % segments)];
      if (id < 0) id = addVertex(rim(static_cast<float>(s % segments), r, zAt(z0, z1, j, nz)));
      return id;
    };
    for (int j = 0; j < nz; ++j) {
      for (int s = 0; s < segments; ++s) {
        auto sample = [&](int k) {
          static constexpr float kAt[3] = {0.5f, 0.0f, 1.0f};
          const float zs = z0 + (z1 - z0) * (static_cast<float>(j) + kAt[k / 3]) / nz;
          return rim(static_cast<float>(s) + kAt[k % 3], r + kPushM, zs);
        };
        if (hidden(sample, 9, near)) continue;
        const int32_t a = sideVertex(s, j), bb = sideVertex(s + 1, j),
                      cc = sideVertex(s + 1, j + 1), d = sideVertex(s, j + 1);
        mesh_->faces.emplace_back(a, bb, cc);
        mesh_->faces.emplace_back(a, cc, d);
      }
    }
    addDisc(c, r, z1, true, segments, rings, near);
    addDisc(c, r, z0, false, segments, rings, near);
  }

 private:
  static float zAt(float z0, float z1, int j, int n) {
    return j == n ? z1 : z0 + (z1 - z0) * static_cast<float>(j) / static_cast<float>(n);
  }

  int segmentsFor(float radius) const {
    return std::max(8,
                    static_cast<int>(std::ceil(2.0f * static_cast<float>(kPi) * radius / cell_m_)));
  }

  int cells(float length) const {
    return std::max(1, static_cast<int>(std::ceil(length / cell_m_)));
  }

  // Concentric rings of quads around a fan at the centre; `up` faces +z.
  void addDisc(const Vector2f& c, float r, float z, bool up, int segments, int rings,
               const std::vector<int>& near) {
    const float push = up ? kPushM : -kPushM;
    auto point = [&](int ring, int s) {
      const double theta = 2.0 * kPi * static_cast<double>(s % segments) / segments;
      // The rim is exactly the side's top or bottom ring: no slit between disc and side.
      const float radius =
          ring == rings ? r : r * static_cast<float>(ring) / static_cast<float>(rings);
      return Vector3f(c.x() + radius * static_cast<float>(std::cos(theta)),
                      c.y() + radius * static_cast<float>(std::sin(theta)), z);
    };
    int32_t centre = -1;
    std::vector<int32_t> index(static_cast<size_t>(rings) * segments, -1);
    auto vertex = [&](int ring, int s) {
      if (ring == 0) {
        if (centre < 0) centre = addVertex(Vector3f(c.x(), c.y(), z));
        return centre;
      }
      int32_t& id = index[static_cast<size_t>(ring - 1) * segments + (s % segments)];
      if (id < 0) id = addVertex(point(ring, s));
      return id;
    };
    const Vector3f lift(0.0f, 0.0f, push);
    for (int ring = 1; ring <= rings; ++ring) {
      for (int s = 0; s < segments; ++s) {
        const std::array<Vector3f, 4> corners = {point(ring - 1, s), point(ring, s),
                                                 point(ring, s + 1), point(ring - 1, s + 1)};
        auto sample = [&](int k) {
          if (k == 0)
            return Vector3f(0.25f * (corners[0] + corners[1] + corners[2] + corners[3]) + lift);
          return Vector3f(corners[k - 1] + lift);
        };
        if (hidden(sample, 5, near)) continue;
        const int32_t a = vertex(ring - 1, s), b = vertex(ring, s), cc = vertex(ring, s + 1);
        if (ring == 1) {
          if (up) {
            mesh_->faces.emplace_back(a, b, cc);
          } else {
            mesh_->faces.emplace_back(a, cc, b);
          }
          continue;
        }
        const int32_t d = vertex(ring - 1, s + 1);
        if (up) {
          mesh_->faces.emplace_back(a, b, cc);
          mesh_->faces.emplace_back(a, cc, d);
        } else {
          mesh_->faces.emplace_back(a, cc, b);
          mesh_->faces.emplace_back(a, d, cc);
        }
      }
    }
  }

  std::vector<int> nearbySolids(const Box3& region, int self) const {
    const Vector3f pad = Vector3f::Constant(kPushM + 2.0f * kTolM);
    const Box3 grown(region.min() - pad, region.max() + pad);
    std::vector<int> near;
    for (size_t s = 0; s < solids_.size(); ++s) {
      if (static_cast<int>(s) != self && grown.intersects(solids_[s].box)) {
        near.push_back(static_cast<int>(s));
      }
    }
    return near;
  }

  static constexpr int kFree = -1, kOutside = -2;

  // What hides p: kOutside (the room's outside), a box's index, else a cylinder's index, else
  // kFree.
  int blocker(const Vector3f& p, const std::vector<int>& near) const {
    if (p.z() < -kTolM || p.z() > ceiling_m_ + kTolM) return kOutside;
    if (!shape_.contains(p.head<2>(), kTolM)) return kOutside;
    int found = kFree;
    for (int s : near) {
      if (!solidContains(solids_[s], p, kTolM)) continue;
      if (!solids_[s].cylinder) return s;
      found = s;
    }
    return found;
  }

  bool blocked(const Vector3f& p, const std::vector<int>& near) const {
    return blocker(p, near) != kFree;
  }

  // Sample 0 first: most cells are visible at their centre and stop there.
  template <typename Sample>
  bool hidden(Sample sample, int count, const std::vector<int>& near) const {
    for (int k = 0; k < count; ++k) {
      if (!blocked(sample(k), near)) return false;
    }
    return true;
  }

  int32_t addVertex(const Vector3f& p) {
    mesh_->vertices.push_back(p);
    mesh_->colors.push_back(color_);
    mesh_->semantic.push_back(semantic_);
    mesh_->instance.push_back(instance_);
    return static_cast<int32_t>(mesh_->vertices.size() - 1);
  }

  const RoomShape& shape_;
  float ceiling_m_;
  float cell_m_;
  std::vector<Solid> solids_;
  LabelledMesh* mesh_;
  int32_t instance_ = 0;
  int32_t semantic_ = 0;
  Rgb8 color_;
};

std::string metres(float v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

}  // namespace

void RoomConfig::check() const {
  auto fail = [](const std::string& field, const std::string& why, float value) {
    throw Error(field + ": " + why + ", got " + metres(value));
  };
  if (!(min_width_m >= 2.0f)) fail("min_width_m", "must be at least 2 m", min_width_m);
  if (!(max_width_m >= min_width_m)) fail("max_width_m", "must be >= min_width_m", max_width_m);
  if (!(max_width_m <= 30.0f)) fail("max_width_m", "must be at most 30 m", max_width_m);
  if (!(min_ceiling_m >= 2.3f)) {
    fail("min_ceiling_m", "must be at least 2.3 m (doors, shower curtains)", min_ceiling_m);
  }
  if (!(max_ceiling_m >= min_ceiling_m)) {
    fail("max_ceiling_m", "must be >= min_ceiling_m", max_ceiling_m);
  }
  if (!(max_ceiling_m <= 10.0f)) fail("max_ceiling_m", "must be at most 10 m", max_ceiling_m);
  if (!(l_shape_probability >= 0.0f && l_shape_probability <= 1.0f)) {
    fail("l_shape_probability", "must be in [0, 1]", l_shape_probability);
  }
  if (!(max_edge_m > 0.0f)) fail("max_edge_m", "must be > 0", max_edge_m);
  if (!(max_edge_m >= 0.005f)) {
    fail("max_edge_m", "must be at least 0.005 m (finer meshes are too large)", max_edge_m);
  }
  const int n = static_cast<int>(evaluatedClasses().size());
  if (min_classes < 0 || min_classes > n) {
    throw Error("min_classes: must be in [0, " + std::to_string(n) + "], got " +
                std::to_string(min_classes));
  }
}

ProceduralRoom generateRoom(uint64_t seed, const RoomConfig& config) {
  config.check();
  // The floor plan depends on the seed alone; furnishing retries draw from their own streams.
  Rng shape_rng(splitMix64(seed));
  const RoomShape shape = drawShape(&shape_rng, config);
  const float ceiling_m = shape_rng.uniform(config.min_ceiling_m, config.max_ceiling_m);
  std::unique_ptr<Layout> layout;
  uint64_t stream = 0;
  for (int attempt = 0; attempt < kMaxAttempts && !layout; ++attempt) {
    stream = splitMix64(seed ^ splitMix64(0xF0123456789ull + static_cast<uint64_t>(attempt)));
    Rng rng(stream);
    layout = furnish(shape, ceiling_m, config, &rng);
  }
  if (!layout) {
    throw Error("min_classes: " + std::to_string(config.min_classes) +
                " evaluated classes do not fit in the " + metres(shape.width_m) + " x " +
                metres(shape.depth_m) + " m room of seed " + std::to_string(seed));
  }
  Rng colour_rng(splitMix64(stream + 1));

  ProceduralRoom room;
  room.seed = seed;
  room.ceiling_height_m = ceiling_m;
  room.floor_polygon = shape.polygon;
  room.clear_floor = layout->clearFloor();

  std::vector<Solid> solids;
  for (const Item& item : layout->items()) {
    for (const Part& p : item.parts) solids.push_back(Solid{p.box, p.cylinder});
  }
  MeshWriter writer(shape, ceiling_m, config.max_edge_m, solids, &room.mesh);
  const float w = shape.width_m, d = shape.depth_m, h = ceiling_m;

  writer.setLabel(1, kWall, tint(&colour_rng, 225, 220, 210, 25));
  for (size_t i = 0; i < shape.polygon.size(); ++i) {
    const Vector2f a = shape.polygon[i];
    const Vector2f b = shape.polygon[(i + 1) % shape.polygon.size()];
    // z x (b - a) is the inward normal of a counter-clockwise outline.
    writer.addRect({a.x(), a.y(), 0.0f}, {a.x(), a.y(), h}, {b.x(), b.y(), 0.0f}, -1);
  }
  writer.setLabel(2, kFloor, tint(&colour_rng, 150, 115, 80, 40));
  for (const Box2& t : shape.tiles) {
    const Vector2f a = t.min(), b = t.max();
    writer.addRect({a.x(), a.y(), 0.0f}, {b.x(), a.y(), 0.0f}, {a.x(), b.y(), 0.0f}, -1);
  }
  writer.setLabel(3, kCeiling, tint(&colour_rng, 240, 240, 238, 8));
  for (const Box2& t : shape.tiles) {
    const Vector2f a = t.min(), b = t.max();
    writer.addRect({a.x(), a.y(), h}, {a.x(), b.y(), h}, {b.x(), a.y(), h}, -1);
  }
  room.objects.push_back(
      RoomObject{1, kWall, "wall", Box3(Vector3f::Zero(), Vector3f(w, d, h)), {}});
  room.objects.push_back(
      RoomObject{2, kFloor, "floor", Box3(Vector3f::Zero(), Vector3f(w, d, 0.0f)), {}});
  room.objects.push_back(
      RoomObject{3, kCeiling, "ceiling", Box3(Vector3f(0.0f, 0.0f, h), Vector3f(w, d, h)), {}});

  int solid = 0;
  int32_t instance = 4;
  for (const Item& item : layout->items()) {
    writer.setLabel(instance, item.semantic, item.color);
    RoomObject object{instance, item.semantic, item.name, item.bounds(), {}};
    for (const Part& p : item.parts) {
      if (p.cylinder) {
        writer.addCylinder(p.box, solid);
      } else {
        writer.addBox(p.box, solid);
      }
      object.parts.push_back(p.box);
      ++solid;
    }
    room.objects.push_back(std::move(object));
    ++instance;
  }
  return room;
}

}  // namespace panmap

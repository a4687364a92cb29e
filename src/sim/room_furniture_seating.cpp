#include "panmap/sim/internal/room_furniture.h"

#include <algorithm>
#include <vector>

namespace panmap {
namespace internal {
namespace room {
namespace {

constexpr float kChairW = 0.44f, kChairD = 0.44f, kSeatZ = 0.45f;

Item makeTable(RoomRng* rng, const char* name, float x0, float y0, float l, float w, float top_z) {
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

// A four-legged chair with a back; its front edge is centred at (x, y) and it faces -y turned
// by `quarter_turns` (1: faces +x, 2: +y, 3: -x).
Item makeChair(RoomRng* rng, float x, float y, int quarter_turns, const Rgb8& base) {
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

Rgb8 chairColour(RoomRng* rng) { return tint(rng, 140, 95, 60, 50); }

}  // namespace

Module buildTableGroup(RoomRng* rng, const BuildContext& ctx) {
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

Module buildIslandTableGroup(RoomRng* rng, bool end_chairs) {
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

Module buildDesk(RoomRng* rng, const BuildContext& ctx) {
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

Module buildSofa(RoomRng* rng, const BuildContext& ctx) {
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

}  // namespace room
}  // namespace internal
}  // namespace panmap

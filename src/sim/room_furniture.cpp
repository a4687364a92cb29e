#include "panmap/sim/internal/room_furniture.h"

#include <algorithm>
#include <vector>

namespace panmap {
namespace internal {
namespace room {
namespace {

// One bed with its head at y = 0: headboard, frame, a mattress inset on it, pillows on top.
void addBed(RoomRng* rng, float x0, float bw, std::vector<Item>* items) {
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

}  // namespace

Module buildDoor(RoomRng* rng, const BuildContext& ctx) {
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

Module buildWindow(RoomRng* rng, const BuildContext& ctx, bool curtains) {
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

Module buildPicture(RoomRng* rng, const BuildContext& ctx) {
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

Module buildCabinets(RoomRng* rng, const BuildContext& ctx) {
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

Module buildCounter(RoomRng* rng, const BuildContext& ctx) {
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

Module buildFridge(RoomRng* rng, const BuildContext& ctx) {
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

Module buildBookshelf(RoomRng* rng, const BuildContext& ctx) {
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

Module buildBed(RoomRng* rng, const BuildContext& ctx) {
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

Module buildBath(RoomRng* rng, const BuildContext& ctx) {
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

Module buildToilet(RoomRng* rng, const BuildContext& ctx) {
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

Module buildOtherFurniture(RoomRng* rng, const BuildContext& ctx) {
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

Module buildBoxes(RoomRng* rng, const BuildContext& ctx) {
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

Module buildGroup(Group g, RoomRng* rng, const BuildContext& ctx) {
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
    case Group::kDresser:
      return buildDresser(rng, ctx);
    case Group::kWallShelf:
      return buildWallShelf(rng, ctx);
    case Group::kWallBoard:
      return buildWallBoard(rng, ctx);
  }
  return Module();
}

}  // namespace room
}  // namespace internal
}  // namespace panmap

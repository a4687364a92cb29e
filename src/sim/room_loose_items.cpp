#include "panmap/sim/internal/room_loose_items.h"

#include <algorithm>
#include <vector>

namespace panmap {
namespace internal {
namespace room {
namespace {

// Moves the item so that its bounds start at the origin (builders may overhang to -x, -y).
Item atOrigin(Item item) {
  const Vector3f lo = item.bounds().min();
  for (Part& p : item.parts) p.box.translate(-lo);
  return item;
}

// A box at the origin, each side drawn from its range: height, depth, width in that order (the
// order the rooms' draws were fixed in).
Part drawnBox(RoomRng* rng, float w0, float w1, float d0, float d1, float h0, float h1) {
  const float h = rng->uniform(h0, h1);
  const float d = rng->uniform(d0, d1);
  const float w = rng->uniform(w0, w1);
  return cuboid(0.0f, 0.0f, 0.0f, w, d, h);
}

Item bookStack(RoomRng* rng) {
  Item books = makeItem(kBooks, "books", anyColour(rng));
  const int n = rng->uniformInt(1, 4);
  const float w0 = rng->uniform(0.15f, 0.26f), d0 = rng->uniform(0.11f, 0.19f);
  float z = 0.0f;
  for (int i = 0; i < n; ++i) {
    // Each book a little smaller and shifted: a stack is not a block.
    const float w = w0 * rng->uniform(0.8f, 1.0f), d = d0 * rng->uniform(0.8f, 1.0f);
    const float t = rng->uniform(0.015f, 0.045f);
    const float ox = rng->uniform(0.0f, w0 - w + 0.02f), oy = rng->uniform(0.0f, d0 - d + 0.02f);
    books.parts.push_back(cuboid(ox, oy, z, ox + w, oy + d, z + t));
    z += t;
  }
  return atOrigin(books);
}

Item smallBox(RoomRng* rng, float max_side) {
  Item box = makeItem(kBox, "box", tint(rng, 185, 145, 95, 35));
  const float w = rng->uniform(0.1f, max_side), d = rng->uniform(0.08f, max_side);
  box.parts.push_back(cuboid(0.0f, 0.0f, 0.0f, w, d, rng->uniform(0.06f, max_side)));
  return box;
}

Item bottle(RoomRng* rng) {
  Item b = makeItem(kOtherProp, "bottle", anyColour(rng));
  const float r = rng->uniform(0.03f, 0.045f), h = rng->uniform(0.14f, 0.22f);
  const float neck = rng->uniform(0.04f, 0.06f);
  const float neck_r = rng->uniform(0.012f, 0.016f);
  b.parts.push_back(cylinder(r, r, r, 0.0f, h));
  b.parts.push_back(cylinder(r, r, neck_r, h, h + neck));
  return b;
}

Item cup(RoomRng* rng) {
  Item c = makeItem(kOtherProp, "cup", anyColour(rng));
  const float r = rng->uniform(0.035f, 0.045f);
  c.parts.push_back(cylinder(r, r, r, 0.0f, rng->uniform(0.08f, 0.11f)));
  return c;
}

Item keyboard(RoomRng* rng) {
  Item k = makeItem(kOtherProp, "keyboard", tint(rng, 40, 40, 45, 15));
  k.parts.push_back(drawnBox(rng, 0.36f, 0.45f, 0.12f, 0.15f, 0.02f, 0.03f));
  return k;
}

Item mouse(RoomRng* rng) {
  Item m = makeItem(kOtherProp, "mouse", tint(rng, 50, 50, 55, 20));
  m.parts.push_back(drawnBox(rng, 0.055f, 0.07f, 0.1f, 0.12f, 0.03f, 0.04f));
  return m;
}

Item laptop(RoomRng* rng) {
  Item l = makeItem(kOtherProp, "laptop", tint(rng, 60, 60, 65, 25));
  const float w = rng->uniform(0.3f, 0.34f), d = rng->uniform(0.21f, 0.24f);
  l.parts.push_back(cuboid(0.0f, 0.0f, 0.0f, w, d, 0.018f));
  // The open screen stands at the back edge: its back is y = 0.
  l.parts.push_back(cuboid(0.0f, 0.0f, 0.018f, w, 0.012f, 0.018f + rng->uniform(0.19f, 0.22f)));
  return l;
}

Item paper(RoomRng* rng) {
  Item p = makeItem(kPaper, "paper", tint(rng, 238, 238, 232, 10));
  p.parts.push_back(drawnBox(rng, 0.21f, 0.29f, 0.15f, 0.21f, 0.008f, 0.025f));
  return p;
}

Item deskLamp(RoomRng* rng) {
  Item lamp = makeItem(kLamp, "lamp", tint(rng, 225, 205, 160, 30));
  const float shade = rng->uniform(0.08f, 0.11f), base = rng->uniform(0.06f, 0.075f);
  const float stem = rng->uniform(0.25f, 0.38f);
  lamp.parts.push_back(cylinder(shade, shade, base, 0.0f, 0.025f));
  lamp.parts.push_back(cylinder(shade, shade, 0.01f, 0.025f, stem));
  lamp.parts.push_back(
      cylinder(shade, shade, shade, stem - 0.02f, stem + rng->uniform(0.12f, 0.16f)));
  return lamp;
}

Item towel(RoomRng* rng) {
  Item t = makeItem(kTowel, "towel", tint(rng, 200, 200, 210, 50));
  t.parts.push_back(drawnBox(rng, 0.22f, 0.29f, 0.14f, 0.2f, 0.04f, 0.08f));
  return t;
}

Item clothes(RoomRng* rng) {
  Item c = makeItem(kClothes, "clothes", anyColour(rng));
  const int n = rng->uniformInt(2, 4);
  float z = 0.0f;
  for (int i = 0; i < n; ++i) {
    const float w = rng->uniform(0.25f, 0.45f), d = rng->uniform(0.2f, 0.35f);
    const float t = rng->uniform(0.03f, 0.08f);
    const float ox = rng->uniform(-0.08f, 0.08f), oy = rng->uniform(-0.08f, 0.08f);
    c.parts.push_back(cuboid(ox, oy, z, ox + w, oy + d, z + t));
    z += t;
  }
  return atOrigin(c);
}

Item cushion(RoomRng* rng) {
  Item c = makeItem(kPillow, "pillow", anyColour(rng));
  c.parts.push_back(drawnBox(rng, 0.35f, 0.45f, 0.12f, 0.18f, 0.3f, 0.42f));
  return c;
}

Item bag(RoomRng* rng) {
  Item b = makeItem(kBag, "bag", anyColour(rng));
  switch (rng->uniformInt(0, 2)) {
    case 0: {  // a handbag with a handle loop
      const float w = rng->uniform(0.22f, 0.29f), d = rng->uniform(0.1f, 0.14f);
      const float h = rng->uniform(0.18f, 0.24f);
      b.parts.push_back(cuboid(0.0f, 0.0f, 0.0f, w, d, h));
      const float y0 = 0.5f * d - 0.01f;
      b.parts.push_back(cuboid(0.05f, y0, h, 0.07f, y0 + 0.02f, h + 0.08f));
      b.parts.push_back(cuboid(w - 0.07f, y0, h, w - 0.05f, y0 + 0.02f, h + 0.08f));
      b.parts.push_back(cuboid(0.05f, y0, h + 0.08f, w - 0.05f, y0 + 0.02f, h + 0.1f));
      break;
    }
    case 1: {  // a backpack with a front pocket
      const float w = rng->uniform(0.28f, 0.33f), d = rng->uniform(0.14f, 0.2f);
      const float h = rng->uniform(0.38f, 0.46f);
      b.parts.push_back(cuboid(0.0f, 0.0f, 0.0f, w, d, h));
      b.parts.push_back(cuboid(0.05f, d, 0.04f, w - 0.05f, d + 0.06f, 0.5f * h));
      break;
    }
    default: {  // a paper bag
      b.parts.push_back(drawnBox(rng, 0.2f, 0.29f, 0.12f, 0.18f, 0.2f, 0.29f));
    }
  }
  return b;
}

Item shoes(RoomRng* rng) {
  Item s = makeItem(kOtherProp, "shoes", anyColour(rng));
  const float w = rng->uniform(0.09f, 0.11f), l = rng->uniform(0.24f, 0.29f);
  const float h = rng->uniform(0.08f, 0.12f), gap = rng->uniform(0.02f, 0.05f);
  s.parts.push_back(cuboid(0.0f, 0.0f, 0.0f, w, l, h));
  s.parts.push_back(cuboid(w + gap, 0.0f, 0.0f, 2.0f * w + gap, l, h));
  return s;
}

Item leaningPicture(RoomRng* rng) {
  Item p = makeItem(kPicture, "picture", anyColour(rng));
  p.parts.push_back(drawnBox(rng, 0.3f, 0.6f, 0.02f, 0.03f, 0.3f, 0.55f));
  return p;
}

Item plant(RoomRng* rng) {
  Item p = makeItem(kOtherProp, "plant", tint(rng, 70, 120, 60, 30));
  const float r = rng->uniform(0.08f, 0.14f), pot = rng->uniform(0.15f, 0.3f);
  p.parts.push_back(cylinder(r, r, r, 0.0f, pot));
  // Foliage: boxes wider than the pot, stacked.
  float z = pot;
  const int n = rng->uniformInt(2, 3);
  for (int i = 0; i < n; ++i) {
    const float s = 2.0f * r * rng->uniform(0.7f, 1.3f), t = rng->uniform(0.1f, 0.25f);
    p.parts.push_back(cuboid(r - 0.5f * s, r - 0.5f * s, z, r + 0.5f * s, r + 0.5f * s, z + t));
    z += t;
  }
  return atOrigin(p);
}

Item trashCan(RoomRng* rng) {
  Item can = makeItem(kOtherFurniture, "trash can", anyColour(rng));
  const float r = rng->uniform(0.1f, 0.15f);
  can.parts.push_back(cylinder(r, r, r, 0.0f, rng->uniform(0.25f, 0.35f)));
  return can;
}

bool soft(int32_t support) { return support == kBed || support == kSofa; }

}  // namespace

Item buildSurfaceObject(RoomRng* rng, int32_t support) {
  if (soft(support)) {
    switch (rng->uniformInt(0, 4)) {
      case 0:
        return cushion(rng);
      case 1:
        return clothes(rng);
      case 2:
        return bag(rng);
      case 3:
        return bookStack(rng);
      default:
        return towel(rng);
    }
  }
  if (support == kCounter) {
    switch (rng->uniformInt(0, 3)) {
      case 0:
        return bottle(rng);
      case 1:
        return cup(rng);
      case 2:
        return smallBox(rng, 0.25f);
      default:
        return towel(rng);
    }
  }
  // Mostly small things; a laptop, a lamp or a bag now and then.
  const bool work_top = support == kTable || support == kDesk;
  switch (rng->uniformInt(0, 9)) {
    case 0:
    case 1:
      return bookStack(rng);
    case 2:
      return smallBox(rng, 0.25f);
    case 3:
    case 4:
      return bottle(rng);
    case 5:
      return cup(rng);
    case 6:
      return work_top ? paper(rng) : towel(rng);
    case 7:
      return work_top ? laptop(rng) : smallBox(rng, 0.2f);
    case 8:
      return deskLamp(rng);
    default:
      return work_top ? bag(rng) : cup(rng);
  }
}

Item buildSmallObject(RoomRng* rng, int32_t support) {
  switch (rng->uniformInt(0, 5)) {
    case 0:
      return bookStack(rng);
    case 1:
      return smallBox(rng, 0.25f);
    case 2:
      return bottle(rng);
    case 3:
      return cup(rng);
    case 4:
      return support == kTable || support == kDesk ? paper(rng) : towel(rng);
    default:
      return soft(support) ? towel(rng) : cup(rng);
  }
}

Item buildFloorObject(RoomRng* rng) {
  switch (rng->uniformInt(0, 9)) {
    case 0:
    case 1:
      return bag(rng);
    case 2:
    case 3:
      return smallBox(rng, 0.28f);
    case 4:
      return smallBox(rng, 0.45f);
    case 5:
      return shoes(rng);
    case 6:
      return leaningPicture(rng);
    case 7:
      return plant(rng);
    case 8:
      return trashCan(rng);
    default:
      return rng->chance(0.5) ? clothes(rng) : bookStack(rng);
  }
}

Item buildSmallFloorObject(RoomRng* rng) {
  switch (rng->uniformInt(0, 4)) {
    case 0:
      return smallBox(rng, 0.28f);
    case 1:
      return shoes(rng);
    case 2:
      return bookStack(rng);
    default: {
      // A handbag or a paper bag: the two kinds of bag under 0.3 m.
      Item b = bag(rng);
      return isSmall(b) ? b : smallBox(rng, 0.28f);
    }
  }
}

Item buildDeskObject(RoomRng* rng) {
  switch (rng->uniformInt(0, 3)) {
    case 0:
      return keyboard(rng);
    case 1:
      return mouse(rng);
    case 2:
      return bookStack(rng);
    default:
      return paper(rng);
  }
}

Item buildPile(RoomRng* rng, float max_side_m, float max_height_m) {
  Item pile = makeItem(kUnannotated, "clutter", tint(rng, 125, 115, 105, 60));
  // Parts scale with the pile: a heap on the floor is made of larger things than one on a shelf.
  const float scale = std::min(1.0f, max_side_m);
  const float base_side = 0.55f * scale;
  pile.parts.push_back(drawnBox(rng, 0.2f * scale, base_side, 0.2f * scale, base_side, 0.05f,
                                std::min(0.35f, max_height_m)));
  const int n = rng->uniformInt(4, 8);
  for (int i = 1; i < n; ++i) {
    const Box3 below = pile.parts[rng->uniformInt(0, static_cast<int>(pile.parts.size()) - 1)].box;
    const float a = rng->uniform(0.06f, 0.4f * scale), b = rng->uniform(0.06f, 0.4f * scale);
    const float c = rng->uniform(0.03f, 0.3f);
    const bool on_top = rng->chance(0.55);
    const bool round = rng->chance(0.25);
    const float u = rng->uniform(0.0f, 1.0f), v = rng->uniform(0.0f, 1.0f);
    const int side = rng->uniformInt(0, 3);
    Vector3f lo;
    if (on_top) {
      // Centred somewhere over the part below, so it rests on it.
      lo = Vector3f(below.min().x() + u * below.sizes().x() - 0.5f * a,
                    below.min().y() + v * below.sizes().y() - 0.5f * b, below.max().z());
    } else {
      // On the ground, pushed against one side of the part.
      const float along_x = below.min().x() + u * below.sizes().x() - 0.5f * a;
      const float along_y = below.min().y() + v * below.sizes().y() - 0.5f * b;
      switch (side) {
        case 0:
          lo = Vector3f(below.max().x(), along_y, 0.0f);
          break;
        case 1:
          lo = Vector3f(below.min().x() - a, along_y, 0.0f);
          break;
        case 2:
          lo = Vector3f(along_x, below.max().y(), 0.0f);
          break;
        default:
          lo = Vector3f(along_x, below.min().y() - b, 0.0f);
      }
    }
    const Part part = round
                          ? cylinder(lo.x() + 0.5f * std::min(a, b), lo.y() + 0.5f * std::min(a, b),
                                     0.5f * std::min(a, b), lo.z(), lo.z() + c)
                          : cuboid(lo.x(), lo.y(), lo.z(), lo.x() + a, lo.y() + b, lo.z() + c);
    Box3 grown = pile.bounds();
    grown.extend(part.box);
    if (grown.sizes().head<2>().maxCoeff() > max_side_m || grown.max().z() > max_height_m) continue;
    pile.parts.push_back(part);
  }
  return atOrigin(pile);
}

bool isSmall(const Item& item) { return item.bounds().sizes().maxCoeff() < 0.3f; }

}  // namespace room
}  // namespace internal
}  // namespace panmap

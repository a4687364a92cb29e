#include <vector>

#include "panmap/sim/internal/room_furniture.h"
#include "panmap/sim/internal/room_layout.h"

namespace panmap {
namespace internal {
namespace room {
namespace {

// Furniture items beyond which no more optional groups are added: the loose objects need a
// share of the 30-60 instances a ScanNet-like room may have.
constexpr size_t kMaxFurnitureItems = 20;

}  // namespace

bool furnishScanNetLike(Layout* layout, RoomRng* rng, const RoomConfig& config) {
  const BuildContext ctx = layout->context();
  auto group = [&](Group g) {
    return placeSome(layout, rng, [&] { return buildGroup(g, rng, ctx); });
  };
  std::vector<Group> groups = {Group::kCounter,   Group::kFridge, Group::kDesk,
                               Group::kBookshelf, Group::kSofa,   Group::kBed,
                               Group::kBath,      Group::kToilet, Group::kOther};
  rng->shuffle(&groups);
  // The classes first (pictures, placed last, add one), then what real rooms have besides.
  std::vector<Group> later;
  for (Group g : groups) {
    if (static_cast<int>(layout->evaluatedClassesPresent().size()) + 1 >= config.min_classes) {
      later.push_back(g);
      continue;
    }
    group(g);
  }
  std::vector<Group> extras = {Group::kDresser, Group::kWallShelf, Group::kWallBoard};
  rng->shuffle(&extras);
  for (Group g : extras) group(g);
  for (Group g : later) {
    if (layout->items().size() >= kMaxFurnitureItems) break;
    group(g);
  }
  placeSome(layout, rng, [&] { return buildBoxes(rng, ctx); });
  const int pictures = rng->uniformInt(1, 3);
  int placed = 0;
  for (int i = 0; i < pictures; ++i) {
    placed += placeSome(layout, rng, [&] { return buildPicture(rng, ctx); }) ? 1 : 0;
  }
  return placed > 0 &&
         static_cast<int>(layout->evaluatedClassesPresent().size()) >= config.min_classes;
}

}  // namespace room
}  // namespace internal
}  // namespace panmap

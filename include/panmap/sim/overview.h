#pragma once

#include <cstddef>
#include <functional>
#include <vector>

#include "panmap/core/image.h"
#include "panmap/core/labelled_mesh.h"

namespace panmap {

/// The colour of a mesh vertex in one overview picture (a face takes its first vertex's).
using OverviewColouring = std::function<Rgb8(size_t vertex)>;

/// The mesh's own vertex colours, or MeshRenderer's grey when it has none.
OverviewColouring vertexColours(const LabelledMesh& mesh);

/// An overview picture of a mesh (a room or a reconstruction): seen from above one side of
/// its bounding box, looking down at its centre, with the top 20 cm (the ceiling) cut away.
/// Colours are the mesh's vertex colours (grey without them) with headlight shading.
ColorImage renderOverview(const LabelledMesh& mesh, int width = 1280, int height = 960);

/// renderOverview() in several colourings of the same mesh, rasterised once and without a copy
/// of the mesh's labels or colours (a whole map's mesh is hundreds of MB): picture i equals
/// renderOverview() of the mesh with colours[v] = colourings[i](v).
std::vector<ColorImage> renderOverviews(const LabelledMesh& mesh,
                                        const std::vector<OverviewColouring>& colourings,
                                        int width = 1280, int height = 960);

}  // namespace panmap

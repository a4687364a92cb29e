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

/// Overview pictures of a mesh (a room or a reconstruction), one per colouring: seen from above
/// one side of its bounding box, looking down at its centre, with the top 20 cm (the ceiling)
/// cut away, headlight shading. Rasterised once, with no copy of the mesh (a whole map's is
/// hundreds of MB).
std::vector<ColorImage> renderOverviews(const LabelledMesh& mesh,
                                        const std::vector<OverviewColouring>& colourings,
                                        int width = 1280, int height = 960);

}  // namespace panmap

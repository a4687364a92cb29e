#pragma once

#include "panmap/core/image.h"
#include "panmap/core/labelled_mesh.h"

namespace panmap {

/// An overview picture of a mesh (a room or a reconstruction): seen from above one side of
/// its bounding box, looking down at its centre, with the top 20 cm (the ceiling) cut away.
/// Colours are the mesh's vertex colours with headlight shading.
ColorImage renderOverview(const LabelledMesh& mesh, int width = 1280, int height = 960);

}  // namespace panmap

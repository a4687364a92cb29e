#pragma once

#include "panmap/graph/instance_evidence.h"
#include "panmap/graph/optimiser.h"
#include "panmap/graph/superpoint_graph.h"

namespace panmap {

/// The probability that an instance with this evidence is a real object: the logistic model of
/// OptimiserConfig::Objects, the area from its voxels at voxel_size_m. The optimiser's objects
/// and those a mapper reports without an optimiser's answer are scored by it alike, so a
/// confidence means the same whichever made it.
float objectConfidence(const InstanceEvidence& evidence, double voxel_size_m,
                       const OptimiserConfig::Objects& model);

/// What objectConfidence() reads from the evidence: area, support and class share.
ObjectEvidence objectEvidence(const InstanceEvidence& evidence, double voxel_size_m);

}  // namespace panmap

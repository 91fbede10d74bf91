// The closing note of a mesh with elements not proven valid: how many, where on the CAD (and at
// which cusps of the CAD, cad/face_cusps.hpp, when they have a corner at one), and what was
// tried on them (the optimiser, the repair rounds and their actions), so that a one-line
// message names the stage that gave up and the entity.
#pragma once

#include <string>
#include <vector>

#include "pipeline/mesh_pipeline.hpp"

namespace homesh {

// `linearGiven`: the caller gave the linear mesh (no repair rounds can remesh it).
std::string notValidNote(const MeshResult& result, bool linearGiven);

// One note per layer face (2D: curve) where the layer is well short of the thickness asked:
// fewer than kFullLayerShare of its columns at full height, or one below half of it. "the
// boundary layer on Face5 reaches its thickness on 0 % of its 194 columns; the thinnest is
// 4.2e-11 of it, at (0, 0, 0)", and the narrowest gap that held a column down, "; Face2 is 1 away
// along the layer's normal at (0.5, 0.5, 0): room for 0.4 of the 1e+09 asked there". A layer the
// space around it could not hold is grown to fit, and says so here as well as in the report.
inline constexpr double kFullLayerShare = 0.95;
std::vector<std::string> layerShortNotes(const BoundaryLayerRecord& layer, int dim);

}  // namespace homesh

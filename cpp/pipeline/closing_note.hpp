// The closing note of a mesh with elements not proven valid: how many, where on the CAD (and at
// which cusps of the CAD, cad/face_cusps.hpp, when they have a corner at one), and what was
// tried on them (the optimiser, the repair rounds and their actions), so that a one-line
// message names the stage that gave up and the entity.
#pragma once

#include <string>

#include "pipeline/mesh_pipeline.hpp"

namespace homesh {

// `linearGiven`: the caller gave the linear mesh (no repair rounds can remesh it).
std::string notValidNote(const MeshResult& result, bool linearGiven);

}  // namespace homesh

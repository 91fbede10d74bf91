// What to mesh and how, from the command line's INPUT: a CAD file, or a NekMesh case (.mcf)
// that names its CAD and carries the sizing parameters and the order.
#pragma once

#include <string>
#include <vector>

#include "pipeline/mesh_pipeline.hpp"

namespace homesh {

struct CaseSetup {
  CadSource source;
  MeshingOptions options;  // order and sizing from a .mcf; defaults otherwise
  bool fromMcf = false;
  std::vector<std::string> notices;  // .mcf keys that are unknown or not used yet
};

// A .mcf (by extension, case-insensitive) is read with readMcfFile: its CAD file is read in
// metres, as NekMesh does (OCCT's millimetres scaled by 0.001); CADFile "NNNN" builds the NACA
// domain; MinDelta, MaxDelta and EPS (all three, or none) set the octree sizing, REFINEMENT
// LINEs become segment sources, Order the order. Anything else is a CAD file, read as is.
// Throws IoError or ParameterError.
CaseSetup setupCase(const std::string& input);

}  // namespace homesh

// CGNS writer (SIDS-conforming HDF5 file through Debian's CGNS library).
//
// One base ("HOMesh", cell dimension mesh.dim, physical dimension 3, or 2 for a 2D mesh in the
// plane z = 0), one unstructured zone: the nodes as CoordinateX/Y/Z (double; no Z in 2D space),
// then the cells block by block, elements first, each block's cells in sections of one CAD
// entity each ("Solid1_TETRA_35", "Face3_TRI_15"; the entities in the order they first appear in
// the block, each one's cells in block order), so that a reader rebuilds every cell's entity, and
// a block whose cells were so grouped reads back as it was; then one boundary condition per named
// group and one per other boundary entity ("Face7"), listing its cells (PointList at FaceCenter in
// 3D, EdgeCenter in 2D; type BCTypeUserDefined: HOMesh knows the surfaces, not the physics). Node
// order: io/cgns_elements.hpp. The file is written under a temporary name and renamed.
#pragma once

#include <string>
#include <vector>

#include "core/mesh.hpp"
#include "io/named_group.hpp"

namespace homesh {

// Throws ParameterError for what no CGNS file can hold, before any work: an order above 4 (CGNS
// names no such element) or a group name over 32 characters (the SIDS's limit on names).
void checkCgnsOutput(int order, const std::vector<NamedGroup>& groups);

// Throws ParameterError as checkCgnsOutput, or for a group named as a boundary entity not in it
// ("Face7": one zone's conditions need distinct names), before the file is opened; IoError when
// the library fails (naming the file and the library's message) or the mesh exceeds its 32-bit
// indices.
void writeCgns(const Mesh& mesh, const std::string& path, const std::vector<NamedGroup>& groups);

}  // namespace homesh

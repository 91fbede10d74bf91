// CGNS reader: the unstructured zones of a file's first base, as a Mesh (io/foreign_mesh.hpp's
// checks and normalisations), with its boundary conditions as named groups.
//
// - Zones: every unstructured zone of the first base; several are joined, a node of a later zone
//   that has exactly the coordinates of an earlier zone's node becoming that node (a note says
//   how many). Structured zones are refused by name.
// - Sections: the complete Lagrange types of orders 1 to 4 (io/cgns_elements.hpp), alone or in
//   MIXED sections; NODE sections are skipped; incomplete (serendipity) and polyhedral ones are
//   refused, naming the section and its type.
// - Entities: a section named as HOMesh's writer names them ("Face3_TRI_6") gives its cells that
//   entity; otherwise a boundary cell takes the number of the first boundary condition (1, 2, ...
//   in file order) that lists it (cells no condition lists take the next number), and a volume
//   cell entity 1.
// - Boundary conditions: point lists or ranges of cells (FaceCenter, EdgeCenter, ElementList,
//   ElementRange) or of nodes (Vertex: the boundary cells whose vertices are all listed). Each
//   becomes a NamedGroup of its cells' entities, except one holding exactly one entity and named
//   as that entity ("Face7"): the writers' default group, which needs no name.
#pragma once

#include <string>
#include <vector>

#include "core/mesh.hpp"
#include "io/named_group.hpp"

namespace homesh {

// Throws IoError naming the file and the problem (a zone, section, condition or cell).
Mesh readCgns(const std::string& path, std::vector<std::string>* notes,
              std::vector<NamedGroup>* groups);

}  // namespace homesh

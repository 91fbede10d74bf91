// A hybrid mesh as Gmsh makes it, for the tests that need pyramids: the unit box with
// quadrilaterals on its faces, pyramids on them and tetrahedra inside (Gmsh 4.8: 36 pyramids and
// 633 tetrahedra at size 0.5), written (MSH 4.1) at each order asked, from one linear mesh and in
// one Gmsh session, in a child process (gmsh_child.hpp says why).
#pragma once

#include <gmsh.h>

#include "gmsh_child.hpp"

#include <string>
#include <utility>
#include <vector>

namespace homesh::test {

inline void writeGmshHybridBox(const std::vector<std::pair<int, std::string>>& orders,
                               double size = 0.5) {
  inGmshChild([&] {
    gmsh::initialize(0, nullptr, false);
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::model::add("hybrid");
    gmsh::model::occ::addBox(0, 0, 0, 1, 1, 1);
    gmsh::model::occ::synchronize();
    gmsh::vectorpair corners;
    gmsh::model::getEntities(corners, 0);
    gmsh::model::mesh::setSize(corners, size);
    gmsh::option::setNumber("Mesh.RecombineAll", 1);
    gmsh::model::mesh::generate(3);
    for (const auto& [order, path] : orders) {
      gmsh::model::mesh::setOrder(order);
      gmsh::write(path);
    }
    gmsh::finalize();
  });
}

}  // namespace homesh::test

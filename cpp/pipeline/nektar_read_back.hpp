// The check every front end runs after writing a Nektar++ file. Nektar++ does not store the
// interiors of 3D elements: it rebuilds them from the faces (its modified basis without interior
// modes), so the geometry a solver uses from a .xml is not the mesh that was certified. This
// reads the written file back as Nektar++ builds it (io/nektar_reader.hpp) and certifies that
// geometry (quality/mesh_quality.hpp).
#pragma once

#include <cstddef>
#include <string>

namespace homesh {

struct NektarReadBack {
  std::string path;
  double worst = 0.0;  // certified scaled Jacobian, minimum
  std::size_t invalid = 0, undecided = 0;
  bool proven() const { return invalid + undecided == 0; }
  // "<path> as Nektar++ builds it (element interiors from the faces): scaled Jacobian min
  // <worst>; <n> invalid, <m> undecided": the one line the CLI prints and Python warns with.
  std::string line() const;
};

// Reads the Nektar++ file at `path` back and certifies it. Throws IoError as readMesh does.
NektarReadBack checkNektarReadBack(const std::string& path, int threads);

}  // namespace homesh

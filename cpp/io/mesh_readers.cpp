#include "io/mesh_readers.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "core/error.hpp"
#include "core/input_file.hpp"
#include "io/cgns_reader.hpp"
#include "io/msh_reader.hpp"
#include "io/nektar_reader.hpp"
#include "io/unv_reader.hpp"
#include "io/vtk_readers.hpp"

namespace homesh {

Mesh readMesh(const std::string& path, std::vector<std::string>* notes,
              std::vector<NamedGroup>* groups) {
  const std::string ext = lowerExtension(path);
  requireRegularFile(path, "mesh file");
  if (groups != nullptr) groups->clear();
  if (ext == ".cgns") return readCgns(path, notes, groups);
  if (ext == ".msh") return readMsh(path);
  if (ext == ".xml") return readNektarXml(path);
  if (ext == ".unv") return readUnv(path, notes);
  if (ext == ".vtk") return readLegacyVtk(path, notes);
  if (ext == ".vtu") return readVtu(path, notes);
  throw IoError("cannot read '" + path + "': unknown mesh format '" + ext +
                "' (use .msh, .xml, .unv, .vtk, .vtu or .cgns)");
}

}  // namespace homesh

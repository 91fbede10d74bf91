#include "io/mesh_writers.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <map>
#include <set>

#include "cad/cad_model.hpp"
#include "core/error.hpp"
#include "core/input_file.hpp"
#include "io/atomic_file.hpp"
#include "io/cgns_writer.hpp"
#include "io/msh_writer.hpp"
#include "io/nektar_writer.hpp"
#include "io/vtu_writer.hpp"

namespace homesh {

void checkCellFields(const Mesh& mesh, const std::vector<CellField>& fields) {
  std::size_t cells = 0;
  for (const ElementBlock& block : mesh.blocks) cells += block.count();
  for (const CellField& f : fields)
    if (f.values.size() != cells)
      throw Error("cell field '" + f.name + "' has " + std::to_string(f.values.size()) +
                  " values for " + std::to_string(cells) + " cells");
}

void checkMeshOutputPath(const std::string& path) {
  const std::string ext = lowerExtension(path);
  if (ext != ".msh" && ext != ".vtu" && ext != ".xml" && ext != ".cgns")
    throw IoError("cannot write '" + path + "': unknown mesh format '" + ext +
                  "' (use .msh, .vtu, .xml or .cgns)");
  checkParentFolder(path);
}

void checkGroups(const Mesh& mesh, const std::vector<NamedGroup>& groups) {
  std::set<int> present;
  for (const ElementBlock& b : mesh.blocks)
    if (cellDimension(b.type) == mesh.dim - 1) present.insert(b.entity.begin(), b.entity.end());
  std::map<int, std::string> owner;
  std::set<std::string> names;
  for (const NamedGroup& g : groups) {
    if (g.name.empty()) throw ParameterError("a boundary group has no name");
    if (g.name.find_first_of("\"<>&") != std::string::npos)
      throw ParameterError("boundary group '" + g.name +
                           "': a name must not contain a quote, '<', '>' or '&'");
    if (!names.insert(g.name).second)
      throw ParameterError("boundary group '" + g.name + "' is given twice");
    if (g.entities.empty()) throw ParameterError("boundary group '" + g.name + "' is empty");
    for (const int entity : g.entities) {
      const std::string what = cadEntityName(mesh.dim - 1, entity);
      if (present.count(entity) == 0)
        throw ParameterError("boundary group '" + g.name + "': the mesh has no boundary cell on " +
                             what);
      const auto [it, fresh] = owner.emplace(entity, g.name);
      if (!fresh)
        throw ParameterError(what + " is in two boundary groups, '" + it->second + "' and '" +
                             g.name + "'");
    }
  }
}

void writeMesh(const Mesh& mesh, const std::string& path, const std::vector<CellField>& fields,
               const WriteOptions& options) {
  checkMeshOutputPath(path);
  checkGroups(mesh, options.groups);
  const std::string ext = lowerExtension(path);
  if (ext == ".msh") return writeMsh41(mesh, path, fields, options.binary, options.groups);
  if (ext == ".vtu") return writeVtu(mesh, path, fields, options.binary);
  if (ext == ".cgns") return writeCgns(mesh, path, options.groups);
  return writeNektarXml(mesh, path, options.compressed, options.groups);
}

}  // namespace homesh

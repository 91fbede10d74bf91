#include "io/mesh_writers.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/msh_writer.hpp"
#include "io/nektar_writer.hpp"
#include "io/vtu_writer.hpp"

namespace homesh {
namespace {

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace

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
  if (ext != ".msh" && ext != ".vtu" && ext != ".xml")
    throw IoError("cannot write '" + path + "': unknown mesh format '" + ext +
                  "' (use .msh, .vtu or .xml)");
  checkParentFolder(path);
}

void writeMesh(const Mesh& mesh, const std::string& path, const std::vector<CellField>& fields,
               const WriteOptions& options) {
  checkMeshOutputPath(path);
  const std::string ext = lowerExtension(path);
  if (ext == ".msh") return writeMsh41(mesh, path, fields, options.binary);
  if (ext == ".vtu") return writeVtu(mesh, path, fields, options.binary);
  return writeNektarXml(mesh, path, options.compressed);
}

}  // namespace homesh

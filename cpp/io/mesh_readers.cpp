#include "io/mesh_readers.hpp"

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "core/error.hpp"
#include "core/input_file.hpp"
#include "io/msh_reader.hpp"
#include "io/nektar_reader.hpp"

namespace homesh {

Mesh readMesh(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  requireRegularFile(path, "mesh file");
  if (ext == ".msh") return readMsh(path);
  if (ext == ".xml") return readNektarXml(path);
  throw IoError("cannot read '" + path + "': unknown mesh format '" + ext + "' (use .msh or .xml)");
}

}  // namespace homesh

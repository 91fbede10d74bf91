#include "io/vtu_writer.hpp"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/base64.hpp"
#include "io/vtk_cells.hpp"

namespace homesh {

namespace {

// [UInt64 byte count][raw little-endian values]: VTK's layout of one binary data array.
template <class T>
std::string withHeader(const std::vector<T>& values) {
  const std::uint64_t bytes = values.size() * sizeof(T);
  std::string buffer(sizeof bytes + bytes, '\0');
  std::memcpy(buffer.data(), &bytes, sizeof bytes);
  if (bytes > 0) std::memcpy(buffer.data() + sizeof bytes, values.data(), bytes);
  return buffer;
}

// Writes DataArray elements, either with their data base64-encoded inline or as references
// into the raw <AppendedData> block written at the end.
class DataArrays {
 public:
  DataArrays(std::ostream& os, bool appended) : os_(os), appended_(appended) {}

  template <class T>
  void add(const char* type, const std::string& name, int components,
           const std::vector<T>& values) {
    os_ << "        <DataArray type=\"" << type << "\"";
    if (!name.empty()) os_ << " Name=\"" << name << "\"";
    if (components > 1) os_ << " NumberOfComponents=\"" << components << "\"";
    const std::string data = withHeader(values);
    if (appended_) {
      os_ << R"( format="appended" offset=")" << appendix_.size() << "\"/>\n";
      appendix_ += data;
    } else {
      os_ << " format=\"binary\">\n          " << base64Encode(data.data(), data.size())
          << "\n        </DataArray>\n";
    }
  }

  // After </UnstructuredGrid>: the appended data, if any.
  void finish() {
    if (!appended_) return;
    os_ << "  <AppendedData encoding=\"raw\">\n   _";
    os_.write(appendix_.data(), static_cast<std::streamsize>(appendix_.size()));
    os_ << "\n  </AppendedData>\n";
  }

 private:
  std::ostream& os_;
  bool appended_;
  std::string appendix_;
};

}  // namespace

void writeVtu(const Mesh& mesh, const std::string& path, const std::vector<CellField>& fields,
              bool appended) {
  mesh.checkConsistency();
  checkCellFields(mesh, fields);
  std::vector<std::int64_t> connectivity, offsets;
  std::vector<std::uint8_t> types;
  std::vector<std::int32_t> entity;
  for (const ElementBlock& block : mesh.blocks) {
    if (cellDimension(block.type) != mesh.dim) continue;
    // File version 1.0, which every reader (meshio included) accepts: hexahedra carry VTK's
    // version-1 numbering, which VTK 9 renumbers on reading.
    // VTK 9.1 (Debian 12's) has no Lagrange pyramid: a linear pyramid is a VTK_PYRAMID, in
    // Gmsh's order, and a curved one cannot be written.
    const bool pyramid = block.type == CellType::Pyramid;
    if (pyramid && block.order > 1)
      throw ParameterError("VTU output has no curved pyramid (these are of order " +
                           std::to_string(block.order) +
                           "): VTK 9.1 has no Lagrange pyramid; write .msh instead");
    const std::vector<int> perm = pyramid ? std::vector<int>{0, 1, 2, 3, 4}
                                          : vtkPermutationFromGmsh(block.type, block.order, true);
    const std::uint8_t cellType = pyramid ? 14 : vtkLagrangeType(block.type);
    for (std::size_t e = 0; e < block.count(); ++e) {
      const std::int64_t* nodes = block.element(e);
      for (const int k : perm) connectivity.push_back(nodes[k]);
      offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
      types.push_back(cellType);
      entity.push_back(block.entity[e]);
    }
  }
  std::vector<std::int32_t> cadDim(mesh.nodeCadDim.begin(), mesh.nodeCadDim.end());

  AtomicFile file(path, appended);
  std::ostream& os = file.stream();
  DataArrays arrays(os, appended);
  os << "<?xml version=\"1.0\"?>\n"
     << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
        "header_type=\"UInt64\">\n"
     << "  <UnstructuredGrid>\n"
     << "    <Piece NumberOfPoints=\"" << mesh.numNodes() << "\" NumberOfCells=\"" << types.size()
     << "\">\n";
  os << "      <PointData>\n";
  arrays.add("Int32", "cad_dim", 1, cadDim);
  arrays.add("Int32", "cad_index", 1, mesh.nodeCadIndex);
  os << "      </PointData>\n";
  os << "      <CellData" << (fields.empty() ? "" : " Scalars=\"" + fields[0].name + "\"") << ">\n";
  for (const CellField& f : fields)
    arrays.add("Float64", f.name, 1,
               std::vector<double>(f.values.begin(), f.values.begin() + types.size()));
  arrays.add("Int32", "cad_entity", 1, entity);
  os << "      </CellData>\n";
  os << "      <Points>\n";
  arrays.add("Float64", "", 3, mesh.xyz);
  os << "      </Points>\n";
  os << "      <Cells>\n";
  arrays.add("Int64", "connectivity", 1, connectivity);
  arrays.add("Int64", "offsets", 1, offsets);
  arrays.add("UInt8", "types", 1, types);
  os << "      </Cells>\n"
     << "    </Piece>\n"
     << "  </UnstructuredGrid>\n";
  arrays.finish();
  os << "</VTKFile>\n";
  file.commit();
}

}  // namespace homesh

#include "io/mesh_writers.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <set>

#include "cad/cad_model.hpp"
#include "core/error.hpp"
#include "element/node_ordering.hpp"
#include "io/atomic_file.hpp"
#include "io/gmsh_element_types.hpp"

namespace homesh {

namespace {

void checkFields(const Mesh& mesh, const std::vector<CellField>& fields) {
  std::size_t cells = 0;
  for (const ElementBlock& block : mesh.blocks) cells += block.count();
  for (const CellField& f : fields)
    if (f.values.size() != cells)
      throw Error("cell field '" + f.name + "' has " + std::to_string(f.values.size()) +
                  " values for " + std::to_string(cells) + " cells");
}

// Gmsh entity tags must be positive; meshes without CAD have index 0.
int entityTag(int cadIndex) {
  return std::max(1, cadIndex);
}

struct Box {
  double lo[3] = {std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
                  std::numeric_limits<double>::max()};
  double hi[3] = {std::numeric_limits<double>::lowest(), std::numeric_limits<double>::lowest(),
                  std::numeric_limits<double>::lowest()};
  void add(const double* p) {
    for (int c = 0; c < 3; ++c) {
      lo[c] = std::min(lo[c], p[c]);
      hi[c] = std::max(hi[c], p[c]);
    }
  }
};

using EntityKey = std::pair<int, int>;  // (dim, tag)

void writeMshEntities(std::ostream& os, const std::map<EntityKey, Box>& entities,
                      const std::set<EntityKey>& physical) {
  std::array<int, 4> counts{0, 0, 0, 0};
  for (const auto& [key, box] : entities) ++counts[key.first];
  os << "$Entities\n"
     << counts[0] << " " << counts[1] << " " << counts[2] << " " << counts[3] << "\n";
  for (const auto& [key, box] : entities) {
    const auto [dim, tag] = key;
    os << tag;
    const int nb = dim == 0 ? 1 : 2;
    for (int k = 0; k < nb; ++k) {
      const double* b = k == 0 ? box.lo : box.hi;
      os << " " << b[0] << " " << b[1] << " " << b[2];
    }
    if (physical.count(key) > 0)
      os << " 1 " << tag;
    else
      os << " 0";
    if (dim > 0) os << " 0";  // bounding entities are not listed
    os << "\n";
  }
  os << "$EndEntities\n";
}

}  // namespace

void writeMsh41(const Mesh& mesh, const std::string& path, const std::vector<CellField>& fields) {
  mesh.checkConsistency();
  checkFields(mesh, fields);
  const std::size_t n = mesh.numNodes();

  // Entities: from node classification and element entities.
  std::map<EntityKey, Box> entities;
  std::map<EntityKey, std::vector<std::size_t>> nodesOf;
  for (std::size_t i = 0; i < n; ++i) {
    const EntityKey key{mesh.nodeCadDim[i], entityTag(mesh.nodeCadIndex[i])};
    entities[key].add(&mesh.xyz[3 * i]);
    nodesOf[key].push_back(i);
  }
  std::set<EntityKey> physical;
  for (const ElementBlock& block : mesh.blocks) {
    const int dim = cellDimension(block.type);
    for (std::size_t e = 0; e < block.count(); ++e) {
      const EntityKey key{dim, entityTag(block.entity[e])};
      physical.insert(key);
      Box& box = entities[key];
      const std::int64_t* nodes = block.element(e);
      for (int k = 0; k < cellNumVertices(block.type); ++k) box.add(&mesh.xyz[3 * nodes[k]]);
    }
  }

  AtomicFile file(path, false);
  std::ostream& os = file.stream();
  os.precision(17);
  os << "$MeshFormat\n4.1 0 8\n$EndMeshFormat\n";
  os << "$PhysicalNames\n" << physical.size() << "\n";
  for (const auto& [dim, tag] : physical)
    os << dim << " " << tag << " \"" << cadEntityName(dim, tag) << "\"\n";
  os << "$EndPhysicalNames\n";
  writeMshEntities(os, entities, physical);

  os << "$Nodes\n" << nodesOf.size() << " " << n << " 1 " << n << "\n";
  for (const auto& [key, ids] : nodesOf) {
    os << key.first << " " << key.second << " 0 " << ids.size() << "\n";
    for (const std::size_t i : ids) os << i + 1 << "\n";
    for (const std::size_t i : ids)
      os << mesh.xyz[3 * i] << " " << mesh.xyz[3 * i + 1] << " " << mesh.xyz[3 * i + 2] << "\n";
  }
  os << "$EndNodes\n";

  // Element blocks per (entity, type); tags: cells of dimension mesh.dim first, in block order,
  // so that element tag k+1 carries field value k.
  struct Group {
    int dim, tag, type, nodesPerElement;
    std::vector<std::pair<std::size_t, const std::int64_t*>> elements;  // (tag, nodes)
  };
  std::map<std::array<int, 3>, Group> groups;
  std::size_t total = 0, nextTag = 1;
  std::vector<const ElementBlock*> ordered;
  for (const ElementBlock& b : mesh.blocks)
    if (cellDimension(b.type) == mesh.dim) ordered.push_back(&b);
  for (const ElementBlock& b : mesh.blocks)
    if (cellDimension(b.type) != mesh.dim) ordered.push_back(&b);
  for (const ElementBlock* block : ordered) {
    const int dim = cellDimension(block->type);
    const int type = gmshElementType(block->type, block->order);
    for (std::size_t e = 0; e < block->count(); ++e) {
      const int tag = entityTag(block->entity[e]);
      Group& g = groups[{dim, tag, type}];
      g.dim = dim;
      g.tag = tag;
      g.type = type;
      g.nodesPerElement = block->nodesPerElement();
      g.elements.emplace_back(nextTag++, block->element(e));
      ++total;
    }
  }
  os << "$Elements\n" << groups.size() << " " << total << " 1 " << total << "\n";
  for (const auto& [key, g] : groups) {
    os << g.dim << " " << g.tag << " " << g.type << " " << g.elements.size() << "\n";
    for (const auto& [tag, nodes] : g.elements) {
      os << tag;
      for (int k = 0; k < g.nodesPerElement; ++k) os << " " << nodes[k] + 1;
      os << "\n";
    }
  }
  os << "$EndElements\n";

  for (const CellField& f : fields) {
    os << "$ElementData\n1\n\"" << f.name << "\"\n1\n0\n3\n0\n1\n" << f.values.size() << "\n";
    for (std::size_t k = 0; k < f.values.size(); ++k) os << k + 1 << " " << f.values[k] << "\n";
    os << "$EndElementData\n";
  }
  file.commit();
}

namespace {

std::string base64(const std::uint8_t* data, std::size_t size) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((size + 2) / 3 * 4);
  for (std::size_t i = 0; i < size; i += 3) {
    const std::uint32_t b0 = data[i];
    const std::uint32_t b1 = i + 1 < size ? data[i + 1] : 0;
    const std::uint32_t b2 = i + 2 < size ? data[i + 2] : 0;
    const std::uint32_t triple = (b0 << 16) | (b1 << 8) | b2;
    out += table[(triple >> 18) & 63];
    out += table[(triple >> 12) & 63];
    out += i + 1 < size ? table[(triple >> 6) & 63] : '=';
    out += i + 2 < size ? table[triple & 63] : '=';
  }
  return out;
}

// Base64 of [UInt64 byte count][raw little-endian values], VTK's inline binary layout.
template <class T>
std::string vtkBinary(const std::vector<T>& values) {
  const std::uint64_t bytes = values.size() * sizeof(T);
  std::vector<std::uint8_t> buffer(sizeof bytes + bytes);
  std::memcpy(buffer.data(), &bytes, sizeof bytes);
  if (bytes) std::memcpy(buffer.data() + sizeof bytes, values.data(), bytes);
  return base64(buffer.data(), buffer.size());
}

template <class T>
void dataArray(std::ostream& os, const char* type, const std::string& name, int components,
               const std::vector<T>& values) {
  os << "        <DataArray type=\"" << type << "\"";
  if (!name.empty()) os << " Name=\"" << name << "\"";
  if (components > 1) os << " NumberOfComponents=\"" << components << "\"";
  os << " format=\"binary\">\n          " << vtkBinary(values) << "\n        </DataArray>\n";
}

std::uint8_t vtkLagrangeType(CellType type) {
  switch (type) {
    case CellType::Line:
      return 68;
    case CellType::Triangle:
      return 69;
    case CellType::Quadrilateral:
      return 70;
    case CellType::Tetrahedron:
      return 71;
    case CellType::Hexahedron:
      return 72;
    case CellType::Prism:
      return 73;
    case CellType::Pyramid:
      return 74;
    default:
      throw ParameterError("no VTK Lagrange cell for " + cellShortName(type));
  }
}

}  // namespace

void writeVtu(const Mesh& mesh, const std::string& path, const std::vector<CellField>& fields) {
  mesh.checkConsistency();
  checkFields(mesh, fields);
  std::vector<std::int64_t> connectivity, offsets;
  std::vector<std::uint8_t> types;
  std::vector<std::int32_t> entity;
  for (const ElementBlock& block : mesh.blocks) {
    if (cellDimension(block.type) != mesh.dim) continue;
    const std::vector<int> perm =
        nodePermutationFromGmsh(block.type, block.order, NodeConvention::Vtk);
    for (std::size_t e = 0; e < block.count(); ++e) {
      const std::int64_t* nodes = block.element(e);
      for (const int k : perm) connectivity.push_back(nodes[k]);
      offsets.push_back(static_cast<std::int64_t>(connectivity.size()));
      types.push_back(vtkLagrangeType(block.type));
      entity.push_back(block.entity[e]);
    }
  }
  std::vector<std::int32_t> cadDim(mesh.nodeCadDim.begin(), mesh.nodeCadDim.end());

  AtomicFile file(path, false);
  std::ostream& os = file.stream();
  os << "<?xml version=\"1.0\"?>\n"
     << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" "
        "header_type=\"UInt64\">\n"
     << "  <UnstructuredGrid>\n"
     << "    <Piece NumberOfPoints=\"" << mesh.numNodes() << "\" NumberOfCells=\"" << types.size()
     << "\">\n";
  os << "      <PointData>\n";
  dataArray(os, "Int32", "cad_dim", 1, cadDim);
  dataArray(os, "Int32", "cad_index", 1, mesh.nodeCadIndex);
  os << "      </PointData>\n";
  os << "      <CellData" << (fields.empty() ? "" : " Scalars=\"" + fields[0].name + "\"") << ">\n";
  for (const CellField& f : fields)
    dataArray(os, "Float64", f.name, 1,
              std::vector<double>(f.values.begin(), f.values.begin() + types.size()));
  dataArray(os, "Int32", "cad_entity", 1, entity);
  os << "      </CellData>\n";
  os << "      <Points>\n";
  dataArray(os, "Float64", "", 3, mesh.xyz);
  os << "      </Points>\n";
  os << "      <Cells>\n";
  dataArray(os, "Int64", "connectivity", 1, connectivity);
  dataArray(os, "Int64", "offsets", 1, offsets);
  dataArray(os, "UInt8", "types", 1, types);
  os << "      </Cells>\n"
     << "    </Piece>\n"
     << "  </UnstructuredGrid>\n"
     << "</VTKFile>\n";
  file.commit();
}

namespace {
std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}
}  // namespace

void checkMeshOutputPath(const std::string& path) {
  const std::string ext = lowerExtension(path);
  if (ext != ".msh" && ext != ".vtu")
    throw IoError("cannot write '" + path + "': unknown mesh format '" + ext +
                  "' (use .msh or .vtu)");
  checkParentFolder(path);
}

void writeMesh(const Mesh& mesh, const std::string& path, const std::vector<CellField>& fields) {
  checkMeshOutputPath(path);
  if (lowerExtension(path) == ".msh") return writeMsh41(mesh, path, fields);
  return writeVtu(mesh, path, fields);
}

}  // namespace homesh

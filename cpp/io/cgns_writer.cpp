#include "io/cgns_writer.hpp"

#include <cgnslib.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>
#include <set>
#include <utility>

#include "cad/cad_model.hpp"
#include "core/error.hpp"
#include "io/atomic_file.hpp"
#include "io/cgns_elements.hpp"

namespace homesh {
namespace {

// An open CGNS file, closed (and, unless committed, removed) on scope exit.
class CgnsOutput {
 public:
  explicit CgnsOutput(const std::string& path) : path_(path), temporary_(path + ".part") {
    std::remove(temporary_.c_str());
    if (cg_set_file_type(CG_FILE_HDF5) != CG_OK ||
        cg_open(temporary_.c_str(), CG_MODE_WRITE, &fn_) != CG_OK)
      throw IoError("cannot write '" + path + "': " + cg_get_error());
    open_ = true;
  }
  ~CgnsOutput() {
    if (open_) cg_close(fn_);
    if (!committed_) std::remove(temporary_.c_str());
  }
  CgnsOutput(const CgnsOutput&) = delete;
  CgnsOutput& operator=(const CgnsOutput&) = delete;

  int fn() const { return fn_; }
  void check(int status, const std::string& what) const {
    if (status != CG_OK)
      throw IoError("cannot write '" + path_ + "' (" + what + "): " + cg_get_error());
  }
  void commit() {
    open_ = false;
    check(cg_close(fn_), "closing");
    if (std::rename(temporary_.c_str(), path_.c_str()) != 0)
      throw IoError("cannot write '" + path_ + "': renaming " + temporary_ +
                    " failed: " + std::strerror(errno));
    committed_ = true;
  }

 private:
  std::string path_, temporary_;
  int fn_ = 0;
  bool open_ = false, committed_ = false;
};

cgsize_t index(std::size_t i, const std::string& path) {
  if (i > static_cast<std::size_t>(std::numeric_limits<cgsize_t>::max()))
    throw IoError("cannot write '" + path + "': " + std::to_string(i) +
                  " exceeds the 32-bit indices of Debian's CGNS library");
  return static_cast<cgsize_t>(i);
}

// A block's cells by entity: the entities in the order they first appear, each with its cells
// in block order.
std::vector<std::pair<int, std::vector<std::size_t>>> cellsByEntity(const ElementBlock& block) {
  std::vector<std::pair<int, std::vector<std::size_t>>> out;
  std::map<int, std::size_t> slot;
  for (std::size_t e = 0; e < block.count(); ++e) {
    const auto [it, fresh] = slot.emplace(block.entity[e], out.size());
    if (fresh) out.emplace_back(block.entity[e], std::vector<std::size_t>());
    out[it->second].second.push_back(e);
  }
  return out;
}

// The name of the section holding the cells of one entity.
std::string sectionName(int dim, int entity, int code) {
  return cadEntityName(dim, entity) + "_" + cgnsTypeName(code);
}

}  // namespace

void checkCgnsOutput(int order, const std::vector<NamedGroup>& groups) {
  checkCgnsOrder(order);
  for (const NamedGroup& g : groups)
    if (g.name.size() > 32)
      throw ParameterError("boundary group '" + g.name + "': CGNS names are at most 32 characters");
}

void writeCgns(const Mesh& mesh, const std::string& path, const std::vector<NamedGroup>& groups) {
  checkCgnsOutput(mesh.order, groups);
  for (const ElementBlock& block : mesh.blocks) cgnsElementType(block.type, block.order);
  // One zone's conditions need distinct names: a group may not take a name an ungrouped boundary
  // entity's own condition has.
  std::set<int> grouped;
  for (const NamedGroup& g : groups) grouped.insert(g.entities.begin(), g.entities.end());
  std::set<std::string> ungrouped;
  for (const ElementBlock& block : mesh.blocks)
    if (cellDimension(block.type) == mesh.dim - 1)
      for (const int entity : block.entity)
        if (grouped.count(entity) == 0) ungrouped.insert(cadEntityName(mesh.dim - 1, entity));
  for (const NamedGroup& g : groups)
    if (ungrouped.count(g.name) != 0)
      throw ParameterError("boundary group '" + g.name +
                           "' has the name of a boundary entity not in it; " +
                           "rename the group for CGNS");
  const std::unique_lock<std::mutex> library = holdCgnsLibrary();
  CgnsOutput out(path);
  const int fn = out.fn();
  int base = 0, zone = 0;
  // A 2D mesh in the plane z = 0 is written in 2D physical space (X, Y), as CGNS's checker asks
  // (a coordinate of range 0 is a warning); other 2D meshes, and surfaces, keep Z.
  bool planeZ0 = mesh.dim == 2;
  for (std::size_t i = 0; i < mesh.numNodes() && planeZ0; ++i)
    planeZ0 = mesh.xyz[3 * i + 2] == 0.0 && !std::signbit(mesh.xyz[3 * i + 2]);
  const int physical = planeZ0 ? 2 : 3;
  out.check(cg_base_write(fn, "HOMesh", mesh.dim, physical, &base), "base");
  // The model's units are the CAD's, which the mesh does not record.
  out.check(cg_goto(fn, base, "end"), "base");
  out.check(cg_dataclass_write(CGNS_ENUMV(NormalizedByUnknownDimensional)), "data class");
  cgsize_t size[3] = {index(mesh.numNodes(), path), index(mesh.numElements(), path), 0};
  out.check(cg_zone_write(fn, base, "Mesh", size, CGNS_ENUMV(Unstructured), &zone), "zone");
  const char* names[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
  std::vector<double> coordinate(mesh.numNodes());
  for (int k = 0; k < physical; ++k) {
    for (std::size_t i = 0; i < mesh.numNodes(); ++i) coordinate[i] = mesh.xyz[3 * i + k];
    int c = 0;
    out.check(
        cg_coord_write(fn, base, zone, CGNS_ENUMV(RealDouble), names[k], coordinate.data(), &c),
        names[k]);
    // A length, in the model's unknown unit: exponents of mass, length, time, temperature, angle.
    const float length[5] = {0.0F, 1.0F, 0.0F, 0.0F, 0.0F};
    out.check(cg_goto(fn, base, "Zone_t", zone, "GridCoordinates", 0, "DataArray_t", c, "end"),
              names[k]);
    out.check(cg_exponents_write(CGNS_ENUMV(RealSingle), length), names[k]);
  }

  // Sections: a block's cells of one entity each, the entities in the order they first appear
  // and each one's cells in block order, numbered from 1.
  std::map<int, std::vector<cgsize_t>> cellsOfEntity;  // boundary entity -> CGNS cell numbers
  std::size_t next = 1;  // the next cell's number (checked into cgsize_t where it is used)
  std::vector<cgsize_t> connectivity;
  for (const ElementBlock& block : mesh.blocks) {
    const int dim = cellDimension(block.type), code = cgnsElementType(block.type, block.order);
    const std::vector<int> perm = cgnsPermutationFromGmsh(block.type, block.order);
    for (const auto& [entity, cells] : cellsByEntity(block)) {
      connectivity.clear();
      for (std::size_t i = 0; i < cells.size(); ++i) {
        const std::int64_t* nodes = block.element(cells[i]);
        for (const int k : perm)
          connectivity.push_back(index(static_cast<std::size_t>(nodes[k]) + 1, path));
        if (dim == mesh.dim - 1) cellsOfEntity[entity].push_back(index(next + i, path));
      }
      index(connectivity.size(), path);  // the library sizes a section's array in 32 bits too
      const std::size_t end = next + cells.size() - 1;
      int section = 0;
      out.check(cg_section_write(fn, base, zone, sectionName(dim, entity, code).c_str(),
                                 static_cast<CGNS_ENUMT(ElementType_t)>(code), index(next, path),
                                 index(end, path), 0, connectivity.data(), &section),
                "section of " + cgnsTypeName(code));
      next = end + 1;
    }
  }

  // Boundary conditions: the named groups, then each other boundary entity.
  std::vector<std::pair<std::string, std::vector<cgsize_t>>> conditions;
  for (const NamedGroup& g : groups) {
    std::vector<cgsize_t> cells;
    for (const int entity : g.entities) {
      auto it = cellsOfEntity.find(entity);
      if (it == cellsOfEntity.end()) continue;
      cells.insert(cells.end(), it->second.begin(), it->second.end());
      cellsOfEntity.erase(it);
    }
    std::sort(cells.begin(), cells.end());
    conditions.emplace_back(g.name, std::move(cells));
  }
  for (auto& [entity, cells] : cellsOfEntity)
    conditions.emplace_back(cadEntityName(mesh.dim - 1, entity), std::move(cells));
  const auto location = mesh.dim == 3 ? CGNS_ENUMV(FaceCenter) : CGNS_ENUMV(EdgeCenter);
  for (const auto& [name, cells] : conditions) {
    if (cells.empty()) continue;
    int bc = 0;
    out.check(cg_boco_write(fn, base, zone, name.c_str(), CGNS_ENUMV(BCTypeUserDefined),
                            CGNS_ENUMV(PointList), index(cells.size(), path), cells.data(), &bc),
              "boundary condition '" + name + "'");
    out.check(cg_boco_gridlocation_write(fn, base, zone, bc, location),
              "location of boundary condition '" + name + "'");
  }
  out.commit();
}

}  // namespace homesh

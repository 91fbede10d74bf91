#include "io/cgns_reader.hpp"

#include <cgns_io.h>
#include <cgnslib.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <initializer_list>
#include <map>
#include <mutex>
#include <new>
#include <set>
#include <stdexcept>
#include <utility>

#include "cad/cad_model.hpp"
#include "core/error.hpp"
#include "core/isolated_call.hpp"
#include "core/mesh_bytes.hpp"
#include "io/cgns_elements.hpp"
#include "io/foreign_mesh.hpp"

namespace homesh {
namespace {

// An error message from its parts (joined here, not by + chains at each throw in a loop).
std::string joined(std::initializer_list<std::string> parts) {
  std::string message;
  for (const std::string& part : parts) message += part;
  return message;
}
IoError ioError(std::initializer_list<std::string> parts) {
  return IoError{joined(parts)};
}

constexpr const char* kTypesRead =
    ", which HOMesh does not read (it reads complete Lagrange elements of orders 1 to 4: BAR, "
    "TRI, QUAD, TETRA, PYRA, PENTA, HEXA)";
constexpr const char* kLocationsRead =
    ", which HOMesh does not read (it reads conditions on boundary cells or on nodes)";
constexpr const char* kSharedCells =
    "' lists cells an earlier condition lists: they stay in the earlier one";

class CgnsInput {
 public:
  explicit CgnsInput(const std::string& path) : path_(path) {
    if (cg_open(path.c_str(), CG_MODE_READ, &fn_) != CG_OK)
      throw ioError({"cannot read '", path, "' as CGNS: ", cg_get_error()});
  }
  ~CgnsInput() { cg_close(fn_); }
  CgnsInput(const CgnsInput&) = delete;
  CgnsInput& operator=(const CgnsInput&) = delete;

  int fn() const { return fn_; }
  void check(int status, const std::string& what) const {
    if (status != CG_OK) throw ioError({"'", path_, "': ", what, ": ", cg_get_error()});
  }

 private:
  std::string path_;
  int fn_ = 0;
};

// One cell as the file lists it, before entities are known.
struct FileCell {
  CellType type;
  int order;
  std::size_t firstNode;  // into FileCells::nodes, Gmsh order, 0-based mesh ids
  int entity;             // from the section's name; -1: not named so
};

struct FileCells {
  std::vector<FileCell> cells;
  std::vector<std::int64_t> nodes;
  std::map<cgsize_t, std::size_t> byNumber;  // the zone's cell number -> index in `cells`
};

// The entity a section's name gives ("Face3_TRI_6" -> 3 when dim is 2); -1 otherwise.
int entityOfSectionName(const std::string& name, int dim) {
  static const char* kinds[] = {"Vertex", "Edge", "Face", "Solid"};
  const std::string kind = kinds[dim];
  if (name.compare(0, kind.size(), kind) != 0) return -1;
  std::size_t i = kind.size(), digits = 0;
  while (i + digits < name.size() &&
         std::isdigit(static_cast<unsigned char>(name[i + digits])) != 0)
    ++digits;
  if (digits == 0 || digits > 9 || i + digits >= name.size() || name[i + digits] != '_') return -1;
  return std::stoi(name.substr(i, digits));
}

class ZoneReader {
 public:
  ZoneReader(const CgnsInput& in, std::string path, int base, int zone, std::string baseName,
             std::string zoneName)
      : in_(in),
        path_(std::move(path)),
        base_(base),
        zone_(zone),
        baseName_(std::move(baseName)),
        zoneName_(std::move(zoneName)) {}

  // Appends one section's cells; node ids are mapped through `nodeId` (file index - 1 -> mesh).
  void section(int s, const std::vector<std::int64_t>& nodeId, FileCells& out) {
    char name[33] = {0};
    CGNS_ENUMT(ElementType_t) type{};
    cgsize_t start = 0, end = 0;
    int boundary = 0, parents = 0;
    in_.check(
        cg_section_read(in_.fn(), base_, zone_, s, name, &type, &start, &end, &boundary, &parents),
        "section " + std::to_string(s));
    const std::string where = "section '" + std::string(name) + "'";
    if (end < start)
      throw ioError({"'", path_, "': ", where, "'s element range is empty (first ",
                     std::to_string(start), ", last ", std::to_string(end), ")"});
    const auto count = static_cast<std::size_t>(end - start) + 1;
    const bool mixed = type == CGNS_ENUMV(MIXED);
    // A section of one type is refused (NGON_n, HEXA_20 ...) or sized before its data is read.
    const std::size_t perCell = mixed ? 0 : reading(type, where).perm.size();
    cgsize_t size = 0;
    in_.check(cg_ElementDataSize(in_.fn(), base_, zone_, s, &size), where);
    // (Every cell holds at least a node; MIXED cells a type code and at most 125 nodes.)
    const auto stored = static_cast<std::size_t>(std::max<cgsize_t>(size, 0));
    if (mixed ? stored < 2 * count || stored > 126 * count : stored != perCell * count)
      throw ioError({"'", path_, "': ", where, " stores ", std::to_string(size),
                     " connectivity entries for ", std::to_string(count), " cells",
                     mixed ? "" : " of " + std::to_string(perCell) + " nodes"});
    std::vector<cgsize_t> data(stored);
    if (mixed) {
      // The library copies the file's offsets whatever their length: it must be count + 1.
      checkOffsets(name, count, where);
      std::vector<cgsize_t> offsets(count + 1);
      in_.check(
          cg_poly_elements_read(in_.fn(), base_, zone_, s, data.data(), offsets.data(), nullptr),
          where);
    } else {
      in_.check(cg_elements_read(in_.fn(), base_, zone_, s, data.data(), nullptr), where);
    }
    std::size_t at = 0;
    for (cgsize_t number = start; number <= end; ++number) {
      int code = type;
      if (mixed) {
        if (at >= data.size())
          throw ioError(
              {"'", path_, "': ", where, " ends before its cell ", std::to_string(number)});
        code = static_cast<int>(data[at++]);
      }
      const Reading& r = reading(code, where);
      if (at + r.perm.size() > data.size())
        throw ioError({"'", path_, "': ", where, " ends inside its cell ", std::to_string(number)});
      if (r.skip) {
        at += r.perm.size();
        continue;
      }
      FileCell cell{r.type, r.order, out.nodes.size(),
                    entityOfSectionName(name, cellDimension(r.type))};
      const std::size_t first = at;
      for (const int k : r.fromFile) {
        const cgsize_t id = data[first + static_cast<std::size_t>(k)];
        if (id < 1 || static_cast<std::size_t>(id) > nodeId.size())
          throw ioError({"'", path_, "': ", where, ": cell ", std::to_string(number),
                         " refers to node ", std::to_string(id), ", outside the zone's ",
                         std::to_string(nodeId.size()), " nodes"});
        out.nodes.push_back(nodeId[static_cast<std::size_t>(id - 1)]);
      }
      at += r.perm.size();
      out.byNumber[number] = out.cells.size();
      out.cells.push_back(cell);
    }
  }

 private:
  struct Reading {
    bool skip = false;
    CellType type = CellType::Point;
    int order = 0;
    std::vector<int> perm, fromFile;  // fromFile[k]: the file's position of Gmsh node k
  };

  // Throws unless the MIXED section `name` stores no ElementStartOffset array or one of
  // count + 1 (read through the library's node layer: its mid-level layer lists no arrays
  // under a section).
  void checkOffsets(const std::string& name, std::size_t count, const std::string& where) const {
    int cgio = 0;
    double root = 0.0, id = 0.0;
    in_.check(cg_get_cgio(in_.fn(), &cgio), where);
    in_.check(cg_root_id(in_.fn(), &root), where);
    const std::string node = "/" + baseName_ + "/" + zoneName_ + "/" + name + "/ElementStartOffset";
    if (cgio_get_node_id(cgio, root, node.c_str(), &id) != CG_OK) return;  // none stored
    int dims = 0;
    cgsize_t extent[CGIO_MAX_DIMENSIONS] = {0};
    if (cgio_get_dimensions(cgio, id, &dims, extent) != CG_OK || dims != 1 ||
        static_cast<std::size_t>(extent[0]) != count + 1)
      throw ioError({"'", path_, "': ", where, " has ", std::to_string(extent[0]),
                     " element offsets for ", std::to_string(count), " cells"});
  }

  const Reading& reading(int code, const std::string& where) {
    auto it = readings_.find(code);
    if (it != readings_.end()) return it->second;
    const CgnsTypeReading t = cgnsTypeReading(code);
    Reading r;
    if (!t.why.empty())
      throw ioError(
          {"'", path_, "': ", where, " holds ", cgnsTypeName(code), ", ", t.why, kTypesRead});
    if (t.type == CellType::Point) {  // NODE
      r.skip = true;
      r.perm.assign(1, 0);
    } else {
      r.type = t.type;
      r.order = t.order;
      r.perm = cgnsPermutationFromGmsh(t.type, t.order);
      r.fromFile.assign(r.perm.size(), 0);
      for (std::size_t i = 0; i < r.perm.size(); ++i)
        r.fromFile[static_cast<std::size_t>(r.perm[i])] = static_cast<int>(i);
    }
    return readings_.emplace(code, std::move(r)).first->second;
  }

  const CgnsInput& in_;
  std::string path_;
  int base_, zone_;
  std::string baseName_, zoneName_;
  std::map<int, Reading> readings_;
};

// A zone's boundary conditions: for each, its name and the indices (into cells) it lists.
std::vector<std::pair<std::string, std::vector<std::size_t>>> readConditions(
    const CgnsInput& in, const std::string& path, int base, int zone, int cellDim,
    const FileCells& cells, std::size_t firstCell, const std::vector<std::int64_t>& nodeId) {
  std::vector<std::pair<std::string, std::vector<std::size_t>>> result;
  int count = 0;
  in.check(cg_nbocos(in.fn(), base, zone, &count), "boundary conditions");
  for (int bc = 1; bc <= count; ++bc) {
    char name[33] = {0};
    CGNS_ENUMT(BCType_t) bcType{};
    CGNS_ENUMT(PointSetType_t) setType{};
    cgsize_t points = 0, normalSize = 0;
    int normalIndex[3] = {0, 0, 0}, datasets = 0;
    CGNS_ENUMT(DataType_t) normalType{};
    in.check(cg_boco_info(in.fn(), base, zone, bc, name, &bcType, &setType, &points, normalIndex,
                          &normalSize, &normalType, &datasets),
             "boundary condition " + std::to_string(bc));
    const std::string where = "boundary condition '" + std::string(name) + "'";
    CGNS_ENUMT(GridLocation_t) location{};
    in.check(cg_boco_gridlocation_read(in.fn(), base, zone, bc, &location), where);
    std::vector<cgsize_t> list(static_cast<std::size_t>(points));
    in.check(cg_boco_read(in.fn(), base, zone, bc, list.data(), nullptr), where);
    const bool range = setType == CGNS_ENUMV(PointRange) || setType == CGNS_ENUMV(ElementRange);
    if (!range && setType != CGNS_ENUMV(PointList) && setType != CGNS_ENUMV(ElementList))
      throw ioError({"'", path, "': ", where, " is given as ", cg_PointSetTypeName(setType),
                     ", which HOMesh does not read (it reads point and element lists and ranges)"});
    if (range && list.size() != 2)
      throw ioError({"'", path, "': ", where, " is a range of ", std::to_string(list.size()),
                     " values, not 2"});
    const bool ofCells = setType == CGNS_ENUMV(ElementList) ||
                         setType == CGNS_ENUMV(ElementRange) ||
                         location == CGNS_ENUMV(FaceCenter) || location == CGNS_ENUMV(EdgeCenter);
    std::vector<cgsize_t> items;
    if (range) {
      // Bounded before it is expanded: a range from a hostile file could be 2^31 long.
      const cgsize_t lo =
          ofCells ? (cells.byNumber.empty() ? 1 : cells.byNumber.begin()->first) : 1;
      const cgsize_t hi = ofCells ? (cells.byNumber.empty() ? 0 : cells.byNumber.rbegin()->first)
                                  : static_cast<cgsize_t>(nodeId.size());
      if (list[0] > list[1] || list[0] < lo || list[1] > hi)
        throw ioError({"'", path, "': ", where, " is the range ", std::to_string(list[0]), " to ",
                       std::to_string(list[1]), ", not within the zone's ",
                       ofCells ? "cells " : "nodes ", std::to_string(lo), " to ",
                       std::to_string(hi)});
      for (cgsize_t i = list[0]; i <= list[1]; ++i) items.push_back(i);
    } else {
      items = list;
    }
    std::vector<std::size_t> members;
    if (ofCells) {
      for (const cgsize_t number : items) {
        auto it = cells.byNumber.find(number);
        if (it == cells.byNumber.end())
          throw ioError({"'", path, "': ", where, " lists cell ", std::to_string(number),
                         ", which the zone's sections do not hold"});
        const FileCell& c = cells.cells[it->second];
        if (cellDimension(c.type) != cellDim - 1)
          throw ioError({"'", path, "': ", where, " lists cell ", std::to_string(number), ", a ",
                         cellShortName(c.type), ", not a boundary cell of dimension ",
                         std::to_string(cellDim - 1)});
        members.push_back(it->second);
      }
    } else if (location == CGNS_ENUMV(Vertex)) {
      std::set<std::int64_t> listed;
      for (const cgsize_t id : items) {
        if (id < 1 || static_cast<std::size_t>(id) > nodeId.size())
          throw ioError({"'", path, "': ", where, " lists node ", std::to_string(id),
                         ", outside the zone's ", std::to_string(nodeId.size()), " nodes"});
        listed.insert(nodeId[static_cast<std::size_t>(id - 1)]);
      }
      for (std::size_t i = firstCell; i < cells.cells.size(); ++i) {
        const FileCell& c = cells.cells[i];
        if (cellDimension(c.type) != cellDim - 1) continue;
        bool all = true;
        for (int k = 0; k < cellNumVertices(c.type) && all; ++k)
          all = listed.count(cells.nodes[c.firstNode + static_cast<std::size_t>(k)]) > 0;
        if (all) members.push_back(i);
      }
    } else {
      throw ioError({"'", path, "': ", where, " is located at ", cg_GridLocationName(location),
                     kLocationsRead});
    }
    result.emplace_back(name, std::move(members));
  }
  return result;
}

Mesh readCgnsFile(const std::string& path, std::vector<std::string>* notes,
                  std::vector<NamedGroup>* groups) {
  CgnsInput in(path);
  const int fn = in.fn();
  int bases = 0;
  in.check(cg_nbases(fn, &bases), "bases");
  if (bases < 1) throw ioError({"'", path, "' holds no CGNS base"});
  if (bases > 1 && notes != nullptr)
    notes->push_back("'" + path + "' holds " + std::to_string(bases) + " bases: the first is read");
  char baseName[33] = {0};
  int cellDim = 0, physDim = 0;
  in.check(cg_base_read(fn, 1, baseName, &cellDim, &physDim), "base 1");
  if (cellDim != 2 && cellDim != 3)
    throw ioError({"'", path, "': base '", baseName, "' has cell dimension ",
                   std::to_string(cellDim), "; HOMesh reads 2D and 3D meshes"});
  int zones = 0;
  in.check(cg_nzones(fn, 1, &zones), "zones");
  if (zones < 1) throw ioError({"'", path, "': base '", std::string(baseName), "' holds no zone"});

  ForeignMesh raw;
  FileCells cells;
  std::map<std::array<double, 3>, std::int64_t> earlierNodes;
  std::size_t merged = 0;
  std::vector<std::pair<std::string, std::vector<std::size_t>>> conditions;
  for (int z = 1; z <= zones; ++z) {
    char zoneName[33] = {0};
    CGNS_ENUMT(ZoneType_t) zoneType{};
    in.check(cg_zone_type(fn, 1, z, &zoneType), "zone " + std::to_string(z));
    cgsize_t size[9] = {0};
    in.check(cg_zone_read(fn, 1, z, zoneName, size), "zone " + std::to_string(z));
    const std::string where = "zone '" + std::string(zoneName) + "'";
    if (zoneType != CGNS_ENUMV(Unstructured))
      throw ioError({"'", path, "': ", where, " is structured; HOMesh reads unstructured zones"});
    if (size[0] < 1)
      throw ioError({"'", path, "': ", where, " has ", std::to_string(size[0]), " nodes"});
    const auto n = static_cast<std::size_t>(size[0]);
    std::array<std::vector<double>, 3> xyz;
    const char* coordinateNames[3] = {"CoordinateX", "CoordinateY", "CoordinateZ"};
    for (int k = 0; k < 3; ++k) {
      xyz[k].assign(n, 0.0);
      if (k == 2 && physDim < 3) continue;
      cgsize_t lo = 1, hi = size[0];
      in.check(cg_coord_read(fn, 1, z, coordinateNames[k], CGNS_ENUMV(RealDouble), &lo, &hi,
                             xyz[k].data()),
               where + " " + coordinateNames[k]);
    }
    std::vector<std::int64_t> nodeId(n);
    std::vector<std::pair<std::array<double, 3>, std::int64_t>> added;
    for (std::size_t i = 0; i < n; ++i) {
      const std::array<double, 3> p{xyz[0][i], xyz[1][i], xyz[2][i]};
      for (const double v : p)
        if (!std::isfinite(v))
          throw ioError({"'", path, "': ", where, ": node ", std::to_string(i + 1),
                         " has a coordinate that is not a finite number"});
      auto it = earlierNodes.find(p);
      if (it != earlierNodes.end()) {
        nodeId[i] = it->second;
        ++merged;
        continue;
      }
      nodeId[i] = static_cast<std::int64_t>(raw.xyz.size() / 3);
      raw.xyz.insert(raw.xyz.end(), p.begin(), p.end());
      if (zones > 1) added.emplace_back(p, nodeId[i]);
    }
    if (z < zones) earlierNodes.insert(added.begin(), added.end());
    int sections = 0;
    in.check(cg_nsections(fn, 1, z, &sections), where + " sections");
    ZoneReader reader(in, path, 1, z, baseName, zoneName);
    const std::size_t firstCell = cells.cells.size();
    cells.byNumber.clear();
    for (int s = 1; s <= sections; ++s) reader.section(s, nodeId, cells);
    auto zoneConditions = readConditions(in, path, 1, z, cellDim, cells, firstCell, nodeId);
    conditions.insert(conditions.end(), zoneConditions.begin(), zoneConditions.end());
  }
  if (merged > 0 && notes != nullptr)
    notes->push_back("'" + path + "': " + std::to_string(zones) + " zones joined at " +
                     std::to_string(merged) + " nodes of equal coordinates");

  // Entities: the section's name, else the first condition listing the cell.
  std::vector<int> conditionOf(cells.cells.size(), 0);
  for (std::size_t c = 0; c < conditions.size(); ++c)
    for (const std::size_t i : conditions[c].second)
      if (conditionOf[i] == 0) conditionOf[i] = static_cast<int>(c) + 1;
  const int unlisted = static_cast<int>(conditions.size()) + 1;
  for (std::size_t i = 0; i < cells.cells.size(); ++i) {
    const FileCell& c = cells.cells[i];
    int entity = c.entity;
    if (entity < 0)
      entity = cellDimension(c.type) == cellDim ? 1
               : conditionOf[i] != 0            ? conditionOf[i]
                                                : unlisted;
    raw.addCell(c.type, c.order, cells.nodes.data() + c.firstNode, entity);
  }
  if (groups != nullptr) {
    groups->clear();
    std::set<int> claimed;
    for (std::size_t c = 0; c < conditions.size(); ++c) {
      const auto& [name, members] = conditions[c];
      std::set<int> entities;
      bool shared = false;
      for (const std::size_t i : members) {
        const bool named = cells.cells[i].entity >= 0;
        const int entity = named ? cells.cells[i].entity : conditionOf[i];
        shared = shared || (!named && conditionOf[i] != static_cast<int>(c) + 1);
        if (claimed.count(entity) == 0) entities.insert(entity);
      }
      if (shared && notes != nullptr)
        notes->push_back(joined({"'", path, "': boundary condition '", name, kSharedCells}));
      claimed.insert(entities.begin(), entities.end());
      if (entities.empty()) continue;
      if (entities.size() == 1 && name == cadEntityName(cellDim - 1, *entities.begin())) continue;
      groups->push_back({name, std::vector<int>(entities.begin(), entities.end())});
    }
  }
  return assembleForeignMesh(std::move(raw), path, notes);
}

}  // namespace

Mesh readCgns(const std::string& path, std::vector<std::string>* notes,
              std::vector<NamedGroup>* groups) {
  // In a child process: HDF5 can crash on a damaged file (a freed pointer freed again), which
  // must not take FreeCAD down; the child's crash is an IoError here.
  std::string bytes;
  try {
    const std::unique_lock<std::mutex> library = holdCgnsLibrary();
    bytes = runIsolated("the CGNS library", IsolationLimits{}, [&path] {
      std::vector<std::string> childNotes;
      std::vector<NamedGroup> childGroups;
      std::string out;
      try {
        appendMeshBytes(out, readCgnsFile(path, &childNotes, &childGroups));
      } catch (const std::bad_alloc&) {  // sizes the file states that no memory can hold
        throw IoError("'" + path + "': its arrays are too large for this machine's memory");
      } catch (const std::length_error&) {
        throw IoError("'" + path + "': its arrays are too large for this machine's memory");
      }
      appendTextsBytes(out, childNotes);
      std::vector<std::string> names(childGroups.size());
      for (std::size_t g = 0; g < childGroups.size(); ++g) names[g] = childGroups[g].name;
      appendTextsBytes(out, names);
      for (const NamedGroup& g : childGroups)
        appendIntBytes(out, std::vector<std::int32_t>(g.entities.begin(), g.entities.end()));
      return out;
    });
  } catch (const ChildCrashed& e) {
    throw IoError("cannot read '" + path + "' as CGNS: " + e.what() +
                  " on it: is the file damaged?");
  } catch (const OutOfMemory&) {
    throw IoError("'" + path + "': its arrays are too large for this machine's memory");
  } catch (const IoError&) {
    throw;
  } catch (const ParameterError&) {
    throw;
  } catch (const Error& e) {  // anything else the child met reading the file
    throw IoError("cannot read '" + path + "' as CGNS: " + e.what());
  }
  std::size_t at = 0;
  Mesh mesh = readMeshBytes(bytes, at);
  for (std::string& note : readTextsBytes(bytes, at))
    if (notes != nullptr) notes->push_back(std::move(note));
  for (std::string& name : readTextsBytes(bytes, at)) {
    const std::vector<std::int32_t> entities = readIntBytes(bytes, at);
    if (groups != nullptr) groups->push_back({std::move(name), {entities.begin(), entities.end()}});
  }
  return mesh;
}

}  // namespace homesh

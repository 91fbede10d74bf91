#include "linear/linear_mesher.hpp"

#include <gmsh.h>

#include <BRepGProp.hxx>
#include <GProp_GProps.hxx>
#include <Standard_ErrorHandler.hxx>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iomanip>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cad/model_dimension.hpp"
#include "cad/occt_access.hpp"
#include "core/error.hpp"
#include "core/format.hpp"
#include "core/isolated_call.hpp"
#include "core/mesh_bytes.hpp"
#include "linear/gmsh_entity_map.hpp"
#include "linear/gmsh_progress_watch.hpp"
#include "linear/gmsh_session.hpp"

namespace homesh {
namespace {

constexpr double kMaxEstimatedElements = 5e7;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Gmsh element type codes of the linear cells we request.
constexpr int kGmshLine = 1, kGmshTriangle = 2, kGmshTetrahedron = 4, kGmshPoint = 15;

// The area a uniform size's triangles cover, for an upper estimate of their count: a square of
// the bounding box's half diagonal for a planar model; the faces' area for a surface mesh,
// whose faces can hold far more (a box's shell: 4x).
double triangleArea(const CadModel& cad) {
  if (!isSurfaceModel(cad)) return 0.5 * std::pow(cad.boundingDiagonal(), 2);
  return withOcctErrors("measuring the faces of " + cad.sourceName(), [&] {
    GProp_GProps props;
    BRepGProp::SurfaceProperties(occtShape(cad), props);
    return std::abs(props.Mass());
  });
}

void checkUniformSize(const CadModel& cad, double size, int dim) {
  if (!(size > 0.0) || !std::isfinite(size))
    throw ParameterError("mesh size must be a positive number, got " + formatNumber(size));
  // The bounding box bounds the domain; an absurd element count means a typo in the size.
  const double d = cad.boundingDiagonal();
  if (size >= d)
    throw ParameterError("mesh size " + formatNumber(size) + " is not smaller than " +
                         cad.sourceName() + " itself (bounding-box diagonal " + formatNumber(d) +
                         ")");
  // A cube's worth of regular tetrahedra, or the area's worth of regular triangles.
  const double area = dim == 2 ? triangleArea(cad) : 0.0;
  const double estimate =
      dim == 3 ? 8.5 * std::pow(d / std::sqrt(3.0) / size, 3) : 2.3 * area / (size * size);
  if (estimate > kMaxEstimatedElements) {
    std::ostringstream msg;
    msg << "mesh size " << size << " is too small for " << cad.sourceName() << " (";
    if (dim == 2 && isSurfaceModel(cad))  // (the estimate's own measure)
      msg << "faces' area " << area;
    else
      msg << "bounding-box diagonal " << d;
    msg << "): it could make about " << std::scientific << std::setprecision(1) << estimate
        << " elements";
    throw ParameterError(msg.str());
  }
}

struct NodeTable {
  std::vector<std::int64_t> byTag;  // gmsh tag -> mesh node id, -1 if none

  std::int64_t at(std::size_t tag) const {
    if (tag >= byTag.size() || byTag[tag] < 0)
      throw MeshingError("Gmsh element refers to unknown node " + std::to_string(tag));
    return byTag[tag];
  }
};

void readNodes(const GmshEntityMap& entities, Mesh& mesh, NodeTable& table) {
  struct EntityNodes {
    int dim, cadIndex;
    std::vector<std::size_t> tags;
    std::vector<double> coord, param;
  };
  std::vector<EntityNodes> all;
  std::size_t maxTag = 0;
  gmsh::vectorpair dimTags;
  gmsh::model::getEntities(dimTags);
  for (const auto& [dim, tag] : dimTags) {
    EntityNodes en{dim, entities.cadIndex(dim, tag), {}, {}, {}};
    gmsh::model::mesh::getNodes(en.tags, en.coord, en.param, dim, tag, false, true);
    for (const std::size_t t : en.tags) maxTag = std::max(maxTag, t);
    all.push_back(std::move(en));
  }
  table.byTag.assign(maxTag + 1, -1);
  for (const EntityNodes& en : all) {
    const int dim = en.dim;
    const bool hasParam = (dim == 1 || dim == 2) && en.param.size() == en.tags.size() * dim;
    for (std::size_t i = 0; i < en.tags.size(); ++i) {
      double u = kNaN, v = kNaN;
      if (hasParam) {
        u = en.param[i * dim];
        if (dim == 2) v = en.param[i * dim + 1];
      }
      if (table.byTag[en.tags[i]] >= 0)
        throw MeshingError("Gmsh returned node " + std::to_string(en.tags[i]) + " twice");
      table.byTag[en.tags[i]] = mesh.addNode(&en.coord[3 * i], dim, en.cadIndex, u, v);
    }
  }
}

// Appends the elements of Gmsh entity (dim, tag), which must all be of type `gmshType`.
void readElements(const GmshEntityMap& entities, const NodeTable& table, int dim, int tag,
                  int gmshType, ElementBlock& block) {
  std::vector<int> types;
  std::vector<std::vector<std::size_t>> elementTags, nodeTags;
  gmsh::model::mesh::getElements(types, elementTags, nodeTags, dim, tag);
  const int cadIndex = entities.cadIndex(dim, tag);
  const int nv = cellNumVertices(block.type);
  for (std::size_t k = 0; k < types.size(); ++k) {
    if (types[k] == kGmshPoint) continue;
    if (types[k] != gmshType)
      throw MeshingError("Gmsh made elements of type " + std::to_string(types[k]) + " on " +
                         cadEntityName(dim, cadIndex) + " where only " + cellShortName(block.type) +
                         "s were expected");
    for (const std::size_t nodeTag : nodeTags[k]) block.nodes.push_back(table.at(nodeTag));
    block.entity.insert(block.entity.end(), nodeTags[k].size() / nv, cadIndex);
  }
}

Eigen::Vector3d point(const Mesh& mesh, std::int64_t i) {
  return {mesh.xyz[3 * i], mesh.xyz[3 * i + 1], mesh.xyz[3 * i + 2]};
}

// Makes every tetrahedron positively oriented.
void orientTetrahedra(const Mesh& mesh, ElementBlock& tets) {
  for (std::size_t e = 0; e < tets.count(); ++e) {
    std::int64_t* t = tets.nodes.data() + 4 * e;
    const Eigen::Vector3d a = point(mesh, t[0]);
    if ((point(mesh, t[1]) - a).cross(point(mesh, t[2]) - a).dot(point(mesh, t[3]) - a) < 0.0)
      std::swap(t[1], t[2]);
  }
}

// Makes every tetrahedron positively oriented and every boundary triangle that bounds exactly one
// tetrahedron point out of it. Only the triangles' faces are looked up (sorted, searched by each
// tetrahedron's faces): a map of every tetrahedron's four faces took a second of a run of 67,000.
void orientVolumeMesh(Mesh& mesh, ElementBlock& tets, ElementBlock& tris) {
  using Face = std::array<std::int64_t, 3>;
  orientTetrahedra(mesh, tets);
  std::vector<std::pair<Face, std::size_t>> faces(tris.count());  // sorted face, triangle
  for (std::size_t e = 0; e < tris.count(); ++e) {
    const std::int64_t* t = tris.nodes.data() + 3 * e;
    Face f{t[0], t[1], t[2]};
    std::sort(f.begin(), f.end());
    faces[e] = {f, e};
  }
  std::sort(faces.begin(), faces.end());
  std::vector<std::int64_t> opposite(tris.count(), -1);  // the vertex across, per triangle
  std::vector<int> bounding(tris.count(), 0);            // how many tetrahedra it bounds
  const auto byFace = [](const std::pair<Face, std::size_t>& a, const Face& b) {
    return a.first < b;
  };
  for (std::size_t e = 0; e < tets.count(); ++e) {
    const std::int64_t* t = tets.nodes.data() + 4 * e;
    for (int skip = 0; skip < 4; ++skip) {
      Face f;
      int n = 0;
      for (int k = 0; k < 4; ++k)
        if (k != skip) f[n++] = t[k];
      std::sort(f.begin(), f.end());
      for (auto it = std::lower_bound(faces.begin(), faces.end(), f, byFace);
           it != faces.end() && it->first == f; ++it) {
        ++bounding[it->second];
        opposite[it->second] = t[skip];
      }
    }
  }
  for (std::size_t e = 0; e < tris.count(); ++e) {
    if (bounding[e] != 1) continue;
    std::int64_t* t = tris.nodes.data() + 3 * e;
    const Eigen::Vector3d a = point(mesh, t[0]);
    const Eigen::Vector3d n = (point(mesh, t[1]) - a).cross(point(mesh, t[2]) - a);
    if (n.dot(point(mesh, opposite[e]) - a) > 0.0) std::swap(t[1], t[2]);
  }
}

void orientPlanarMesh(Mesh& mesh, ElementBlock& tris) {
  const Eigen::Vector3d normal(mesh.planeNormal[0], mesh.planeNormal[1], mesh.planeNormal[2]);
  for (std::size_t e = 0; e < tris.count(); ++e) {
    std::int64_t* t = tris.nodes.data() + 3 * e;
    const Eigen::Vector3d a = point(mesh, t[0]);
    if ((point(mesh, t[1]) - a).cross(point(mesh, t[2]) - a).dot(normal) < 0.0)
      std::swap(t[1], t[2]);
  }
}

}  // namespace

namespace {

// Gmsh's Mesh.Algorithm for surfaces: its default (Frontal-Delaunay), and MeshAdapt, slower but
// the one Gmsh's documentation calls the most robust for complex curved surfaces.
constexpr int kDefaultSurfaceAlgorithm = 6, kMeshAdapt = 1;

// What one Gmsh run needs: the model's dimension and plane, and the sizes.
struct GmshRun {
  int dim = 3;
  Eigen::Vector3d normal{0.0, 0.0, 1.0};
  SizeField sizeAt;
  double minSize = 0.0, maxSize = 0.0;
  std::string sizes;  // "with the sizing field" or "with size 0.1", for messages
  int surfaceAlgorithm = kDefaultSurfaceAlgorithm;
  // Write which CAD sub-shape each Gmsh entity is on stdout, for a GmshProgressWatch.
  bool tellEntities = false;
};

// Meshes `cad` with Gmsh in this process (session held) and reads the mesh back.
Mesh meshWithGmsh(const CadModel& cad, const GmshRun& run) {
  Mesh mesh;
  mesh.dim = run.dim;
  mesh.order = 1;
  mesh.planeNormal = {run.normal.x(), run.normal.y(), run.normal.z()};
  const int dim = run.dim;
  withGmshErrors("meshing " + cad.sourceName(), [&] {
    gmsh::model::add("homesh");
    gmsh::vectorpair imported;
    gmsh::model::occ::importShapesNativePointer(&occtShape(cad), imported, false);
    gmsh::model::occ::synchronize();
    const GmshEntityMap entities = GmshEntityMap::build(cad);
    if (run.tellEntities) {
      gmsh::vectorpair all;
      gmsh::model::getEntities(all);
      for (const auto& [d, tag] : all)
        if (d > 0) std::printf("%s\n", gmshEntityLine(d, tag, entities.cadIndex(d, tag)).c_str());
      std::fflush(stdout);
    }

    gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
    gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
    gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 0);
    gmsh::option::setNumber("Mesh.MeshSizeMax", run.maxSize);
    gmsh::option::setNumber("Mesh.MeshSizeMin", run.minSize);
    gmsh::option::setNumber("Mesh.ElementOrder", 1);
    gmsh::option::setNumber("Mesh.Algorithm", run.surfaceAlgorithm);
    const SizeField& sizeAt = run.sizeAt;
    gmsh::model::mesh::setSizeCallback([&sizeAt](int, int, double x, double y, double z) {
      return sizeAt(Eigen::Vector3d(x, y, z));
    });
    try {
      // One call: generating dimension by dimension (1, 2, then 3) gives Gmsh 4.8 a different
      // mesh than generate(dim), and every figure recorded so far is of generate(dim)'s.
      gmsh::model::mesh::generate(dim);
    } catch (const std::string& message) {
      throw MeshingError("Gmsh could not mesh " + cad.sourceName() + " " + run.sizes + ": " +
                         message +
                         (message.find("No elements") != std::string::npos
                              ? " (the size may be too large for a thin part)"
                              : ""));
    }

    NodeTable table;
    readNodes(entities, mesh, table);

    ElementBlock cells, faces, lines;
    cells.type = dim == 3 ? CellType::Tetrahedron : CellType::Triangle;
    faces.type = CellType::Triangle;
    lines.type = CellType::Line;
    gmsh::vectorpair dimTags;
    gmsh::model::getEntities(dimTags);
    for (const auto& [d, tag] : dimTags) {
      if (d == 3) readElements(entities, table, d, tag, kGmshTetrahedron, cells);
      if (d == 2) readElements(entities, table, d, tag, kGmshTriangle, dim == 3 ? faces : cells);
      if (d == 1) readElements(entities, table, d, tag, kGmshLine, lines);
    }
    if (cells.count() == 0) {
      const std::string last = gmshLastError();
      throw MeshingError("Gmsh made no " + cellShortName(cells.type) + "s for " + cad.sourceName() +
                         (last.empty() ? "" : ": " + last));
    }
    if (dim == 3) {
      orientVolumeMesh(mesh, cells, faces);
      mesh.blocks = {std::move(cells), std::move(faces), std::move(lines)};
    } else {
      orientPlanarMesh(mesh, cells);
      mesh.blocks = {std::move(cells), std::move(lines)};
    }
    gmsh::model::mesh::removeSizeCallback();
  });
  return mesh;
}

// `stated`: the budget a message names when options.timeLimit is a retry's share of it.
IsolationLimits isolationLimits(const LinearMeshOptions& options, double stated = 0.0) {
  IsolationLimits limits;
  limits.seconds = options.timeLimit;
  limits.statedSeconds = stated;
  limits.budgetName = options.timeLimitName;
  limits.cancelled = options.cancelRequested;
  // Gmsh runs OpenCASCADE, whose every error handler takes one process-wide mutex. Another
  // thread of the caller (a second job, FreeCAD's own) may hold it at the fork, and the child's
  // copy is then never released: eight jobs on four Python threads hung a child until its 600 s
  // budget about once in 300 starts. The probe takes the mutex once before Gmsh starts, and a
  // child stuck on it is started again (a fresh copy of the mutex, free by then).
  limits.startProbe = [] { const Standard_ErrorHandler probe; };
  limits.restarted = [verbosity = options.verbosity](int child) {
    if (verbosity > 0)
      std::fprintf(stderr,
                   "homesh: note: Gmsh's process %d did not start (an OpenCASCADE lock held by "
                   "another thread when it was made); started again\n",
                   child);
  };
  return limits;
}

// `work` (which uses Gmsh, holding the session it is given) in a child process when
// options.isolate, else here; `work` returns its result as bytes either way. `stated`: as for
// isolationLimits. `watch`: the child's Gmsh writes to its terminal and `watch` reads it (a run
// that stalls: Stalled; one that crashes: ChildCrashed saying where).
std::string withGmsh(const LinearMeshOptions& options, const std::string& what,
                     const std::function<std::string(GmshSession&)>& work, double stated = 0.0,
                     const std::shared_ptr<GmshProgressWatch>& watch = nullptr) {
  if (!options.isolate) {
    GmshSession session(options.verbosity, 1);
    return work(session);
  }
  IsolationLimits limits = isolationLimits(options, stated);
  if (watch) limits.watch = [watch](const std::string& line) { return (*watch)(line); };
  // Held across the fork: no other thread of this process is inside Gmsh while the child
  // starts (its copy of a held lock would never be released), and the child's session uses it.
  std::unique_lock<std::mutex> held = holdGmsh();
  try {
    return runIsolated(what, limits, [&] {
      GmshSession session(std::move(held), options.verbosity, 1,
                          watch ? GmshOutput::Terminal : GmshOutput::Collected);
      return work(session);
    });
  } catch (const ChildCrashed& crash) {
    const std::string where = watch ? watch->lastActivity() : std::string();
    if (where.empty()) throw;
    throw ChildCrashed(std::string(crash.what()) + " (" + where + ")");
  }
}

}  // namespace

Mesh generateLinearMesh(const CadModel& cad, const LinearMeshOptions& options) {
  GmshRun run;
  run.dim = modelMeshDimension(cad, run.normal);
  // A uniform size is the constant field (no lower bound, as before fields existed).
  const bool field = static_cast<bool>(options.sizeField);
  if (field) {
    if (!(options.minSize > 0.0) || !(options.maxSize >= options.minSize))
      throw ParameterError("a size field needs bounds 0 < minSize <= maxSize");
  } else {
    checkUniformSize(cad, options.size, run.dim);
  }
  const double size = options.size;
  run.sizeAt = field ? options.sizeField : [size](const Eigen::Vector3d&) { return size; };
  run.minSize = field ? options.minSize : 0.0;
  run.maxSize = field ? options.maxSize : size;
  run.sizes = field ? "with the sizing field" : "with size " + formatNumber(size);

  // Gmsh meshes on one thread: its threaded meshing gave a
  // different mesh from run to run (box_hole.step at size 1: 256, 257 or 258 tetrahedra at 2
  // threads), and a mesh must be reproducible; the coarse meshes made here take a fraction of a
  // second (0.18 s for NekMesh's 3d_sphere case), the threads pay off in the later stages.
  // A retry gets what is left of the time budget, not a budget of its own.
  const auto start = std::chrono::steady_clock::now();
  const auto attempt = [&](const GmshRun& r) {
    LinearMeshOptions o = options;
    if (o.timeLimit > 0.0) {
      const double spent =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      o.timeLimit = std::max(o.timeLimit - spent, 1e-3);
    }
    GmshRun told = r;
    told.tellEntities = o.isolate;
    const auto watch =
        o.isolate ? std::make_shared<GmshProgressWatch>(o.verbosity, o.givenNames) : nullptr;
    const std::string bytes = withGmsh(
        o, "Gmsh's meshing of " + cad.sourceName(),
        [&](GmshSession&) {
          std::string out;
          appendMeshBytes(out, meshWithGmsh(cad, told));
          return out;
        },
        options.timeLimit, watch);
    std::size_t offset = 0;
    return readMeshBytes(bytes, offset);
  };
  // Gmsh 4.8's default surface algorithm crashes on some surfaces (a needle-thin cone aborted
  // it from inside a parallel region) and leaves others empty (a sphere of radius 1e6: "Surface
  // 1 consists of no elements"); MeshAdapt meshes both more often. A run stopped by its time
  // budget, cancelled or out of memory is not tried again.
  const auto retry = [&](const std::string& first) {
    GmshRun again = run;
    again.surfaceAlgorithm = kMeshAdapt;
    Mesh m = attempt(again);
    if (options.note) options.note(first + "; with its MeshAdapt surface algorithm Gmsh meshed it");
    return m;
  };
  Mesh mesh;
  try {
    mesh = attempt(run);
  } catch (const ChildCrashed& crash) {
    try {
      mesh = retry(crash.what());
    } catch (const ChildCrashed& second) {
      throw MeshingError(std::string(second.what()) + " " + run.sizes +
                         ", with its default surface algorithm and with MeshAdapt: the model may "
                         "have a degenerate face (a needle or sliver; healing or another size "
                         "may help)");
    }
  } catch (const MeshingError& failure) {
    if (endsTheJob(failure)) throw;
    try {
      mesh = retry(failure.what());
    } catch (const CancelledError&) {
      throw;
    } catch (const Error& second) {
      if (endsTheJob(second)) throw;
      if (dynamic_cast<const Stalled*>(&failure) != nullptr)
        throw MeshingError(std::string(failure.what()) + " (" + run.sizes +
                           "; Gmsh's MeshAdapt algorithm failed too): sizes below that face's "
                           "radius of curvature may help (--min-delta, --max-delta)");
      throw failure;  // the first algorithm's message says more
    }
  }
  if (options.dimensionDone) options.dimensionDone(run.dim, run.dim);
  mesh.checkConsistency();
  return mesh;
}

namespace {

// Meshes the current Gmsh model's entity of dimension `dim` inside its discrete boundary, which
// Gmsh keeps as it is; sizes grow from the boundary's edge lengths, at most `maxSize` (> 0).
void generateFill(int dim, double maxSize, const std::string& what, const std::string& hint) {
  gmsh::option::setNumber("Mesh.MeshSizeFromPoints", 0);
  gmsh::option::setNumber("Mesh.MeshSizeFromCurvature", 0);
  gmsh::option::setNumber("Mesh.MeshSizeExtendFromBoundary", 1);
  if (maxSize > 0.0) gmsh::option::setNumber("Mesh.MeshSizeMax", maxSize);
  gmsh::option::setNumber("Mesh.ElementOrder", 1);
  try {
    gmsh::model::mesh::generate(dim);
  } catch (const std::string& message) {
    throw MeshingError("Gmsh could not fill " + what + ": " + message + hint);
  }
}

// Reads a fill back: the nodes of the boundary entities (dimension dim - 1) are found again
// among `known` by their coordinates (Gmsh may renumber; it does not move them), the fill's own
// nodes are appended to `mesh` (CAD dimension dim, entity `entity`), and its cells, which must
// all be of `gmshType`, appended to `cells` with entity `entity`.
void readFill(Mesh& mesh, const std::map<std::array<double, 3>, std::int64_t>& known,
              const std::vector<int>& boundary, int dim, int tag, int gmshType, int entity,
              ElementBlock& cells, const std::string& what) {
  std::map<std::size_t, std::int64_t> fresh;
  std::vector<std::size_t> nodeTags;
  std::vector<double> coords, params;
  for (const int b : boundary) {
    gmsh::model::mesh::getNodes(nodeTags, coords, params, dim - 1, b, true, false);
    for (std::size_t i = 0; i < nodeTags.size(); ++i) {
      const auto it = known.find({coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]});
      if (it == known.end())
        throw MeshingError("Gmsh moved or added a node on the boundary of " + what);
      fresh[nodeTags[i]] = it->second;
    }
  }
  gmsh::model::mesh::getNodes(nodeTags, coords, params, dim, tag, false, false);
  for (std::size_t i = 0; i < nodeTags.size(); ++i)
    fresh[nodeTags[i]] = mesh.addNode(&coords[3 * i], dim, entity, kNaN, kNaN);
  std::vector<int> types;
  std::vector<std::vector<std::size_t>> elementTags, elementNodes;
  gmsh::model::mesh::getElements(types, elementTags, elementNodes, dim, tag);
  const auto nv = static_cast<std::size_t>(cellNumVertices(cells.type));
  for (std::size_t k = 0; k < types.size(); ++k) {
    if (types[k] != gmshType)
      throw MeshingError("Gmsh filled " + what + " with elements of type " +
                         std::to_string(types[k]) + " where only " + cellShortName(cells.type) +
                         "s were expected");
    for (const std::size_t t : elementNodes[k]) {
      const auto it = fresh.find(t);
      if (it == fresh.end())
        throw MeshingError("Gmsh's fill refers to unknown node " + std::to_string(t));
      cells.nodes.push_back(it->second);
    }
    cells.entity.insert(cells.entity.end(), elementNodes[k].size() / nv, entity);
  }
}

// A fill's result (the mesh with the fill's nodes appended, and its cells) as bytes, and back.
std::string meshAndBlockBytes(const Mesh& mesh, const ElementBlock& cells) {
  std::string out;
  appendMeshBytes(out, mesh);
  appendBlockBytes(out, cells);
  return out;
}

void readMeshAndBlock(const std::string& bytes, Mesh& mesh, ElementBlock& cells) {
  std::size_t offset = 0;
  mesh = readMeshBytes(bytes, offset);
  cells = readBlockBytes(bytes, offset);
}

// The triangles of `boundary` grouped into shells (connected through shared nodes), the one
// with the largest bounding box (the outer one, which encloses the others) first.
std::vector<std::vector<std::size_t>> connectedShells(
    const Mesh& mesh, const std::vector<std::array<std::int64_t, 3>>& boundary) {
  std::map<std::int64_t, std::int64_t> parent;
  const auto root = [&](std::int64_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (const auto& t : boundary)
    for (const std::int64_t v : t) parent.emplace(v, v);
  for (const auto& t : boundary) {
    parent[root(t[1])] = root(t[0]);
    parent[root(t[2])] = root(t[0]);
  }
  std::map<std::int64_t, std::size_t> shellOf;
  std::vector<std::vector<std::size_t>> shells;
  std::vector<Eigen::AlignedBox3d> boxes;
  for (std::size_t t = 0; t < boundary.size(); ++t) {
    const auto [it, fresh] = shellOf.emplace(root(boundary[t][0]), shells.size());
    if (fresh) {
      shells.emplace_back();
      boxes.emplace_back();
    }
    shells[it->second].push_back(t);
    for (const std::int64_t v : boundary[t])
      boxes[it->second].extend(Eigen::Vector3d(mesh.xyz[3 * static_cast<std::size_t>(v)],
                                               mesh.xyz[3 * static_cast<std::size_t>(v) + 1],
                                               mesh.xyz[3 * static_cast<std::size_t>(v) + 2]));
  }
  std::size_t outer = 0;
  for (std::size_t k = 1; k < shells.size(); ++k)
    if (boxes[k].diagonal().norm() > boxes[outer].diagonal().norm()) outer = k;
  std::swap(shells[0], shells[outer]);
  return shells;
}

}  // namespace

ElementBlock fillTetrahedra(Mesh& mesh, const std::vector<std::array<std::int64_t, 3>>& boundary,
                            const LinearMeshOptions& options, int solid, const FillRegion& region) {
  if (boundary.empty()) throw MeshingError("no surface to fill with tetrahedra");
  // One discrete surface per shell, the outer one first: a single surface loop over a body's
  // shell and the box's would have Gmsh fill the body too.
  const std::vector<std::vector<std::size_t>> shells = connectedShells(mesh, boundary);
  // Gmsh tags are the node ids + 1 (tags start at 1); its new nodes get larger tags.
  std::vector<char> used(mesh.numNodes(), 0);
  std::vector<std::vector<std::size_t>> tags(shells.size()), triangles(shells.size());
  std::vector<std::vector<double>> coords(shells.size());
  for (std::size_t k = 0; k < shells.size(); ++k)
    for (const std::size_t t : shells[k])
      for (const std::int64_t v : boundary[t]) {
        const auto i = static_cast<std::size_t>(v);
        triangles[k].push_back(i + 1);
        if (used.at(i) != 0) continue;
        used[i] = 1;
        tags[k].push_back(i + 1);
        coords[k].insert(coords[k].end(), mesh.xyz.begin() + static_cast<std::ptrdiff_t>(3 * i),
                         mesh.xyz.begin() + static_cast<std::ptrdiff_t>(3 * i + 3));
      }

  ElementBlock tets;
  tets.type = CellType::Tetrahedron;
  const double maxSize = options.sizeField ? options.maxSize : options.size;
  const std::string bytes =
      withGmsh(options, "Gmsh's filling of " + region.what, [&](GmshSession&) {
        withGmshErrors("filling " + region.what, [&] {
          gmsh::model::add("homesh-fill");
          std::vector<int> surfaces, loops;
          for (std::size_t k = 0; k < shells.size(); ++k) {
            const int tag = static_cast<int>(k) + 1;
            gmsh::model::addDiscreteEntity(2, tag);
            gmsh::model::mesh::addNodes(2, tag, tags[k], coords[k]);
            gmsh::model::mesh::addElementsByType(tag, kGmshTriangle, {}, triangles[k]);
            surfaces.push_back(tag);
            // A volume bounded by discrete surfaces without parametrisation: Gmsh meshes the
            // volume and leaves the surface mesh alone.
            loops.push_back(gmsh::model::geo::addSurfaceLoop({tag}));
          }
          const int volume = gmsh::model::geo::addVolume(loops);
          gmsh::model::geo::synchronize();
          generateFill(3, maxSize, region.what, region.hint);
          std::map<std::array<double, 3>, std::int64_t> known;
          for (std::size_t i = 0; i < used.size(); ++i)
            if (used[i] != 0)
              known.emplace(
                  std::array<double, 3>{mesh.xyz[3 * i], mesh.xyz[3 * i + 1], mesh.xyz[3 * i + 2]},
                  static_cast<std::int64_t>(i));
          readFill(mesh, known, surfaces, 3, volume, kGmshTetrahedron, solid, tets, region.what);
        });
        return meshAndBlockBytes(mesh, tets);
      });
  readMeshAndBlock(bytes, mesh, tets);
  if (tets.count() == 0) throw MeshingError("Gmsh made no tetrahedra in " + region.what);
  orientTetrahedra(mesh, tets);
  return tets;
}

ElementBlock fillTriangles(Mesh& mesh, const std::vector<std::array<std::int64_t, 2>>& boundary,
                           const LinearMeshOptions& options, int face) {
  // The segments as closed loops: every node on exactly two of them.
  std::map<std::int64_t, std::vector<std::size_t>> at;
  for (std::size_t s = 0; s < boundary.size(); ++s)
    for (const std::int64_t v : boundary[s]) at[v].push_back(s);
  for (const auto& [node, segments] : at)
    if (segments.size() != 2)
      throw MeshingError("the region inside the boundary layer is not closed: node " +
                         std::to_string(node) + " ends " + std::to_string(segments.size()) +
                         " boundary segments");
  std::vector<std::vector<std::int64_t>> loops;
  std::vector<char> used(boundary.size(), 0);
  for (std::size_t first = 0; first < boundary.size(); ++first) {
    if (used[first] != 0) continue;
    std::vector<std::int64_t> loop{boundary[first][0]};
    std::size_t s = first;
    std::int64_t next = boundary[first][1];
    used[first] = 1;
    while (next != loop.front()) {
      loop.push_back(next);
      const std::vector<std::size_t>& two = at[next];
      s = two[0] == s ? two[1] : two[0];
      used[s] = 1;
      next = boundary[s][0] == next ? boundary[s][1] : boundary[s][0];
    }
    loops.push_back(std::move(loop));
  }
  // The outer loop has the largest bounding box.
  std::size_t outer = 0;
  double largest = -1.0;
  for (std::size_t l = 0; l < loops.size(); ++l) {
    Eigen::Vector3d lo = point(mesh, loops[l][0]), hi = lo;
    for (const std::int64_t v : loops[l]) {
      lo = lo.cwiseMin(point(mesh, v));
      hi = hi.cwiseMax(point(mesh, v));
    }
    if ((hi - lo).norm() > largest) {
      largest = (hi - lo).norm();
      outer = l;
    }
  }

  ElementBlock tris;
  tris.type = CellType::Triangle;
  const double maxSize = options.sizeField ? options.maxSize : options.size;
  const std::string bytes =
      withGmsh(options, "Gmsh's filling of the boundary layer's inside", [&](GmshSession&) {
        withGmshErrors("filling the region inside the boundary layer", [&] {
          gmsh::model::add("homesh-fill-2d");
          std::map<std::array<double, 3>, std::int64_t> byPoint;
          std::vector<int> curveLoops;
          std::size_t tag = 1;
          for (std::size_t l = 0; l < loops.size(); ++l) {
            const int curve = static_cast<int>(l) + 1;
            gmsh::model::addDiscreteEntity(1, curve);
            std::vector<std::size_t> tags, lines;
            std::vector<double> coords;
            for (const std::int64_t v : loops[l]) {
              tags.push_back(tag++);
              const Eigen::Vector3d x = point(mesh, v);
              coords.insert(coords.end(), {x.x(), x.y(), x.z()});
              byPoint.emplace(std::array<double, 3>{x.x(), x.y(), x.z()}, v);
            }
            for (std::size_t k = 0; k < tags.size(); ++k)
              lines.insert(lines.end(), {tags[k], tags[(k + 1) % tags.size()]});
            gmsh::model::mesh::addNodes(1, curve, tags, coords);
            gmsh::model::mesh::addElementsByType(curve, kGmshLine, {}, lines);
            curveLoops.push_back(gmsh::model::geo::addCurveLoop({curve}));
          }
          std::vector<int> surfaceLoops{curveLoops[outer]};
          for (std::size_t l = 0; l < curveLoops.size(); ++l)
            if (l != outer) surfaceLoops.push_back(curveLoops[l]);
          const int surface = gmsh::model::geo::addPlaneSurface(surfaceLoops);
          gmsh::model::geo::synchronize();
          generateFill(2, maxSize, "the region inside the boundary layer",
                       " (the layer's top may cross itself or a wall)");
          std::vector<int> curves;
          for (std::size_t l = 0; l < loops.size(); ++l) curves.push_back(static_cast<int>(l) + 1);
          readFill(mesh, byPoint, curves, 2, surface, kGmshTriangle, face, tris,
                   "the region inside the boundary layer");
        });
        return meshAndBlockBytes(mesh, tris);
      });
  readMeshAndBlock(bytes, mesh, tris);
  if (tris.count() == 0) throw MeshingError("Gmsh made no triangles inside the boundary layer");
  orientPlanarMesh(mesh, tris);
  return tris;
}

}  // namespace homesh

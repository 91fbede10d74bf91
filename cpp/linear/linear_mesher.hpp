// Linear (order 1) mesh of a CAD model, made by Gmsh in-process.
//
// A model with solids gets tetrahedra, with triangles on its faces and lines on its edges as the
// boundary blocks; a model made only of planar faces in one plane gets triangles (dim 2), with
// lines on its edges. Every node records the CAD entity it lies on and its parameters there
// (see core/mesh.hpp), taken from Gmsh's parametric coordinates, so the high-order stages can
// place new nodes on the CAD. Volume elements have positive Jacobian (2D ones: positive with
// respect to Mesh::planeNormal).
#pragma once

#include <Eigen/Core>
#include <array>
#include <functional>
#include <string>
#include <vector>

#include "cad/cad_model.hpp"
#include "core/mesh.hpp"

namespace homesh {

// The target edge length at a point; called by Gmsh (one thread at a time, see below).
using SizeField = std::function<double(const Eigen::Vector3d&)>;

struct LinearMeshOptions {
  double size = 0.0;    // uniform target edge length (> 0), used when there is no sizeField
  int verbosity = 0;    // 0 silent, 1 Gmsh's warnings, 2 Gmsh's information
  SizeField sizeField;  // when set: sizes from it (Gmsh's curve meshing integrates 1/size)
  double minSize = 0.0, maxSize = 0.0;  // with sizeField: the bounds it keeps to (> 0)
  // Called once Gmsh has meshed every dimension up to the model's (dim == of); it may throw
  // (CancelledError).
  std::function<void(int dim, int of)> dimensionDone;
  // Gmsh runs in a child process (core/isolated_call.hpp), so that a crash inside Gmsh is a
  // MeshingError and a run can be stopped: after timeLimit seconds (0: none; MeshingError
  // naming timeLimitName) or when cancelRequested says so (asked every 50 ms; CancelledError).
  // When Gmsh crashes on a model's surfaces, generateLinearMesh tries once more with Gmsh's
  // MeshAdapt surface algorithm and tells `note` so. false: Gmsh runs in this process.
  bool isolate = true;
  double timeLimit = 0.0;
  std::string timeLimitName;
  std::function<bool()> cancelRequested;
  std::function<void(const std::string&)> note;
  // The names the user knows a sub-shape of the model meshed by (dimension 0..3, its 1-based
  // number), where healing or imprinting numbered the model afresh (NumberingMap::givenNames:
  // "Face7"); empty or "": the model's own numbers are the user's. A message naming a CAD
  // entity (a stalled or crashed Gmsh run) adds it.
  std::function<std::string(int dim, int index)> givenNames;

  static LinearMeshOptions uniform(double size) {
    LinearMeshOptions o;
    o.size = size;
    return o;
  }
};

// Gmsh meshes on one thread (see linear_mesher.cpp): the same CAD and options give the same
// mesh every time. Throws ParameterError (bad size), CadError (nothing meshable) or
// MeshingError.
Mesh generateLinearMesh(const CadModel& cad, const LinearMeshOptions& options);

// Triangles filling the planar region enclosed by `boundary`, closed loops of segments on
// existing nodes of `mesh` (one outer loop, the others holes), which Gmsh keeps as they are. New
// nodes are appended (CAD dimension 2, face `face`, no parameters); the triangles are oriented
// counter-clockwise around mesh.planeNormal. Sizes as for fillTetrahedra. Throws MeshingError
// when the segments do not form closed loops or Gmsh cannot fill them.
ElementBlock fillTriangles(Mesh& mesh, const std::vector<std::array<std::int64_t, 2>>& boundary,
                           const LinearMeshOptions& options, int face);

// What a fill is of, for its messages: "the volume inside the boundary layer", and a hint at the
// likely cause appended when Gmsh cannot fill it.
struct FillRegion {
  std::string what = "the volume inside the boundary layer";
  std::string hint = " (the layer's top may cross itself or a wall)";
};

// Tetrahedra filling the volume enclosed by `boundary`, a closed surface of triangles on
// existing nodes of `mesh` (one shell, or an outer shell and the shells of the holes inside it:
// a body in a box), which Gmsh keeps as it is (no node added or moved on it). New
// interior nodes are appended to `mesh` (CAD dimension 3, solid `solid`); the tetrahedra are
// positively oriented. Sizes grow from the boundary's edge lengths, at most options.maxSize (or
// options.size). Throws MeshingError when Gmsh cannot fill the surface (it is
// not closed, or intersects itself).
ElementBlock fillTetrahedra(Mesh& mesh, const std::vector<std::array<std::int64_t, 3>>& boundary,
                            const LinearMeshOptions& options, int solid,
                            const FillRegion& region = {});

}  // namespace homesh

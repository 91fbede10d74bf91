// Macro boundary layer (3D): one layer of prisms grown from chosen CAD faces, the rest of the
// solid refilled with tetrahedra (../shared/DESIGN.md section 3; NekMesh's method).
//
// From a linear tetrahedral mesh (generateLinearMesh) only the surface is kept. Every node of a
// layer face moves inwards along a smoothed normal (angle-weighted facet normals, relaxed with
// its neighbours) by the thickness there; a node that also lies on a face without a layer moves
// tangent to that face and is projected onto it (onto the common curve where two such faces
// meet), so the layer's side faces are quadrilaterals on the CAD. Heights shrink locally (and
// grade smoothly around) where a prism would fold, where a neighbouring face's triangle would
// fold when its node moves up, or where the normal, extended to 2.5 thicknesses, crosses another
// wall (thin gaps, the layer meeting itself). The layer's top and the other faces' triangles
// close a surface that Gmsh fills with tetrahedra (fillTetrahedra).
//
// The prisms are the macro elements the later stages curve and optimise; the split into thin
// layers (curving/layer_split.hpp) comes last. Every prism has its wall triangle as vertices
// 0, 1, 2 (Gmsh's prism order) and its top as 3, 4, 5.
//
// 2D: quadrilaterals (wall 0, 1; tops 3 above 0 and 2 above 1) from chosen curves of a planar
// face. Where two layer curves meet at a sharp convex corner, the corner node gets a fan: a
// column along each curve's own normal (each side's quadrilateral uses its own) and columns
// between them, with triangles (corner, top, top) between consecutive columns, appended to the
// triangle block; they are part of the layer (layerFanTriangles in curving/layer_split.hpp).
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "cad/cad_model.hpp"
#include "core/mesh.hpp"
#include "core/parameters.hpp"
#include "linear/linear_mesher.hpp"

namespace homesh {

struct BoundaryLayerParameters {
  std::vector<int> faces;  // 1-based CAD faces (FaceN) that carry the layer
  std::string thickness;   // total thickness: a number or an expression of x, y, z
  // Defaults as NekMesh's (core/parameters.hpp).
  int layers = static_cast<int>(parameterDefault("layers"));  // thin layers per macro prism
  double progression = parameterDefault("progression");       // consecutive layers' height ratio

  // Throws ParameterError naming the parameter (no faces, a thickness that does not parse,
  // layers or progression out of range).
  void validate() const;
  // The split coordinates across the layer: z_0 = 0 < z_1 < ... < z_n = 1, with
  // z_{k+1} - z_k = z_1 r^k (a geometric progression of ratio r, n layers).
  std::vector<double> splitCoordinates() const;
};

// "1,8", "11-12", "1, 3-5": a list of positive integers and ranges (NekMesh's
// BndLayerSurfaces), sorted, without repeats. Throws ParameterError naming `what`.
std::vector<int> parseIndexList(const std::string& text, const std::string& what);

// Where the layer was grown thinner than asked: per face, the smallest factor and where.
struct LayerShrink {
  int face = 0;
  std::array<double, 3> where{};  // the wall node with the smallest factor
  double factor = 1.0;            // grown height / asked thickness there
  std::size_t nodes = 0;          // wall nodes of the face whose height was reduced
};

// How far the optimiser let a macro layer's top move (BoundaryLayerRecord::release).
enum class LayerRelease { None, Parallel, Sides, Free };
// "none", "parallel", "parallel_and_sides", "free"
const char* layerReleaseName(LayerRelease release);

struct BoundaryLayerRecord {
  BoundaryLayerParameters parameters;
  double thicknessMin = 0, thicknessMax = 0;  // macro heights grown at the wall nodes
  // (The first split layer's height, as measured, is the split's: LayerSplitStats.)
  std::vector<LayerShrink> shrunk;
  std::size_t cells = 0;  // macro cells: prisms (3D), quadrilaterals (2D)
  // 2D: triangles of the fans at sharp convex corners of the wall (a column per wall curve's
  // normal there and between them, instead of one along the bisector): part of the layer, split
  // into thin triangles (curving/layer_split.hpp).
  std::size_t fanTriangles = 0;
  // 2D: wall segments halved before the growth, where the curve turns by more than 30 degrees
  // along one.
  std::size_t wallSplits = 0;
  std::size_t sideQuadrilaterals = 0, wallNodes = 0;
  int shrinkPasses = 0;
  // The optimiser keeps the macro layer as grown unless elements stay invalid; then it lets the
  // layer's top move around them, first parallel to the wall (the heights stay; its nodes on
  // the layer's side faces fixed, then sliding on them), then, if still needed, freely (the split
  // then sets its levels per column so that the first layer keeps its height where it can; the
  // outer layers absorb the change).
  LayerRelease release = LayerRelease::None;
  double seconds = 0.0;
};

// `volume`: a linear tetrahedral mesh of one solid with outward boundary triangles (as
// generateLinearMesh makes). Returns the linear mesh with the macro layer: blocks tetrahedra,
// prisms, boundary triangles, boundary quadrilaterals (the layer's sides on faces without a
// layer), lines. `fill` gives the largest tetrahedron size. Throws ParameterError (a face that
// does not exist, a thickness that is not positive somewhere, more than one solid) or
// MeshingError naming the face and the place where no layer can be grown.
Mesh growBoundaryLayer(const Mesh& volume, const CadModel& cad,
                       const BoundaryLayerParameters& parameters, const LinearMeshOptions& fill,
                       BoundaryLayerRecord& record);

}  // namespace homesh

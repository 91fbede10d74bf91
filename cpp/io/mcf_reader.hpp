// Reader of NekMesh's mesh configuration files (.mcf): the CAD file, the mesh type, the octree
// sizing parameters (MinDelta, MaxDelta, EPS), the order, the boundary-layer parameters, the NACA
// domain and the refinement lines.
//
// Layout (XML):
//   <NEKTAR><MESHING>
//     <INFORMATION> <I PROPERTY="CADFile" VALUE="part.stp"/> <I PROPERTY="MeshType" .../>
//     <PARAMETERS> <P PARAM="MinDelta" VALUE="0.01"/> ...          (optional)
//     <BOOLPARAMETERS> <P VALUE="SurfaceOptimiser"/> ...           (optional)
//     <REFINEMENT> <LINE> <X1>x y z</X1> <X2>x y z</X2> <R>r</R> <D>d</D> </LINE> ...  (optional)
//   </MESHING></NEKTAR>
// A LINE may also give its end points as NekMesh itself writes them, one coordinate per element:
// X1, Y1, Z1, X2, Y2, Z2. Keys match case-sensitively, as in NekMesh.
#pragma once

#include <Eigen/Core>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace homesh {

// A refinement region: the points within `radius` of the segment x1-x2 get size `delta`.
struct RefinementLine {
  Eigen::Vector3d x1 = Eigen::Vector3d::Zero(), x2 = Eigen::Vector3d::Zero();
  double radius = 0, delta = 0;
};

struct McfCase {
  std::string path;     // the .mcf as given
  std::string cadFile;  // CAD path resolved relative to the .mcf's folder; empty for a NACA case
  std::optional<std::string>
      nacaDigits;        // CADFile "NNNN" (exactly 4 digits): NACA 4-digit aerofoil
  std::string meshType;  // "3D", "2D", "3DBndLayer" or "2DBndLayer"
  std::optional<double> minDelta, maxDelta, eps;
  std::optional<int> order;
  // Boundary-layer parameters, kept as text for the boundary-layer stage: BndLayerSurfaces,
  // BndLayerThickness (may be an expression), BndLayerLayers, BndLayerProgression,
  // BndLayerAdjustment, SpaceOutBndLayer, NoSpaceOutSurf.
  std::map<std::string, std::string> boundaryLayer;
  std::optional<int> boundaryLayerLayers;             // BndLayerLayers, parsed (>= 1)
  std::optional<double> boundaryLayerProgression;     // BndLayerProgression, parsed (> 0)
  std::optional<double> xmin, ymin, xmax, ymax, aoa;  // NACA box and angle of attack (degrees)
  std::set<std::string> boolParameters;               // every name in BOOLPARAMETERS
  std::vector<RefinementLine> refinementLines;
  // One line per key or section that is unknown, or known to NekMesh but not used by HOMesh yet,
  // naming the file, the section and the key.
  std::vector<std::string> notices;

  bool isNaca() const { return nacaDigits.has_value(); }
  bool is2D() const { return meshType == "2D" || meshType == "2DBndLayer"; }
  bool hasBoundaryLayer() const { return meshType == "3DBndLayer" || meshType == "2DBndLayer"; }
};

// Throws IoError when the file is missing, unreadable or not well-formed XML, and ParameterError
// naming the file, the section and the key when its content is wrong (a required key missing, a
// number that does not parse or is out of range, an unknown MeshType).
McfCase readMcfFile(const std::string& path);

}  // namespace homesh

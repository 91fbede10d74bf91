// The sections of a Nektar++ XML geometry (plain or compressed, B64Z-LittleEndian) read into
// tables of entities by id, as the file states them: vertices' points, edges' vertices, faces'
// edges, elements' faces (3D) or edges (2D), the curves' points with their points type, and the
// composites' names and ids. Nothing is assembled or checked for fitting together here (that is
// the reader's, nektar_reader.hpp); each record is checked on its own: ids are integers in
// 0..INT_MAX, numbers finite, counts as the tag needs, compressed blocks decoded and sized.
#pragma once

#include <Eigen/Core>
#include <array>
#include <map>
#include <string>
#include <vector>

#include "core/cell_type.hpp"
#include "io/xml_document.hpp"

namespace homesh::nektar {

struct FaceRecord {
  bool triangle = true;
  std::vector<int> edges;
  std::vector<int> vertices;  // own order, from the edge loop (filled by the reader)
};

struct ElementRecord {
  CellType type;
  int id;
  std::vector<int> ids;  // faces (3D) or edges (2D)
};

struct CurveRecord {
  std::vector<Eigen::Vector3d> points;
  std::string type;  // Nektar++'s points type (PolyEvenlySpaced, GaussLobattoLegendre, ...)
};

struct CompositeRecord {
  std::string name;
  char letter;
  std::vector<int> ids;
};

struct GeometrySections {
  int dim = 3;
  std::map<int, Eigen::Vector3d> vertices;
  std::map<int, std::array<int, 2>> edges;
  std::map<int, FaceRecord> faces;
  std::vector<ElementRecord> elements;  // sorted by id
  std::map<int, CurveRecord> edgeCurves, faceCurves;
  std::vector<CompositeRecord> composites;
};

// Throws IoError "'path' is not a valid Nektar++ geometry: what".
[[noreturn]] void failGeometry(const std::string& path, const std::string& what);

// The sections under <NEKTAR><GEOMETRY> of the document `root` read from `path` (named in
// errors). Throws IoError (failGeometry) for a missing section, a malformed record or a file
// without elements.
GeometrySections readGeometrySections(const XmlElement& root, const std::string& path);

}  // namespace homesh::nektar

// OCCT handles of a CadModel, for the few components that pass the shape to OCCT-based tools
// (the Gmsh import). Everything else uses CadModel's OCCT-free interface.
#pragma once

#include <TopoDS_Edge.hxx>
#include <TopoDS_Face.hxx>
#include <TopoDS_Shape.hxx>
#include <TopoDS_Solid.hxx>
#include <TopoDS_Vertex.hxx>

#include "cad/cad_model.hpp"

namespace homesh {

const TopoDS_Shape& occtShape(const CadModel& cad);
// 1-based, FreeCAD numbering; throw CadError when out of range.
TopoDS_Vertex occtVertex(const CadModel& cad, int index);
TopoDS_Edge occtEdge(const CadModel& cad, int index);
TopoDS_Face occtFace(const CadModel& cad, int index);
TopoDS_Solid occtSolid(const CadModel& cad, int index);

// A model of `shape` (numbered afresh), named `source` in messages; throws CadError as the
// loaders do (no face).
CadModel cadModelFromShape(const TopoDS_Shape& shape, const std::string& source);

// Runs f() and converts OCCT's Standard_Failure into CadError("<what>: <OCCT message>").
template <class F>
auto withOcctErrors(const std::string& what, F&& f) -> decltype(f());

}  // namespace homesh

#include "cad/occt_errors.hpp"

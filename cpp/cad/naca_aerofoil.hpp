// A NACA 4-digit aerofoil in a rectangular domain, as NekMesh builds for a .mcf whose CADFile is
// "NNNN": one planar face (z = 0) in [xmin, xmax] x [ymin, ymax] with the aerofoil cut out.
//
// The aerofoil has chord 1 and its leading edge at the origin. Digits MPTT: maximum camber M/100
// at P/10 of the chord, thickness TT/100, with the closed-trailing-edge thickness formula
//   yt = 5 t (0.2969 sqrt(x) - 0.1260 x - 0.3516 x^2 + 0.2843 x^3 - 0.1036 x^4)
// applied normal to the mean camber line. It is rotated about the origin by -AOA, so that a
// positive angle of attack raises the leading edge above the trailing edge for a flow along +x.
//
// Numbering (FreeCAD's, TopExp::MapShapes order): Edge1..Edge4 the rectangle (bottom, right,
// top, left, counter-clockwise), Edge5 the upper surface (leading to trailing edge), Edge6 the
// lower surface (trailing to leading edge); Vertex1..4 the rectangle's corners from (xmin, ymin)
// counter-clockwise, Vertex5 the leading edge, Vertex6 the trailing edge. NekMesh's NACA case
// names curves 5-6 as the aerofoil, as here. Each surface is one cubic B-spline interpolating
// points clustered at both edges (cosine spacing); it lies within about 1e-7 chord of the formula
// (1e-9 for a symmetric aerofoil).
#pragma once

#include <string>

#include "cad/cad_model.hpp"

namespace homesh {

struct NacaDomain {
  std::string digits;  // exactly 4 digits, "0012"
  double xmin = -1.0, ymin = -1.0, xmax = 2.0, ymax = 1.0;
  double aoaDegrees = 0.0;
};

// Throws ParameterError naming the parameter (digits, Xmin, ..., AOA) when the digits are not a
// sensible NACA 4-digit code or the box does not contain the rotated aerofoil with a margin of
// 0.01 chord, and CadError when OCCT fails or the face is invalid.
CadModel makeNacaDomain(const NacaDomain& d);

}  // namespace homesh

// Apexes of the CAD faces: vertices where a face's normal jumps (a cone's tip; the tip of a
// surface of revolution whose profile meets the axis at an angle).
//
// Why it matters: the surface's parametrisation degenerates there, and the normal around the
// vertex takes every direction of a cone of directions however close one comes. A polynomial
// facet with a corner at the apex has one normal at that corner, so its normal is off the
// face's near the apex by up to half that cone's opening at any order: a fidelity term that
// asks for the face's normal there pulls the facet's nodes against the volume's quality for
// nothing it can win. A pole of a sphere degenerates the parametrisation too, but the normal
// around it converges: no apex.
#pragma once

#include "cad/cad_model.hpp"

namespace homesh {

// Whether `vertex` (1-based) is an apex of `face`: the face's parametrisation degenerates at
// the vertex (one derivative vanishes) and the face's normals around it, a thousandth of the
// other parameter's range away, spread over more than kApexSpreadDeg. False for a vertex that
// is not on the face or a point the CAD cannot evaluate.
bool isFaceApex(const CadModel& cad, int face, int vertex);

// Normals around a degenerate point spread by less than this on a smooth surface (a sphere's
// pole: by the thousandth step, 0.2 degrees) and by twice the complement of the half-angle at a
// cone's tip (90 degrees for a 45-degree cone).
inline constexpr double kApexSpreadDeg = 10.0;

}  // namespace homesh

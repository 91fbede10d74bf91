// Hybrid meshes as an industrial mesher makes them, made by Gmsh in the test, with the CAD they
// mesh (OpenCASCADE, as STEP): a wall inside a box with a boundary layer of prisms extruded from
// the wall's surface mesh along its normals (Gmsh's extrudeBoundaryLayer: `layers` layers, the
// first `firstHeight` high, each `ratio` times the one below) and tetrahedra between. The walls
// are built in Gmsh's own kernel, which extrudeBoundaryLayer needs, from exact circle arcs: their
// nodes lie on the STEP's surfaces to rounding. Each is made in a child process (gmsh_child.hpp
// says why).
//
// - writeGmshLayeredSphere: a sphere of radius 0.5 in the box [-1, 1]^3, quadrilaterals on the
//   box's faces and pyramids on them. At size 0.25 (Gmsh 4.8, MSH 4.1): 232 wall triangles, 1160
//   prisms, 483 pyramids, 9608 tetrahedra. A closed layer: no sides.
// - writeGmshLayeredCylinder: a cylinder of radius 0.5 along z through the box [-1, 1]^2 x [0, 1];
//   the layer's sides lie on the box's end planes, Gmsh's quadrilaterals there (up to 2.4e-3 off
//   the plane at size 0.25: Gmsh extrudes the end circle along its averaged normals, so a
//   classification tolerance of 2e-3 of the diagonal puts them on it).
#pragma once

#include <gmsh.h>

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdlib>
#include <set>
#include <string>
#include <vector>

#include "gmsh_child.hpp"

namespace homesh::test {

struct GmshLayer {
  int layers = 5;
  double firstHeight = 0.01, ratio = 1.3, size = 0.25;
  // How many of the wall's patches (the sphere's 8, the cylinder's 4, in the order they are
  // made) have their mesh recombined into quadrilaterals: the layer there is hexahedra, with
  // pyramids on its top; prisms elsewhere, the two sharing their columns where the patches meet.
  std::size_t quadPatches = 0;

  // Each layer's top, measured from the wall.
  std::vector<double> heights() const {
    std::vector<double> out;
    out.reserve(static_cast<std::size_t>(layers));
    double h = 0.0;
    for (int k = 0; k < layers; ++k) out.push_back(h += firstHeight * std::pow(ratio, k));
    return out;
  }
};

namespace gmsh_layered {

// The box [-a, a]^2 x [z0, z1] in Gmsh's kernel: its faces' curve loops, bottom and top first.
inline std::vector<std::vector<int>> boxLoops(double a, double z0, double z1, double size) {
  namespace g = gmsh::model::geo;
  int b[8];
  for (int k = 0; k < 8; ++k)
    b[k] = g::addPoint((k & 1) != 0 ? a : -a, (k & 2) != 0 ? a : -a, (k & 4) != 0 ? z1 : z0, size);
  const auto line = [&](int i, int j) { return g::addLine(b[i], b[j]); };
  const int x00 = line(0, 1), x10 = line(2, 3), x01 = line(4, 5), x11 = line(6, 7);
  const int y00 = line(0, 2), y10 = line(1, 3), y01 = line(4, 6), y11 = line(5, 7);
  const int z00 = line(0, 4), z10 = line(1, 5), z01 = line(2, 6), z11 = line(3, 7);
  return {{x00, y10, -x10, -y00}, {x01, y11, -x11, -y01}, {x00, z10, -x01, -z00},
          {x10, z11, -x11, -z01}, {y00, z01, -y01, -z00}, {y10, z11, -y11, -z10}};
}

// The circle of radius r around the z axis at height z: its centre, the four points on the x and
// y axes and the four arcs between them.
struct Circle {
  int centre = 0;
  std::array<int, 4> points{};
  gmsh::vectorpair arcs;
};

inline Circle circle(double r, double z, double size) {
  namespace g = gmsh::model::geo;
  Circle c;
  c.centre = g::addPoint(0, 0, z, size);
  c.points = {g::addPoint(r, 0, z, size), g::addPoint(0, r, z, size), g::addPoint(-r, 0, z, size),
              g::addPoint(0, -r, z, size)};
  for (int k = 0; k < 4; ++k)
    c.arcs.emplace_back(1, g::addCircleArc(c.points[k], c.centre, c.points[(k + 1) % 4]));
  return c;
}

// The CAD: the box less `tool` (an OpenCASCADE solid made by `makeTool`), written to `step`.
template <class MakeTool>
void writeBoxLess(const std::string& step, double a, double z0, double z1,
                  const MakeTool& makeTool) {
  gmsh::model::add("cad");
  const int solid = gmsh::model::occ::addBox(-a, -a, z0, 2 * a, 2 * a, z1 - z0);
  gmsh::vectorpair cut;
  std::vector<gmsh::vectorpair> map;
  gmsh::model::occ::cut({{3, solid}}, {{3, makeTool()}}, cut, map);
  gmsh::model::occ::synchronize();
  gmsh::write(step);
}

// A fresh Gmsh session, quiet, with an empty model.
inline void startSession() {
  gmsh::initialize(0, nullptr, false);
  gmsh::option::setNumber("General.Terminal", 0);
  gmsh::model::add("layered");
}

}  // namespace gmsh_layered

inline void writeGmshLayeredSphere(const std::string& mesh, const std::string& step,
                                   const GmshLayer& s = {}) {
  inGmshChild([&] {
    namespace g = gmsh::model::geo;
    const double r = 0.5, a = 1.0;
    gmsh_layered::startSession();
    const gmsh_layered::Circle equator = gmsh_layered::circle(r, 0.0, s.size);
    const int c = equator.centre;
    const int north = g::addPoint(0, 0, r, s.size), south = g::addPoint(0, 0, -r, s.size);
    int up[4], down[4];
    for (int k = 0; k < 4; ++k) up[k] = g::addCircleArc(equator.points[k], c, north);
    for (int k = 0; k < 4; ++k) down[k] = g::addCircleArc(equator.points[k], c, south);
    gmsh::vectorpair sphere;
    for (int k = 0; k < 4; ++k) {
      const int n = (k + 1) % 4, e = equator.arcs[static_cast<std::size_t>(k)].second;
      sphere.emplace_back(2, g::addSurfaceFilling({g::addCurveLoop({e, up[n], -up[k]})}, -1, c));
      sphere.emplace_back(2,
                          g::addSurfaceFilling({g::addCurveLoop({-e, down[k], -down[n]})}, -1, c));
    }
    std::vector<int> box;
    for (const std::vector<int>& loop : gmsh_layered::boxLoops(a, -a, a, s.size))
      box.push_back(g::addPlaneSurface({g::addCurveLoop(loop)}));
    std::vector<int> surfaces = box;
    gmsh::option::setNumber("Geometry.ExtrudeReturnLateralEntities", 0);
    gmsh::vectorpair extruded;
    g::extrudeBoundaryLayer(sphere, extruded, std::vector<int>(s.layers, 1), s.heights(), true);
    for (const auto& [dim, tag] : extruded)
      if (dim == 2) surfaces.push_back(tag);  // the layer's top
    g::addVolume({g::addSurfaceLoop(surfaces)});
    g::synchronize();
    for (const int f : box) gmsh::model::mesh::setRecombine(2, f);
    for (std::size_t k = 0; k < s.quadPatches && k < sphere.size(); ++k)
      gmsh::model::mesh::setRecombine(sphere[k].first, sphere[k].second);
    gmsh::model::mesh::generate(3);
    gmsh::write(mesh);
    gmsh_layered::writeBoxLess(step, a, -a, a,
                               [&] { return gmsh::model::occ::addSphere(0, 0, 0, r); });
    gmsh::finalize();
  });
}

inline void writeGmshLayeredCylinder(const std::string& mesh, const std::string& step,
                                     const GmshLayer& s = {}) {
  inGmshChild([&] {
    namespace g = gmsh::model::geo;
    const double r = 0.5, a = 1.0;
    gmsh_layered::startSession();
    const gmsh::vectorpair bottom = gmsh_layered::circle(r, 0.0, s.size).arcs;
    gmsh::vectorpair side, wall;
    g::extrude(bottom, 0, 0, 1, side);
    std::set<int> bottomArcs, topArcs;
    for (const auto& [dim, tag] : bottom) bottomArcs.insert(tag);
    for (const auto& [dim, tag] : side) {
      if (dim == 1) topArcs.insert(std::abs(tag));
      if (dim == 2) wall.emplace_back(dim, tag);
    }
    // Each wall patch extrudes to (its top, its volume, its 4 sides): the sides from the end
    // arcs belong to one patch, those from the lines between patches to two.
    gmsh::option::setNumber("Geometry.ExtrudeReturnLateralEntities", 1);
    gmsh::vectorpair extruded;
    g::extrudeBoundaryLayer(wall, extruded, std::vector<int>(s.layers, 1), s.heights(), true);
    g::synchronize();
    std::vector<int> tops;
    std::multiset<int> sides;
    for (std::size_t i = 0; i + 1 < extruded.size(); ++i)
      if (extruded[i + 1].first == 3) {
        tops.push_back(extruded[i].second);
        for (std::size_t k = i + 2; k < i + 6 && k < extruded.size(); ++k)
          sides.insert(extruded[k].second);
      }
    // The layer's outer edge on each end plane: of the end sides' curves, the one that is
    // neither the end arc nor shared with a neighbour (the radial lines).
    std::vector<gmsh::vectorpair> ends;
    std::multiset<int> uses;
    for (const int f : std::set<int>(sides.begin(), sides.end())) {
      if (sides.count(f) > 1) continue;
      ends.emplace_back();
      gmsh::model::getBoundary({{2, f}}, ends.back(), false, false, false);
      for (const auto& [dim, tag] : ends.back()) uses.insert(std::abs(tag));
    }
    std::vector<int> outer[2];
    for (const gmsh::vectorpair& curves : ends) {
      int end = 1, arc = 0;
      for (const auto& [dim, tag] : curves) {
        const int e = std::abs(tag);
        if (bottomArcs.count(e) != 0) end = 0;
        if (bottomArcs.count(e) == 0 && topArcs.count(e) == 0 && uses.count(e) == 1) arc = e;
      }
      outer[end].push_back(arc);
    }
    const std::vector<std::vector<int>> loops = gmsh_layered::boxLoops(a, 0.0, 1.0, s.size);
    std::vector<int> surfaces;
    for (std::size_t f = 0; f < loops.size(); ++f) {
      std::vector<int> faceLoops = {g::addCurveLoop(loops[f])};
      if (f < 2) faceLoops.push_back(g::addCurveLoop(outer[f], -1, true));  // the end planes
      surfaces.push_back(g::addPlaneSurface(faceLoops));
    }
    surfaces.insert(surfaces.end(), tops.begin(), tops.end());
    g::addVolume({g::addSurfaceLoop(surfaces)});
    g::synchronize();
    for (std::size_t k = 0; k < s.quadPatches && k < wall.size(); ++k)
      gmsh::model::mesh::setRecombine(wall[k].first, wall[k].second);
    gmsh::model::mesh::generate(3);
    gmsh::write(mesh);
    gmsh_layered::writeBoxLess(step, a, 0.0, 1.0,
                               [&] { return gmsh::model::occ::addCylinder(0, 0, 0, 0, 0, 1, r); });
    gmsh::finalize();
  });
}

}  // namespace homesh::test

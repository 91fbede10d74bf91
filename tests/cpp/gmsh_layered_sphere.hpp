// A hybrid mesh as an industrial mesher makes one, made by Gmsh in the test: a sphere of radius
// 0.5 in the box [-1, 1]^3 with a boundary layer of prisms extruded from the sphere's surface mesh
// along its normals (Gmsh's extrudeBoundaryLayer: `layers` layers, the first `firstHeight` high,
// each `ratio` times the one below), quadrilaterals on the box's faces, pyramids on them and
// tetrahedra between; and the CAD it is a mesh of (the box less the sphere, OpenCASCADE), as STEP.
// Gmsh 4.8 (MSH 4.1) at size 0.25: 232 wall triangles, 1160 prisms, 483 pyramids, 9608
// tetrahedra. Made in a child process (gmsh_child.hpp says why). The sphere is built in Gmsh's
// own kernel (eight patches of the exact sphere), which
// extrudeBoundaryLayer needs; its nodes lie on the STEP's sphere to rounding.
#pragma once

#include <gmsh.h>

#include "gmsh_child.hpp"

#include <cmath>
#include <cstddef>
#include <string>
#include <vector>

namespace homesh::test {

struct LayeredSphere {
  int layers = 5;
  double firstHeight = 0.01, ratio = 1.3, size = 0.25;
};

inline void writeGmshLayeredSphere(const std::string& mesh, const std::string& step,
                                   const LayeredSphere& s = {}) {
  inGmshChild([&] {
    const double r = 0.5, a = 1.0;
    gmsh::initialize(0, nullptr, false);
    gmsh::option::setNumber("General.Terminal", 0);
    gmsh::model::add("layered");
    namespace g = gmsh::model::geo;
    const int c = g::addPoint(0, 0, 0, s.size);
    const int p[6] = {g::addPoint(r, 0, 0, s.size),  g::addPoint(0, r, 0, s.size),
                      g::addPoint(-r, 0, 0, s.size), g::addPoint(0, -r, 0, s.size),
                      g::addPoint(0, 0, r, s.size),  g::addPoint(0, 0, -r, s.size)};
    int equator[4], up[4], down[4];
    for (int k = 0; k < 4; ++k) equator[k] = g::addCircleArc(p[k], c, p[(k + 1) % 4]);
    for (int k = 0; k < 4; ++k) up[k] = g::addCircleArc(p[k], c, p[4]);
    for (int k = 0; k < 4; ++k) down[k] = g::addCircleArc(p[k], c, p[5]);
    gmsh::vectorpair sphere;
    for (int k = 0; k < 4; ++k) {
      const int n = (k + 1) % 4;
      sphere.emplace_back(
          2, g::addSurfaceFilling({g::addCurveLoop({equator[k], up[n], -up[k]})}, -1, c));
      sphere.emplace_back(
          2, g::addSurfaceFilling({g::addCurveLoop({-equator[k], down[k], -down[n]})}, -1, c));
    }
    int b[8];
    for (int k = 0; k < 8; ++k)
      b[k] =
          g::addPoint((k & 1) != 0 ? a : -a, (k & 2) != 0 ? a : -a, (k & 4) != 0 ? a : -a, s.size);
    const auto line = [&](int i, int j) { return g::addLine(b[i], b[j]); };
    const int x00 = line(0, 1), x10 = line(2, 3), x01 = line(4, 5), x11 = line(6, 7);
    const int y00 = line(0, 2), y10 = line(1, 3), y01 = line(4, 6), y11 = line(5, 7);
    const int z00 = line(0, 4), z10 = line(1, 5), z01 = line(2, 6), z11 = line(3, 7);
    const std::vector<std::vector<int>> loops = {{x00, y10, -x10, -y00}, {x01, y11, -x11, -y01},
                                                 {x00, z10, -x01, -z00}, {x10, z11, -x11, -z01},
                                                 {y00, z01, -y01, -z00}, {y10, z11, -y11, -z10}};
    std::vector<int> surfaces;
    surfaces.reserve(loops.size() + sphere.size());
    for (const std::vector<int>& loop : loops)
      surfaces.push_back(g::addPlaneSurface({g::addCurveLoop(loop)}));
    const std::vector<int> box = surfaces;
    std::vector<double> heights;
    heights.reserve(static_cast<std::size_t>(s.layers));
    double h = 0.0;
    for (int k = 0; k < s.layers; ++k) heights.push_back(h += s.firstHeight * std::pow(s.ratio, k));
    gmsh::option::setNumber("Geometry.ExtrudeReturnLateralEntities", 0);
    gmsh::vectorpair extruded;
    g::extrudeBoundaryLayer(sphere, extruded, std::vector<int>(s.layers, 1), heights, true);
    for (const auto& [dim, tag] : extruded)
      if (dim == 2) surfaces.push_back(tag);  // the layer's top
    g::addVolume({g::addSurfaceLoop(surfaces)});
    g::synchronize();
    for (const int f : box) gmsh::model::mesh::setRecombine(2, f);
    gmsh::model::mesh::generate(3);
    gmsh::write(mesh);

    gmsh::model::add("cad");
    const int solid = gmsh::model::occ::addBox(-a, -a, -a, 2 * a, 2 * a, 2 * a);
    const int ball = gmsh::model::occ::addSphere(0, 0, 0, r);
    gmsh::vectorpair cut;
    std::vector<gmsh::vectorpair> map;
    gmsh::model::occ::cut({{3, solid}}, {{3, ball}}, cut, map);
    gmsh::model::occ::synchronize();
    gmsh::write(step);
    gmsh::finalize();
  });
}

}  // namespace homesh::test

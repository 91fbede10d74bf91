// Small meshes made here for the tests of the optimiser's parts (working_mesh.hpp,
// node_colouring.hpp, region_selection.hpp, cad_sliding.hpp, certified_quality.hpp,
// node_step.hpp, stop_rules.hpp), each made once per test executable.
#pragma once

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "curving/order_elevation.hpp"
#include "optimise/mesh_topology.hpp"
#include "pipeline/mesh_pipeline.hpp"
#include "test_support.hpp"

namespace homesh::test {

// A unit cube meshed by the pipeline (size 0.4), raised to order 3 without CAD, with every node
// inside the domain moved by a pseudo-random vector of up to 1 % of the mesh size in each
// coordinate: curved, valid elements with no node at its optimum (a straight-sided patch is the
// optimiser's ideal: its nodes would never move). No CAD records are used.
inline const Mesh& perturbedCube() {
  static const Mesh mesh = [] {
    MeshingOptions meshing;
    meshing.order = 1;
    meshing.size = 0.4;
    Mesh m = elevateOrder(
        runMeshPipeline(CadSource::brepText(brepText(box(1.0, 1.0, 1.0))), meshing).mesh, 3,
        nullptr);
    std::vector<const ElementBlock*> cells;
    for (const ElementBlock& b : m.blocks)
      if (cellDimension(b.type) == 3) cells.push_back(&b);
    const std::vector<char> boundary = boundaryNodes(m.numNodes(), cells);
    std::mt19937_64 rng(7);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    for (std::size_t i = 0; i < m.numNodes(); ++i)
      for (std::size_t c = 0; c < 3; ++c) {
        const double r = unit(rng);  // drawn for every node: the same stream whatever is fixed
        if (boundary[i] == 0) m.xyz[3 * i + c] += 0.004 * r;
      }
    return m;
  }();
  return mesh;
}

// The box with a cylindrical hole meshed by the pipeline at order 2, not optimised, with its
// model: nodes on the hole's circles slide in t, on the faces in (u, v).
inline const MeshResult& holeOnCad() {
  static const MeshResult result = [] {
    MeshingOptions meshing;
    meshing.order = 2;
    meshing.size = 1.0;
    return runMeshPipeline(CadSource::brepText(brepText(boxWithHole())), meshing);
  }();
  return result;
}

}  // namespace homesh::test

// CGNS: the node order against the SIDS's figures, bit-exact round trips of curved meshes of
// every shape (orders 1 to 4) with their entities and groups, and what the reader makes of files
// other tools write (several zones, MIXED sections, conditions on nodes) and refuses.
#include <cgnslib.h>
#include <gtest/gtest.h>
#include <BRepBuilderAPI_MakeFace.hxx>
#include <gp_Pln.hxx>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <random>
#include <set>

#include "core/error.hpp"
#include "curving/order_elevation.hpp"
#include "element/node_ordering.hpp"
#include "element/reference_element.hpp"
#include "io/cgns_reader.hpp"
#include "io/mesh_readers.hpp"
#include "io/mesh_writers.hpp"
#include "linear/linear_mesher.hpp"
#include "test_support.hpp"

namespace homesh {
namespace {

using Expected = std::map<int, LatticePoint>;  // CGNS node number (1-based) -> lattice point

// Nodes read off the SIDS's figures and tables (source/standard/SIDS/convention.rst; corners as
// in element/node_ordering.hpp: N1 at the origin, N2 on the first axis, ...).
void expectNodes(CellType type, int order, const Expected& expected) {
  const std::vector<LatticePoint> cgns = latticeOrder(type, order, NodeConvention::Cgns);
  for (const auto& [number, point] : expected)
    EXPECT_EQ(cgns.at(static_cast<std::size_t>(number - 1)), point)
        << cellShortName(type) << " order " << order << " node N" << number;
}

TEST(CgnsOrdering, MatchesTheSidsFigures) {
  // QUAD_25: the face ring from next to N1 towards N2, then the centre.
  expectNodes(CellType::Quadrilateral, 4,
              {{5, {1, 0, 0}},
               {8, {4, 1, 0}},
               {14, {0, 3, 0}},
               {16, {0, 1, 0}},
               {17, {1, 1, 0}},
               {18, {2, 1, 0}},
               {19, {3, 1, 0}},
               {20, {3, 2, 0}},
               {21, {3, 3, 0}},
               {22, {2, 3, 0}},
               {23, {1, 3, 0}},
               {24, {1, 2, 0}},
               {25, {2, 2, 0}}});
  // TETRA_35: faces (N1 N3 N2), (N1 N2 N4), (N2 N3 N4), (N3 N1 N4), each face's three nodes
  // next to its corners in the order the SIDS's notes give (N23 by N1, N24 by N2, ...); N35 the
  // centroid.
  expectNodes(CellType::Tetrahedron, 4,
              {{5, {1, 0, 0}},
               {11, {0, 3, 0}},
               {14, {0, 0, 1}},
               {17, {3, 0, 1}},
               {20, {0, 3, 1}},
               {23, {1, 1, 0}},
               {24, {2, 1, 0}},
               {25, {1, 2, 0}},
               {26, {1, 0, 1}},
               {27, {2, 0, 1}},
               {28, {1, 0, 2}},
               {29, {2, 1, 1}},
               {30, {1, 2, 1}},
               {31, {1, 1, 2}},
               {32, {0, 2, 1}},
               {33, {0, 1, 1}},
               {34, {0, 1, 2}},
               {35, {1, 1, 1}}});
  // PENTA_75: the base triangle's nodes, the three quadrilaterals' rings, the top's, then the
  // interior level by level.
  expectNodes(CellType::Prism, 4,
              {{13, {0, 3, 0}}, {16, {0, 0, 1}}, {31, {0, 3, 4}}, {34, {1, 1, 0}}, {35, {2, 1, 0}},
               {36, {1, 2, 0}}, {37, {1, 0, 1}}, {39, {3, 0, 1}}, {41, {3, 0, 3}}, {43, {1, 0, 3}},
               {45, {2, 0, 2}}, {46, {3, 1, 1}}, {55, {0, 3, 1}}, {57, {0, 1, 1}}, {59, {0, 1, 3}},
               {61, {0, 3, 3}}, {63, {0, 2, 2}}, {64, {1, 1, 4}}, {65, {2, 1, 4}}, {66, {1, 2, 4}},
               {67, {1, 1, 1}}, {68, {2, 1, 1}}, {69, {1, 2, 1}}, {75, {1, 2, 3}}});
  // PYRA_55 (apex N5 above N1 in HOMesh's lattice): base ring, triangles (N1 N2 N5),
  // (N2 N3 N5), (N3 N4 N5), (N4 N1 N5), then the level-1 ring and the level-2 node.
  expectNodes(
      CellType::Pyramid, 4,
      {{6, {1, 0, 0}},  {15, {0, 3, 0}}, {18, {0, 0, 1}}, {21, {3, 0, 1}}, {30, {1, 1, 0}},
       {31, {2, 1, 0}}, {32, {3, 1, 0}}, {34, {3, 3, 0}}, {36, {1, 3, 0}}, {38, {2, 2, 0}},
       {39, {1, 0, 1}}, {40, {2, 0, 1}}, {41, {1, 0, 2}}, {42, {3, 1, 1}}, {44, {2, 1, 2}},
       {45, {2, 3, 1}}, {46, {1, 3, 1}}, {48, {0, 2, 1}}, {49, {0, 1, 1}}, {50, {0, 1, 2}},
       {51, {1, 1, 1}}, {52, {2, 1, 1}}, {53, {2, 2, 1}}, {54, {1, 2, 1}}, {55, {1, 1, 2}}});
  // HEXA_125: faces F1 (ring N1 N2 N3 N4), F2, F5 (whose ring starts next to N4), F6, then
  // the interior level by level.
  expectNodes(
      CellType::Hexahedron, 4,
      {{9, {1, 0, 0}},   {18, {0, 3, 0}},  {21, {0, 0, 1}},  {42, {0, 3, 4}},  {45, {1, 1, 0}},
       {46, {2, 1, 0}},  {47, {3, 1, 0}},  {48, {3, 2, 0}},  {49, {3, 3, 0}},  {51, {1, 3, 0}},
       {52, {1, 2, 0}},  {53, {2, 2, 0}},  {54, {1, 0, 1}},  {56, {3, 0, 1}},  {58, {3, 0, 3}},
       {60, {1, 0, 3}},  {62, {2, 0, 2}},  {63, {4, 1, 1}},  {72, {3, 4, 1}},  {81, {0, 3, 1}},
       {82, {0, 2, 1}},  {83, {0, 1, 1}},  {84, {0, 1, 2}},  {85, {0, 1, 3}},  {87, {0, 3, 3}},
       {89, {0, 2, 2}},  {90, {1, 1, 4}},  {92, {3, 1, 4}},  {96, {1, 3, 4}},  {98, {2, 2, 4}},
       {99, {1, 1, 1}},  {100, {2, 1, 1}}, {103, {3, 3, 1}}, {105, {1, 3, 1}}, {107, {2, 2, 1}},
       {108, {1, 1, 2}}, {125, {2, 2, 3}}});
  // Orders 2 and 3: HEXA_27's face centres, HEXA_64's F5 and interior, PENTA_40, PYRA_14/30.
  expectNodes(CellType::Hexahedron, 2,
              {{21, {1, 1, 0}},
               {22, {1, 0, 1}},
               {23, {2, 1, 1}},
               {24, {1, 2, 1}},
               {25, {0, 1, 1}},
               {26, {1, 1, 2}},
               {27, {1, 1, 1}}});
  expectNodes(CellType::Hexahedron, 3,
              {{33, {1, 1, 0}},
               {34, {2, 1, 0}},
               {35, {2, 2, 0}},
               {36, {1, 2, 0}},
               {49, {0, 2, 1}},
               {50, {0, 1, 1}},
               {51, {0, 1, 2}},
               {52, {0, 2, 2}},
               {57, {1, 1, 1}},
               {58, {2, 1, 1}},
               {59, {2, 2, 1}},
               {60, {1, 2, 1}},
               {61, {1, 1, 2}},
               {64, {1, 2, 2}}});
  expectNodes(
      CellType::Prism, 3,
      {{25, {1, 1, 0}}, {26, {1, 0, 1}}, {38, {1, 1, 3}}, {39, {1, 1, 1}}, {40, {1, 1, 2}}});
  expectNodes(CellType::Prism, 2, {{16, {1, 0, 1}}, {17, {1, 1, 1}}, {18, {0, 1, 1}}});
  expectNodes(CellType::Pyramid, 2, {{10, {0, 0, 1}}, {13, {0, 1, 1}}, {14, {1, 1, 0}}});
  expectNodes(CellType::Pyramid, 3, {{22, {1, 1, 0}}, {26, {1, 0, 1}}, {30, {1, 1, 1}}});
  expectNodes(CellType::Tetrahedron, 2, {{8, {0, 0, 1}}, {9, {1, 0, 1}}, {10, {0, 1, 1}}});
}

TEST(CgnsOrdering, IsAPermutationForEveryShapeAndOrderCgnsNames) {
  for (const CellType type :
       {CellType::Line, CellType::Triangle, CellType::Quadrilateral, CellType::Tetrahedron,
        CellType::Pyramid, CellType::Prism, CellType::Hexahedron}) {
    for (int order = 1; order <= 4; ++order) {
      const std::vector<LatticePoint> cgns = latticeOrder(type, order, NodeConvention::Cgns);
      const std::vector<LatticePoint> gmsh = latticeOrder(type, order, NodeConvention::Gmsh);
      EXPECT_EQ(std::set<LatticePoint>(cgns.begin(), cgns.end()),
                std::set<LatticePoint>(gmsh.begin(), gmsh.end()))
          << cellShortName(type) << " order " << order;
      EXPECT_EQ(std::set<LatticePoint>(cgns.begin(), cgns.end()).size(), cgns.size());
      // Vertices first, in the same order as Gmsh's (the shapes' corners agree).
      for (int v = 0; v < cellNumVertices(type); ++v) EXPECT_EQ(cgns[v], gmsh[v]);
    }
    EXPECT_THROW(latticeOrder(type, 5, NodeConvention::Cgns), ParameterError);
  }
}

Mesh curvedBoxWithHole(int order) {
  const CadModel cad = test::toModel(test::boxWithHole());
  return elevateOrder(generateLinearMesh(cad, LinearMeshOptions::uniform(0.9)), order, &cad);
}

void expectSameMesh(const Mesh& back, const Mesh& mesh, const std::string& what) {
  ASSERT_EQ(back.dim, mesh.dim) << what;
  ASSERT_EQ(back.order, mesh.order) << what;
  ASSERT_EQ(back.xyz, mesh.xyz) << what;  // bit for bit
  ASSERT_EQ(back.blocks.size(), mesh.blocks.size()) << what;
  for (std::size_t b = 0; b < mesh.blocks.size(); ++b) {
    EXPECT_EQ(back.blocks[b].type, mesh.blocks[b].type) << what << " block " << b;
    EXPECT_EQ(back.blocks[b].order, mesh.blocks[b].order) << what << " block " << b;
    EXPECT_EQ(back.blocks[b].nodes, mesh.blocks[b].nodes) << what << " block " << b;
    EXPECT_EQ(back.blocks[b].entity, mesh.blocks[b].entity) << what << " block " << b;
  }
}

TEST(CgnsWriter, CurvedMeshRoundTripsBitForBitWithEntitiesAndGroups) {
  const auto dir = test::tempDir();
  for (const int order : {1, 2, 3, 4}) {
    const Mesh mesh = curvedBoxWithHole(order);
    std::set<int> faces;
    for (const ElementBlock& b : mesh.blocks)
      if (cellDimension(b.type) == 2) faces.insert(b.entity.begin(), b.entity.end());
    ASSERT_GE(faces.size(), 4u);
    const std::vector<int> all(faces.begin(), faces.end());
    // Two named groups; the other faces keep their own ("FaceN").
    WriteOptions options;
    options.groups = {{"inlet", {all[0], all[2]}}, {"hole wall", {all[1]}}};
    const std::string path = (dir / ("box" + std::to_string(order) + ".cgns")).string();
    writeMesh(mesh, path, {}, options);
    std::vector<std::string> notes;
    std::vector<NamedGroup> groups;
    const Mesh back = readMesh(path, &notes, &groups);
    expectSameMesh(back, mesh, "order " + std::to_string(order));
    EXPECT_TRUE(notes.empty());
    ASSERT_EQ(groups.size(), 2u);
    EXPECT_EQ(groups[0].name, "inlet");
    EXPECT_EQ(groups[0].entities, (std::vector<int>{all[0], all[2]}));
    EXPECT_EQ(groups[1].name, "hole wall");
    EXPECT_EQ(groups[1].entities, std::vector<int>{all[1]});
  }
}

// A block whose cells interleave entities is written as one section per entity (not one per
// run: a mesh curved from another tool's file lists its boundary in any order), and reads back
// grouped: the entities in the order they first appear, each one's cells in block order.
TEST(CgnsWriter, InterleavedEntitiesComeBackGroupedOneSectionEach) {
  const auto dir = test::tempDir();
  Mesh mesh = curvedBoxWithHole(2);
  ElementBlock* tris = nullptr;
  for (ElementBlock& b : mesh.blocks)
    if (b.type == CellType::Triangle) tris = &b;
  ASSERT_NE(tris, nullptr);
  // Reverse the block: each entity's cells now come in reverse, and the entities too.
  const int n = tris->nodesPerElement();
  ElementBlock reversed = *tris;
  for (std::size_t e = 0; e < tris->count(); ++e) {
    const std::size_t r = tris->count() - 1 - e;
    std::copy(tris->element(r), tris->element(r) + n, reversed.nodes.begin() + e * n);
    reversed.entity[e] = tris->entity[r];
  }
  // Interleave: swap the first entity's last cell with the block's last cell (another entity's).
  std::size_t last = 0;
  while (reversed.entity[last + 1] == reversed.entity[0]) ++last;
  const std::size_t final = reversed.count() - 1;
  ASSERT_GE(last, 1u);
  ASSERT_NE(reversed.entity[final], reversed.entity[0]);
  const auto cell = [&](std::size_t e) {
    return reversed.nodes.begin() + static_cast<std::ptrdiff_t>(e * static_cast<std::size_t>(n));
  };
  std::swap_ranges(cell(last), cell(last + 1), cell(final));
  std::swap(reversed.entity[last], reversed.entity[final]);
  *tris = reversed;
  const std::string path = (dir / "interleaved.cgns").string();
  writeMesh(mesh, path, {});
  // Expected: the stable grouping of the block by entity, in first-appearance order.
  std::vector<int> order;
  std::map<int, std::vector<std::size_t>> cellsOf;
  for (std::size_t e = 0; e < tris->count(); ++e) {
    if (cellsOf[tris->entity[e]].empty()) order.push_back(tris->entity[e]);
    cellsOf[tris->entity[e]].push_back(e);
  }
  ElementBlock grouped = *tris;
  std::size_t at = 0;
  for (const int entity : order)
    for (const std::size_t e : cellsOf[entity]) {
      std::copy(
          tris->element(e), tris->element(e) + n,
          grouped.nodes.begin() + static_cast<std::ptrdiff_t>(at * static_cast<std::size_t>(n)));
      grouped.entity[at++] = entity;
    }
  *tris = grouped;
  expectSameMesh(readMesh(path), mesh, "interleaved");
  // One triangle section per face.
  const std::set<int> faces(tris->entity.begin(), tris->entity.end());
  int fn = 0, sections = 0, triSections = 0;
  ASSERT_EQ(cg_open(path.c_str(), CG_MODE_READ, &fn), CG_OK);
  ASSERT_EQ(cg_nsections(fn, 1, 1, &sections), CG_OK);
  for (int s = 1; s <= sections; ++s) {
    char name[33] = {0};
    CGNS_ENUMT(ElementType_t) type{};
    cgsize_t start = 0, end = 0;
    int boundary = 0, parents = 0;
    ASSERT_EQ(cg_section_read(fn, 1, 1, s, name, &type, &start, &end, &boundary, &parents), CG_OK);
    if (type == CGNS_ENUMV(TRI_6)) ++triSections;
  }
  cg_close(fn);
  EXPECT_EQ(triSections, static_cast<int>(faces.size()));
}

// A 2D mesh (the plane z = 0: written in 2D physical space) with its boundary lines and a named
// group of two edges reads back bit for bit.
TEST(CgnsWriter, TwoDimensionalMeshRoundTripsWithItsBoundaryLines) {
  const auto dir = test::tempDir();
  const TopoDS_Shape face = BRepBuilderAPI_MakeFace(gp_Pln(), 0.0, 2.0, 0.0, 1.0).Face();
  const CadModel cad = test::toModel(face);
  const Mesh mesh = elevateOrder(generateLinearMesh(cad, LinearMeshOptions::uniform(0.3)), 3, &cad);
  ASSERT_EQ(mesh.dim, 2);
  const std::string path = (dir / "square.cgns").string();
  WriteOptions options;
  options.groups = {{"inlet", {1, 3}}};
  writeMesh(mesh, path, {}, options);
  std::vector<NamedGroup> groups;
  const Mesh back = readMesh(path, nullptr, &groups);
  expectSameMesh(back, mesh, "2D");
  ASSERT_EQ(groups.size(), 1u);
  EXPECT_EQ(groups[0].name, "inlet");
  EXPECT_EQ(groups[0].entities, (std::vector<int>{1, 3}));
}

// One curved element of every volume shape per order, side by side.
Mesh curvedShapes(int order) {
  Mesh mesh;
  mesh.dim = 3;
  mesh.order = order;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  int shift = 0;
  for (const CellType type :
       {CellType::Tetrahedron, CellType::Pyramid, CellType::Prism, CellType::Hexahedron}) {
    const ReferenceElement& ref = ReferenceElement::get(type, order);
    ElementBlock block;
    block.type = type;
    block.order = order;
    for (int n = 0; n < ref.numNodes(); ++n) {
      const Eigen::Vector3d xi = ref.nodes().row(n).transpose();
      double x[3] = {xi.x() + 0.1 * std::sin(2.0 * xi.y()) + 3.0 * shift, xi.y(),
                     xi.z() + 0.1 * std::cos(xi.x())};
      if (order > 1)
        for (double& c : x) c += jitter(rng);
      block.nodes.push_back(mesh.addNode(x, 3, 1, NAN, NAN));
    }
    block.entity.push_back(shift + 1);
    mesh.blocks.push_back(block);
    ++shift;
  }
  return mesh;
}

TEST(CgnsWriter, EveryShapeRoundTripsAtOrdersOneToFourAndOrderFiveIsRefused) {
  const auto dir = test::tempDir();
  for (int order = 1; order <= 4; ++order) {
    const Mesh mesh = curvedShapes(order);
    const std::string path = (dir / ("shapes" + std::to_string(order) + ".cgns")).string();
    writeMesh(mesh, path, {});
    expectSameMesh(readMesh(path), mesh, "order " + std::to_string(order));
  }
  const std::string path = (dir / "shapes5.cgns").string();
  try {
    writeMesh(curvedShapes(5), path, {});
    ADD_FAILURE() << "order 5 was written";
  } catch (const ParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("up to order 4"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(path));
  EXPECT_FALSE(std::filesystem::exists(path + ".part"));
}

// A failed write leaves neither the temporary file nor a changed output behind: a group name
// too long for CGNS (refused before the file is opened), and a failure once the whole file is
// written (its name taken by a folder, so that the temporary file cannot be renamed onto it).
TEST(CgnsWriter, AFailedWriteLeavesNoPartialFileAndKeepsThePreviousOne) {
  const auto dir = test::tempDir();
  const Mesh mesh = curvedBoxWithHole(2);
  const std::string path = (dir / "box.cgns").string();
  std::ofstream(path) << "previous";
  int face = 0;
  for (const ElementBlock& b : mesh.blocks)
    if (cellDimension(b.type) == 2) face = b.entity.front();
  WriteOptions options;
  options.groups = {{std::string(33, 'w'), {face}}};
  try {
    writeMesh(mesh, path, {}, options);
    ADD_FAILURE() << "a 33-character name was written";
  } catch (const ParameterError& e) {
    EXPECT_NE(std::string(e.what()).find("at most 32 characters"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(std::filesystem::exists(path + ".part"));
  std::ifstream in(path);
  std::string kept;
  in >> kept;
  EXPECT_EQ(kept, "previous");

  const std::string folder = (dir / "taken.cgns").string();
  std::filesystem::create_directory(folder);
  std::ofstream(folder + "/inside") << "kept";
  EXPECT_THROW(writeMesh(mesh, folder, {}), IoError);
  EXPECT_FALSE(std::filesystem::exists(folder + ".part"));
  EXPECT_TRUE(std::filesystem::is_directory(folder));
  EXPECT_TRUE(std::filesystem::exists(folder + "/inside"));
}

// A file as other tools write them, made with the CGNS library: two zones of one hexahedron
// each, sharing a face, in MIXED sections with their boundary quadrilaterals, conditions on
// nodes (zone 1: the face x = 0) and on cells (zone 2: the face x = 2, by range).
void writeTwoZoneFile(const std::string& path, int badType, cgsize_t rangeEnd = 2) {
  int fn = 0, base = 0;
  ASSERT_EQ(cg_open(path.c_str(), CG_MODE_WRITE, &fn), CG_OK) << cg_get_error();
  ASSERT_EQ(cg_base_write(fn, "Base", 3, 3, &base), CG_OK);
  for (int z = 0; z < 2; ++z) {
    cgsize_t size[3] = {8, 1, 0};
    int zone = 0, c = 0, s = 0, bc = 0;
    ASSERT_EQ(
        cg_zone_write(fn, base, z == 0 ? "left" : "right", size, CGNS_ENUMV(Unstructured), &zone),
        CG_OK);
    double x[8], y[8], w[8];
    for (int k = 0; k < 8; ++k) {
      const int i = (k == 1 || k == 2 || k == 5 || k == 6) ? 1 : 0;
      x[k] = z + i;
      y[k] = (k % 4 == 2 || k % 4 == 3) ? 1.0 : 0.0;
      w[k] = k < 4 ? 0.0 : 1.0;
    }
    ASSERT_EQ(cg_coord_write(fn, base, zone, CGNS_ENUMV(RealDouble), "CoordinateX", x, &c), CG_OK);
    ASSERT_EQ(cg_coord_write(fn, base, zone, CGNS_ENUMV(RealDouble), "CoordinateY", y, &c), CG_OK);
    ASSERT_EQ(cg_coord_write(fn, base, zone, CGNS_ENUMV(RealDouble), "CoordinateZ", w, &c), CG_OK);
    // The hexahedron, then its face x = z (left zone) or x = z + 1 (right zone).
    const cgsize_t cells[] = {CGNS_ENUMV(HEXA_8),
                              1,
                              2,
                              3,
                              4,
                              5,
                              6,
                              7,
                              8,
                              CGNS_ENUMV(QUAD_4),
                              z == 0 ? 1 : 2,
                              z == 0 ? 5 : 3,
                              z == 0 ? 8 : 7,
                              z == 0 ? 4 : 6};
    if (badType != 0 && z == 1) {
      const cgsize_t bad[20] = {1, 2, 3, 4, 5, 6, 7, 8, 1, 2, 3, 4, 5, 6, 7, 8, 1, 2, 3, 4};
      ASSERT_EQ(cg_section_write(fn, base, zone, "Serendipity",
                                 static_cast<CGNS_ENUMT(ElementType_t)>(badType), 1, 1, 0, bad, &s),
                CG_OK);
    } else {
      const cgsize_t offsets[] = {0, 9, 14};
      ASSERT_EQ(cg_poly_section_write(fn, base, zone, "Cells", CGNS_ENUMV(MIXED), 1, 2, 0, cells,
                                      offsets, &s),
                CG_OK)
          << cg_get_error();
    }
    if (z == 0) {
      const cgsize_t nodes[] = {1, 4, 5, 8};
      ASSERT_EQ(cg_boco_write(fn, base, zone, "inflow", CGNS_ENUMV(BCInflow), CGNS_ENUMV(PointList),
                              4, nodes, &bc),
                CG_OK);
    } else if (badType == 0) {
      const cgsize_t range[] = {2, rangeEnd};
      ASSERT_EQ(cg_boco_write(fn, base, zone, "outflow", CGNS_ENUMV(BCOutflow),
                              CGNS_ENUMV(PointRange), 2, range, &bc),
                CG_OK);
      ASSERT_EQ(cg_boco_gridlocation_write(fn, base, zone, bc, CGNS_ENUMV(FaceCenter)), CG_OK);
    }
  }
  ASSERT_EQ(cg_close(fn), CG_OK);
}

TEST(CgnsReader, JoinsZonesReadsMixedSectionsAndConditionsOnNodesOrCells) {
  const auto dir = test::tempDir();
  const std::string path = (dir / "two_zones.cgns").string();
  writeTwoZoneFile(path, 0);
  std::vector<std::string> notes;
  std::vector<NamedGroup> groups;
  const Mesh mesh = readMesh(path, &notes, &groups);
  EXPECT_EQ(mesh.numNodes(), 12u);  // 16 nodes, 4 shared
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("2 zones joined at 4 nodes"), std::string::npos) << notes[0];
  ASSERT_EQ(mesh.blocks.size(), 2u);
  EXPECT_EQ(mesh.blocks[0].type, CellType::Hexahedron);
  EXPECT_EQ(mesh.blocks[0].count(), 2u);
  EXPECT_EQ(mesh.blocks[1].type, CellType::Quadrilateral);
  EXPECT_EQ(mesh.blocks[1].entity, (std::vector<std::int32_t>{1, 2}));
  ASSERT_EQ(groups.size(), 2u);
  EXPECT_EQ(groups[0].name, "inflow");
  EXPECT_EQ(groups[0].entities, std::vector<int>{1});
  EXPECT_EQ(groups[1].name, "outflow");
  EXPECT_EQ(groups[1].entities, std::vector<int>{2});
  // The quadrilateral of the inflow lies at x = 0, the outflow's at x = 2.
  for (std::size_t q = 0; q < 2; ++q)
    for (int k = 0; k < 4; ++k)
      EXPECT_EQ(mesh.xyz[3 * static_cast<std::size_t>(mesh.blocks[1].element(q)[k])],
                q == 0 ? 0.0 : 2.0);
}

TEST(CgnsReader, RefusesIncompleteElementsAndFilesThatAreNotCgnsByName) {
  const auto dir = test::tempDir();
  const std::string path = (dir / "serendipity.cgns").string();
  writeTwoZoneFile(path, CGNS_ENUMV(HEXA_20));
  try {
    readMesh(path);
    ADD_FAILURE() << "HEXA_20 was read";
  } catch (const IoError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("section 'Serendipity' holds HEXA_20"), std::string::npos) << what;
    EXPECT_NE(what.find("incomplete"), std::string::npos) << what;
  }
  // A condition's range reaching past the zone's cells (here to 2^31 - 1, which expanded would
  // take 8 GiB) is refused before it is expanded.
  const std::string huge = (dir / "huge_range.cgns").string();
  writeTwoZoneFile(huge, 0, std::numeric_limits<cgsize_t>::max());
  try {
    readMesh(huge);
    ADD_FAILURE() << "a range past the cells was read";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("boundary condition 'outflow' is the range 2 to " +
                                         std::to_string(std::numeric_limits<cgsize_t>::max()) +
                                         ", not within the zone's cells 1 to 2"),
              std::string::npos)
        << e.what();
  }
  const std::string text = (dir / "text.cgns").string();
  std::ofstream(text) << "not a CGNS file\n";
  try {
    readMesh(text);
    ADD_FAILURE() << "a text file was read";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot read '" + text + "' as CGNS"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace homesh

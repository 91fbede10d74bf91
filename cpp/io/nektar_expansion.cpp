#include "io/nektar_expansion.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "core/cell_type.hpp"
#include "core/error.hpp"
#include "element/node_sets.hpp"
#include "element/orthogonal_basis.hpp"
#include "element/reference_element.hpp"

namespace homesh::nektar {
namespace {

// The Jacobi polynomial P_n^(a, b)(x) by its three-term recurrence.
double jacobi(int n, double a, double b, double x) {
  if (n == 0) return 1.0;
  double previous = 1.0;
  double current = 0.5 * (a - b + (a + b + 2.0) * x);
  for (int k = 2; k <= n; ++k) {
    const double c = 2.0 * k + a + b;
    const double a1 = 2.0 * k * (k + a + b) * (c - 2.0);
    const double a2 = (c - 1.0) * (a * a - b * b);
    const double a3 = (c - 2.0) * (c - 1.0) * c;
    const double a4 = 2.0 * (k + a - 1.0) * (k + b - 1.0) * c;
    const double next = ((a2 + a3 * x) * current - a4 * previous) / a1;
    previous = current;
    current = next;
  }
  return current;
}

// The modified basis's 1D factors (Karniadakis and Sherwin, "Spectral/hp Element Methods for
// CFD", 2nd ed., section 3.2.3), indexed as Nektar++ stores them: the two vertex functions
// first. modA: (1 - z)/2, (1 + z)/2, then the bubbles (1 - z)/2 (1 + z)/2 P^(1,1)_(p-2).
double modA(int p, double z) {
  const double lo = 0.5 * (1.0 - z), hi = 0.5 * (1.0 + z);
  if (p == 0) return lo;
  if (p == 1) return hi;
  return lo * hi * jacobi(p - 2, 1.0, 1.0, z);
}

// modB row p: p = 0 is modA; p = 1 is modA without its second vertex function (the collapsed
// vertex is counted once); p >= 2: ((1 - z)/2)^p, then ((1 - z)/2)^p (1 + z)/2 P^(2p-1,1)_(q-1).
double modB(int p, int q, double z) {
  if (p == 0) return modA(q, z);
  if (p == 1) return q == 0 ? 0.5 * (1.0 - z) : modA(q + 1, z);
  const double power = std::pow(0.5 * (1.0 - z), p);
  if (q == 0) return power;
  return power * 0.5 * (1.0 + z) * jacobi(q - 1, 2.0 * p - 1.0, 1.0, z);
}

struct Mode {
  int p, q, r;
};

// A shape's modes (p, q, r) in Nektar++'s ranges, for order + 1 modes per direction.
std::vector<Mode> modesOf(CellType type, int order) {
  std::vector<Mode> modes;
  const int n = order + 1;
  for (int p = 0; p < n; ++p) {
    if (type == CellType::Pyramid) {  // r up to order - max(p, q)
      for (int q = 0; q < n; ++q)
        for (int r = 0; r < n - std::max(p, q); ++r) modes.push_back({p, q, r});
      continue;
    }
    if (type == CellType::Triangle) {
      for (int q = 0; q < n - p; ++q) modes.push_back({p, q, 0});
      continue;
    }
    for (int q = 0; q < (type == CellType::Tetrahedron ? n - p : n); ++q)
      for (int r = 0; r < (type == CellType::Tetrahedron ? n - p - q : n - p); ++r)
        modes.push_back({p, q, r});
  }
  return modes;
}

bool isInterior(CellType type, const Mode& m) {
  switch (type) {
    case CellType::Triangle:
      return m.p >= 2 && m.q >= 1;
    case CellType::Tetrahedron:
      return isInteriorTetMode(m.p, m.q, m.r);
    case CellType::Pyramid:
      return isInteriorPyramidMode(m.p, m.q, m.r);
    default:
      return isInteriorPrismMode(m.p, m.q, m.r);
  }
}

// A triangle's mode (p, q) at barycentric point `lambda` (Nektar++'s vertices 0..2; lambda0 +
// lambda1 > 0): modA(p, eta1) modB(p, q, eta2), Nektar++ completing the collapsed vertex's
// function (0, 1) to lambda2.
double modifiedTriMode(int p, int q, const std::array<double, 3>& lambda) {
  if (p == 0 && q == 1) return lambda[2];
  const double eta1 = (lambda[1] - lambda[0]) / (lambda[0] + lambda[1]);
  return modA(p, eta1) * modB(p, q, 2.0 * lambda[2] - 1.0);
}

// A mode at a point of our (Gmsh's) reference element, in Nektar++'s local numbering of the
// vertices (the reader's Gmsh local order of a tetrahedron is Nektar++'s; its prism's Gmsh
// vertices 0, 1, 2, 3, 4, 5 are Nektar++'s 4, 1, 0, 5, 2, 3).
double modeAt(CellType type, const Mode& m, double x, double y, double z) {
  if (type == CellType::Triangle) return modifiedTriMode(m.p, m.q, {1.0 - x - y, x, y});
  if (type == CellType::Tetrahedron)
    return modifiedTetMode(m.p, m.q, m.r, {1.0 - x - y - z, x, y, z});
  // Nektar++'s pyramid: its vertices are ours (the apex above vertex 0), xi = 2 x - 1.
  if (type == CellType::Pyramid)
    return modifiedPyramidMode(m.p, m.q, m.r, {2.0 * x - 1.0, 2.0 * y - 1.0, 2.0 * z - 1.0});
  // Nektar++'s prism: xi1 from its vertex 0 to 1 (our y = 0 .. x = 1), xi2 from 0 to 3 (our
  // z), xi3 from 0 to 4 (our x + y = 1 .. 0).
  const double xi1 = 2.0 * x - 1.0, xi2 = 2.0 * z - 1.0, xi3 = 1.0 - 2.0 * (x + y);
  return modifiedPrismMode(m.p, m.q, m.r, {xi1, xi2, xi3});
}

ExpansionInteriorMap buildMap(CellType type, int order) {
  const ReferenceElement& ref = ReferenceElement::get(type, order);
  const int n = ref.numNodes();
  ExpansionInteriorMap map;
  for (int k = 0; k < n; ++k) {
    const LatticePoint& l = ref.lattice()[static_cast<std::size_t>(k)];
    const bool onTriangle = l[0] == 0 || l[1] == 0 || l[0] + l[1] == order;
    const bool onFace =
        type == CellType::Triangle ? onTriangle
        : type == CellType::Tetrahedron
            ? l[0] == 0 || l[1] == 0 || l[2] == 0 || l[0] + l[1] + l[2] == order
        : type == CellType::Pyramid
            ? l[0] == 0 || l[1] == 0 || l[2] == 0 || l[0] + l[2] == order || l[1] + l[2] == order
            : onTriangle || l[2] == 0 || l[2] == order;
    (onFace ? map.boundary : map.interior).push_back(k);
  }
  const std::vector<Mode> modes = modesOf(type, order);
  std::vector<int> boundaryModes;
  for (int m = 0; m < static_cast<int>(modes.size()); ++m)
    if (!isInterior(type, modes[static_cast<std::size_t>(m)])) boundaryModes.push_back(m);
  if (modes.size() != static_cast<std::size_t>(n) || boundaryModes.size() != map.boundary.size())
    throw MeshingError(cellShortName(type) + " modes: " + std::to_string(boundaryModes.size()) +
                       " boundary modes against " + std::to_string(map.boundary.size()) +
                       " boundary nodes");

  // The modes at the lattice nodes, through the shape's orthogonal basis: each mode's
  // coefficients from its values where collapsed coordinates are regular (well-spread nodes
  // shrunk towards the centroid; a well-conditioned Vandermonde matrix), then evaluated at the
  // nodes; exact up to rounding, as the modes lie in the element's space.
  const Eigen::RowVector3d centroid =
      type == CellType::Tetrahedron ? Eigen::RowVector3d(0.25, 0.25, 0.25)
      : type == CellType::Pyramid   ? Eigen::RowVector3d(0.3, 0.3, 0.25)
                                    : Eigen::RowVector3d(1.0 / 3, 1.0 / 3, 0.5);
  const Eigen::Index dim = ref.dim();
  // (Pyramids have no optimal node set: their equispaced nodes, shrunk the same way.)
  Eigen::MatrixXd samples =
      ReferenceElement::get(type, order,
                            type == CellType::Pyramid ? NodeSet::Equispaced : NodeSet::Optimal)
          .nodes();
  for (Eigen::Index k = 0; k < samples.rows(); ++k)
    samples.row(k) = centroid.head(dim) + 0.8 * (samples.row(k) - centroid.head(dim));
  const auto orthogonalAt = [&](const Eigen::MatrixXd& points) {
    Eigen::MatrixXd psi(points.rows(), n);
    Eigen::VectorXd values;
    Eigen::MatrixXd gradients;
    for (Eigen::Index k = 0; k < points.rows(); ++k) {
      const Eigen::VectorXd xi = points.row(k).transpose();
      orthogonalBasis(type, order, xi.data(), values, gradients);
      psi.row(k) = values.transpose();
    }
    return psi;
  };
  Eigen::MatrixXd modeValues(n, static_cast<Eigen::Index>(modes.size()));
  for (Eigen::Index k = 0; k < n; ++k)
    for (std::size_t m = 0; m < modes.size(); ++m)
      modeValues(k, static_cast<Eigen::Index>(m)) =
          modeAt(type, modes[m], samples(k, 0), samples(k, 1), dim > 2 ? samples(k, 2) : 0.0);
  const Eigen::MatrixXd coefficients = orthogonalAt(samples).partialPivLu().solve(modeValues);
  const Eigen::MatrixXd atNodes = orthogonalAt(ref.nodes()) * coefficients;
  // A pyramid's modes lie in our element's space only up to order 2 (nektar_expansion.hpp):
  // checked at points between the samples, where a mode outside it differs from its
  // interpolant (1e-9 of the largest mode value: far above the rounding of these fits at the
  // orders checked, far below the 1e-3 a mode outside the space misses by). Tetrahedra's,
  // prisms' and triangles' spaces are ours by construction.
  if (type == CellType::Pyramid) {
    Eigen::MatrixXd checks = samples;
    for (Eigen::Index k = 0; k < checks.rows(); ++k)
      checks.row(k) = centroid.head(dim) + 0.7 * (checks.row(k) - centroid.head(dim)) +
                      0.01 * Eigen::RowVector3d(0.31, 0.17, 0.23).head(dim);
    Eigen::MatrixXd exact(checks.rows(), static_cast<Eigen::Index>(modes.size()));
    for (Eigen::Index k = 0; k < checks.rows(); ++k)
      for (std::size_t m = 0; m < modes.size(); ++m)
        exact(k, static_cast<Eigen::Index>(m)) =
            modeAt(type, modes[m], checks(k, 0), checks(k, 1), checks(k, 2));
    const Eigen::MatrixXd misfits = (orthogonalAt(checks) * coefficients - exact).cwiseAbs();
    Eigen::Index worstRow = 0, worstMode = 0;
    const double misfit = misfits.maxCoeff(&worstRow, &worstMode);
    if (!(misfit < 1e-9 * std::max(1.0, exact.cwiseAbs().maxCoeff()))) {
      const Mode& m = modes[static_cast<std::size_t>(worstMode)];
      throw MeshingError("Nektar++'s pyramid mode (" + std::to_string(m.p) + ", " +
                         std::to_string(m.q) + ", " + std::to_string(m.r) + ") of order " +
                         std::to_string(order) + " is not in our element's space (misfit " +
                         std::to_string(misfit) +
                         "): the geometry Nektar++ builds cannot be reproduced");
    }
  }

  const auto nb = static_cast<Eigen::Index>(map.boundary.size());
  const auto ni = static_cast<Eigen::Index>(map.interior.size());
  Eigen::MatrixXd boundary(nb, nb), interior(ni, nb);
  for (Eigen::Index c = 0; c < nb; ++c) {
    const int m = boundaryModes[static_cast<std::size_t>(c)];
    for (Eigen::Index r = 0; r < nb; ++r)
      boundary(r, c) = atNodes(map.boundary[static_cast<std::size_t>(r)], m);
    for (Eigen::Index r = 0; r < ni; ++r)
      interior(r, c) = atNodes(map.interior[static_cast<std::size_t>(r)], m);
  }
  // interior = I B^-1, i.e. B^T W^T = I^T.
  map.weights = boundary.transpose().partialPivLu().solve(interior.transpose()).transpose();
  return map;
}

// The points a NodalTriElec curve lists: Hesthaven's electrostatic points on the triangle
// (J. S. Hesthaven, SIAM J. Numer. Anal. 35(2), 1998), one row per symmetry orbit, with the
// orbit's size (1, 3 or 6) and one member's barycentric coordinates, to the 10 digits that
// define the points type in Nektar++ 5.x. These numbers are a fact of the file format (where
// the stored points lie), as the points-type values in nektar_format.hpp are; they are the
// values of Nektar++'s table NodalTriElecData.h, which carries this notice:
//   Copyright (c) 2006 Division of Applied Mathematics, Brown University (USA), Department of
//   Aeronautics, Imperial College London (UK), and Scientific Computing and Imaging
//   Institute, University of Utah (USA). MIT License (see docs/nektar-format.md).
struct Orbit {
  int size;
  double a, b, c;
};

const std::map<int, std::vector<Orbit>>& elecOrbits() {
  static const std::map<int, std::vector<Orbit>> table = {
      {2,
       {{3, 1.0000000000, 0.0000000000, 0.0000000000},
        {3, 0.5000000000, 0.5000000000, 0.0000000000}}},
      {3,
       {{3, 1.0000000000, 0.0000000000, 0.0000000000},
        {6, 0.7236067977, 0.2763932023, 0.0000000000},
        {1, 0.3333333333, 0.3333333333, 0.3333333333}}},
      {4,
       {{3, 1.0000000000, 0.0000000000, 0.0000000000},
        {3, 0.5000000000, 0.5000000000, 0.0000000000},
        {6, 0.8273268354, 0.1726731646, 0.0000000000},
        {3, 0.2371200168, 0.2371200168, 0.5257599664}}},
      {5,
       {{3, 1.0000000000, 0.0000000000, 0.0000000000},
        {6, 0.6426157582, 0.3573842418, 0.0000000000},
        {6, 0.8825276620, 0.1174723380, 0.0000000000},
        {3, 0.4105151510, 0.4105151510, 0.1789696980},
        {3, 0.1575181512, 0.1575181512, 0.6849636976}}},
      {6,
       {{3, 1.0000000000, 0.0000000000, 0.0000000000},
        {3, 0.5000000000, 0.5000000000, 0.0000000000},
        {6, 0.7344243967, 0.2655756033, 0.0000000000},
        {6, 0.9151119481, 0.0848880519, 0.0000000000},
        {1, 0.3333333333, 0.3333333333, 0.3333333333},
        {3, 0.1061169285, 0.1061169285, 0.7877661430},
        {6, 0.3097982151, 0.5569099204, 0.1332918645}}},
      {7,
       {{3, 1.0000000000, 0.0000000000, 0.0000000000},
        {6, 0.9358700743, 0.0641299257, 0.0000000000},
        {6, 0.7958500907, 0.2041499093, 0.0000000000},
        {6, 0.6046496090, 0.3953503910, 0.0000000000},
        {6, 0.2325524777, 0.6759625951, 0.0914849272},
        {3, 0.4477725053, 0.4477725053, 0.1044549894},
        {3, 0.2604038024, 0.2604038024, 0.4791923952},
        {3, 0.0660520784, 0.0660520784, 0.8678958432}}},
      {8,
       {{3, 1.0000000000, 0.0000000000, 0.0000000000},
        {3, 0.5000000000, 0.5000000000, 0.0000000000},
        {6, 0.9498789977, 0.0501210023, 0.0000000000},
        {6, 0.8385931398, 0.1614068602, 0.0000000000},
        {6, 0.6815587319, 0.3184412681, 0.0000000000},
        {3, 0.3905496216, 0.3905496216, 0.2189007568},
        {3, 0.2033467796, 0.2033467796, 0.5933064408},
        {3, 0.0469685351, 0.0469685351, 0.9060629298},
        {6, 0.3617970895, 0.5541643672, 0.0840385433},
        {6, 0.1801396087, 0.7519065566, 0.0679538347}}},
      {9,
       {{3, 1.0000000000, 0.0000000000, 0.0000000000},
        {6, 0.9597669541, 0.0402330459, 0.0000000000},
        {6, 0.8693869326, 0.1306130674, 0.0000000000},
        {6, 0.7389624749, 0.2610375251, 0.0000000000},
        {6, 0.5826394788, 0.4173605212, 0.0000000000},
        {1, 0.3333333333, 0.3333333333, 0.3333333333},
        {3, 0.4640303025, 0.4640303025, 0.0719393950},
        {3, 0.1633923069, 0.1633923069, 0.6732153862},
        {3, 0.0355775717, 0.0355775717, 0.9288448566},
        {6, 0.3225890045, 0.4968009397, 0.1806100558},
        {6, 0.2966333890, 0.6349633653, 0.0684032457},
        {6, 0.1439089974, 0.8031490682, 0.0529419344}}},
      {10,
       {{3, 1.0000000000, 0.0000000000, 0.0000000000},
        {3, 0.5000000000, 0.5000000000, 0.0000000000},
        {6, 0.9670007152, 0.0329992848, 0.0000000000},
        {6, 0.8922417368, 0.1077582632, 0.0000000000},
        {6, 0.7826176635, 0.2173823365, 0.0000000000},
        {6, 0.6478790678, 0.3521209322, 0.0000000000},
        {3, 0.4232062312, 0.4232062312, 0.1535875376},
        {3, 0.2833924371, 0.2833924371, 0.4332151258},
        {3, 0.1330857076, 0.1330857076, 0.7338285848},
        {3, 0.0265250690, 0.0265250690, 0.9469498620},
        {6, 0.3934913008, 0.5472380443, 0.0592706549},
        {6, 0.2707097521, 0.5811217960, 0.1481684519},
        {6, 0.2462883939, 0.6991456238, 0.0545659823},
        {6, 0.1163195333, 0.8427538829, 0.0409265838}}}};
  return table;
}

std::vector<std::array<double, 2>> evenlySpacedSlots(int order) {
  std::vector<std::array<double, 2>> slots{{0.0, 0.0}, {1.0, 0.0}, {0.0, 1.0}};
  const double p = order;
  for (int t = 1; t < order; ++t) slots.push_back({t / p, 0.0});
  for (int t = 1; t < order; ++t) slots.push_back({1.0 - t / p, t / p});
  for (int t = 1; t < order; ++t) slots.push_back({0.0, 1.0 - t / p});
  for (int j = 1; j < order; ++j)
    for (int i = 1; i + j < order; ++i) slots.push_back({i / p, j / p});
  return slots;
}

}  // namespace

bool isInteriorTetMode(int p, int q, int r) {
  return p >= 2 && q >= 1 && r >= 1;
}
bool isInteriorPrismMode(int p, int q, int r) {
  return p >= 2 && q >= 2 && r >= 1;
}

double modifiedPrismMode(int p, int q, int r, const std::array<double, 3>& xi) {
  const double eta1 = 2.0 * (1.0 + xi[0]) / (1.0 - xi[2]) - 1.0;
  // Nektar++ completes the modes of the collapsed edge (vertices 4 to 5) so they do not
  // depend on eta1 there: the (0, q, 1) functions lose their (1 - eta1)/2 factor.
  if (p == 0 && r == 1) return modA(q, xi[1]) * 0.5 * (1.0 + xi[2]);
  return modA(p, eta1) * modA(q, xi[1]) * modB(p, r, xi[2]);
}

bool isInteriorPyramidMode(int p, int q, int r) {
  return p >= 2 && q >= 2 && r >= 1;
}

double modifiedPyramidMode(int p, int q, int r, const std::array<double, 3>& xi) {
  // The apex's function is (1 + xi3)/2 alone (Nektar++ adds it into all four base products).
  if (p == 0 && q == 0 && r == 1) return 0.5 * (1.0 + xi[2]);
  const double eta1 = 2.0 * (1.0 + xi[0]) / (1.0 - xi[2]) - 1.0;
  const double eta2 = 2.0 * (1.0 + xi[1]) / (1.0 - xi[2]) - 1.0;
  const double z = xi[2];
  double c = 0.0;  // ModifiedPyr_C's factor for (p, q, r)
  if (std::min(p, q) <= 1) {
    c = modB(std::max(p, q), r, z);
  } else {
    c = std::pow(0.5 * (1.0 - z), p + q - 2);
    if (r >= 1) c *= 0.5 * (1.0 + z) * jacobi(r - 1, 2.0 * (p + q) - 3.0, 1.0, z);
  }
  return modA(p, eta1) * modA(q, eta2) * c;
}

double modifiedTetMode(int p, int q, int r, const std::array<double, 4>& lambda) {
  const double s1 = lambda[0] + lambda[1], s2 = s1 + lambda[2];
  const double eta1 = (lambda[1] - lambda[0]) / s1;
  const double eta2 = (lambda[2] - s1) / s2;
  const double eta3 = 2.0 * lambda[3] - 1.0;
  // Nektar++ completes the modes that touch the collapsed top vertex and the collapsed edge
  // (vertex 2 to vertex 3) so they do not depend on eta1 (resp. eta2) there: the top vertex's
  // function is lambda_3, and the (0, 1, r) functions lose their (1 - eta1)/2 factor.
  if (p == 0 && q == 0 && r == 1) return lambda[3];
  if (p == 0 && q == 1) return 0.5 * (1.0 + eta2) * modB(1, r, eta3);
  return modA(p, eta1) * modB(p, q, eta2) * modB(p + q, r, eta3);
}

const ExpansionInteriorMap& interiorFromBoundary(CellType type, int order) {
  if (type != CellType::Triangle && type != CellType::Tetrahedron && type != CellType::Prism &&
      type != CellType::Pyramid)
    throw ParameterError("no modified-basis interior for " + cellShortName(type));
  if (order < 1 || order > kMaxOrder)
    throw ParameterError(cellShortName(type) + " order " + std::to_string(order) +
                         " is out of range");
  static std::mutex mutex;
  static std::map<std::pair<CellType, int>, std::unique_ptr<ExpansionInteriorMap>> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[{type, order}];
  if (!slot) slot = std::make_unique<ExpansionInteriorMap>(buildMap(type, order));
  return *slot;
}

bool hasTriElecPoints(int order) {
  return elecOrbits().count(order) != 0;
}

std::vector<std::array<double, 2>> triElecPoints(int order) {
  const auto it = elecOrbits().find(order);
  if (it == elecOrbits().end())
    throw ParameterError("no NodalTriElec points of order " + std::to_string(order));
  // Every distinct permutation of each orbit's barycentric coordinates (x = second, y = third).
  std::vector<std::array<double, 3>> all;
  for (const Orbit& o : it->second) {
    std::array<double, 3> b{o.a, o.b, o.c};
    std::sort(b.begin(), b.end());
    do all.push_back(b);
    while (std::next_permutation(b.begin(), b.end()));
  }
  std::vector<std::array<double, 2>> vertices(3), e01, e12, e20, inside;
  for (const auto& b : all) {
    const std::array<double, 2> xy{b[1], b[2]};
    if (b[0] == 1.0)
      vertices[0] = xy;
    else if (b[1] == 1.0)
      vertices[1] = xy;
    else if (b[2] == 1.0)
      vertices[2] = xy;
    else if (b[2] == 0.0)
      e01.push_back(xy);
    else if (b[0] == 0.0)
      e12.push_back(xy);
    else if (b[1] == 0.0)
      e20.push_back(xy);
    else
      inside.push_back(xy);
  }
  const auto byX = [](const auto& u, const auto& v) { return u[0] < v[0]; };
  const auto byY = [](const auto& u, const auto& v) { return u[1] < v[1]; };
  std::sort(e01.begin(), e01.end(), byX);
  std::sort(e12.begin(), e12.end(), byY);
  std::sort(e20.begin(), e20.end(), [&](const auto& u, const auto& v) { return byY(v, u); });
  // Rows of order - 2, order - 3, ... points by rising y, each by rising x (Nektar++ sorts
  // the interior points by y and cuts the sequence into rows of those sizes).
  std::sort(inside.begin(), inside.end(), byY);
  auto row = inside.begin();
  for (int size = order - 2; size > 0; --size) {
    if (row != inside.begin() && (*(row - 1))[1] == (*row)[1])
      throw MeshingError("the NodalTriElec rows of order " + std::to_string(order) +
                         " are ambiguous");
    std::sort(row, row + size, byX);
    row += size;
  }
  std::vector<std::array<double, 2>> points = vertices;
  for (const auto* part : {&e01, &e12, &e20, &inside})
    points.insert(points.end(), part->begin(), part->end());
  if (points.size() != static_cast<std::size_t>((order + 1) * (order + 2) / 2) ||
      e01.size() != e12.size() || e12.size() != e20.size())
    throw MeshingError("the NodalTriElec table of order " + std::to_string(order) +
                       " is inconsistent");
  return points;
}

const Eigen::MatrixXd& triElecToEvenlySpaced(int order) {
  static std::mutex mutex;
  static std::map<int, Eigen::MatrixXd> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  const auto found = cache.find(order);
  if (found != cache.end()) return found->second;
  const std::vector<std::array<double, 2>> from = triElecPoints(order);
  const std::vector<std::array<double, 2>> to = evenlySpacedSlots(order);
  const auto n = static_cast<Eigen::Index>(from.size());
  const auto basisAt = [&](const std::vector<std::array<double, 2>>& points) {
    Eigen::MatrixXd v(n, n);
    Eigen::VectorXd values;
    Eigen::MatrixXd gradients;
    for (Eigen::Index k = 0; k < n; ++k) {
      orthogonalBasis(CellType::Triangle, order, points[static_cast<std::size_t>(k)].data(), values,
                      gradients);
      v.row(k) = values.transpose();
    }
    return v;
  };
  // Values at `to` = Psi(to) V^-1 values at `from`, with V = Psi(from).
  const Eigen::MatrixXd v = basisAt(from);
  Eigen::MatrixXd m = v.transpose().fullPivLu().solve(basisAt(to).transpose()).transpose();
  return cache.emplace(order, std::move(m)).first->second;
}

}  // namespace homesh::nektar

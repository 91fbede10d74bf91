#include "element/symmetric_quadrature.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

namespace homesh {

namespace {

// One orbit: its weight and the first barycentric coordinates of one of its points (the last
// is 1 minus their sum); the orbit is every distinct permutation of the full tuple.
struct Orbit {
  double weight;
  std::array<double, 3> bary;
};

struct Table {
  CellType type;
  int degree;
  std::vector<Orbit> orbits;
};

// scripts/symmetric-quadrature.py's output.
const std::vector<Table>& tables() {
  static const std::vector<Table> t = {
      {CellType::Tetrahedron,
       5,
       {
           {0.012248840519393658,
            {9.2735250310891226e-2, 9.2735250310891226e-2, 9.2735250310891226e-2}},
           {0.018781320953002642,
            {3.1088591926330061e-1, 3.1088591926330061e-1, 3.1088591926330061e-1}},
           {0.0070910034628469111,
            {4.5503704125649649e-2, 4.5503704125649649e-2, 4.5449629587435035e-1}},
       }},
      {CellType::Tetrahedron,
       7,
       {
           {0.015914214910688475, {2.5e-1, 2.5e-1, 2.5e-1}},
           {0.0070549302016611715,
            {3.157011497782028e-1, 3.157011497782028e-1, 3.157011497782028e-1}},
           {0.0053161546388095967,
            {5.0489822598396369e-2, 5.0489822598396369e-2, 4.4951017740160363e-1}},
           {0.0013517951383172236,
            {2.1265472541483246e-2, 2.1265472541483246e-2, 1.4663881381848495e-1}},
           {0.0062011884547224369,
            {1.8883383102600105e-1, 1.8883383102600105e-1, 5.7517163758700002e-1}},
       }},
  };
  return t;
}

// Appends every distinct permutation of the orbit's tuple; a point's Cartesian coordinates
// are its barycentrics after the first (the vertex at the origin's), as the script has them.
void expand(const Orbit& o, int dim, QuadratureRule& rule) {
  std::vector<double> tuple(o.bary.begin(), o.bary.begin() + dim);
  double rest = 1.0;
  for (const double b : tuple) rest -= b;
  // The last coordinate equals another in some orbits ((a, a, 1/2 - a, 1/2 - a)): take that
  // one's value, so that rounding in the sum does not make two points of one.
  for (const double b : tuple)
    if (std::abs(rest - b) < 1e-14) rest = b;
  tuple.push_back(rest);
  std::sort(tuple.begin(), tuple.end());
  do {
    rule.points.insert(rule.points.end(), tuple.begin() + 1, tuple.end());
    rule.weights.push_back(o.weight);
  } while (std::next_permutation(tuple.begin(), tuple.end()));
}

}  // namespace

std::optional<QuadratureRule> symmetricRule(CellType type, int degree) {
  const Table* best = nullptr;
  for (const Table& t : tables())
    if (t.type == type && t.degree >= degree && (best == nullptr || t.degree < best->degree))
      best = &t;
  if (best == nullptr) return std::nullopt;
  QuadratureRule rule;
  rule.dim = cellDimension(type);
  rule.degree = best->degree;
  for (const Orbit& o : best->orbits) expand(o, rule.dim, rule);
  return rule;
}

}  // namespace homesh

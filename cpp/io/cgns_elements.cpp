#include "io/cgns_elements.hpp"

#include <cgnslib.h>

#include "core/error.hpp"
#include "element/node_ordering.hpp"

namespace homesh {
namespace {

struct Complete {
  CellType type;
  int codes[4];  // orders 1 to 4
};

const Complete kComplete[] = {
    {CellType::Line, {CGNS_ENUMV(BAR_2), CGNS_ENUMV(BAR_3), CGNS_ENUMV(BAR_4), CGNS_ENUMV(BAR_5)}},
    {CellType::Triangle,
     {CGNS_ENUMV(TRI_3), CGNS_ENUMV(TRI_6), CGNS_ENUMV(TRI_10), CGNS_ENUMV(TRI_15)}},
    {CellType::Quadrilateral,
     {CGNS_ENUMV(QUAD_4), CGNS_ENUMV(QUAD_9), CGNS_ENUMV(QUAD_16), CGNS_ENUMV(QUAD_25)}},
    {CellType::Tetrahedron,
     {CGNS_ENUMV(TETRA_4), CGNS_ENUMV(TETRA_10), CGNS_ENUMV(TETRA_20), CGNS_ENUMV(TETRA_35)}},
    {CellType::Pyramid,
     {CGNS_ENUMV(PYRA_5), CGNS_ENUMV(PYRA_14), CGNS_ENUMV(PYRA_30), CGNS_ENUMV(PYRA_55)}},
    {CellType::Prism,
     {CGNS_ENUMV(PENTA_6), CGNS_ENUMV(PENTA_18), CGNS_ENUMV(PENTA_40), CGNS_ENUMV(PENTA_75)}},
    {CellType::Hexahedron,
     {CGNS_ENUMV(HEXA_8), CGNS_ENUMV(HEXA_27), CGNS_ENUMV(HEXA_64), CGNS_ENUMV(HEXA_125)}},
};

// Types with nodes on edges (and faces) but not the complete set of their order.
const int kIncomplete[] = {
    CGNS_ENUMV(TRI_9),      CGNS_ENUMV(TRI_12),   CGNS_ENUMV(QUAD_8),   CGNS_ENUMV(QUAD_12),
    CGNS_ENUMV(QUAD_P4_16), CGNS_ENUMV(TETRA_16), CGNS_ENUMV(TETRA_22), CGNS_ENUMV(TETRA_34),
    CGNS_ENUMV(PYRA_13),    CGNS_ENUMV(PYRA_21),  CGNS_ENUMV(PYRA_29),  CGNS_ENUMV(PYRA_P4_29),
    CGNS_ENUMV(PYRA_50),    CGNS_ENUMV(PENTA_15), CGNS_ENUMV(PENTA_24), CGNS_ENUMV(PENTA_38),
    CGNS_ENUMV(PENTA_33),   CGNS_ENUMV(PENTA_66), CGNS_ENUMV(HEXA_20),  CGNS_ENUMV(HEXA_32),
    CGNS_ENUMV(HEXA_56),    CGNS_ENUMV(HEXA_44),  CGNS_ENUMV(HEXA_98)};

}  // namespace

void checkCgnsOrder(int order) {
  if (order < 1 || order > 4)
    throw ParameterError("CGNS names elements up to order 4, not order " + std::to_string(order) +
                         " (write .msh, .vtu or .xml for higher orders)");
}

int cgnsElementType(CellType type, int order) {
  checkCgnsOrder(order);
  for (const Complete& c : kComplete)
    if (c.type == type) return c.codes[order - 1];
  throw ParameterError("no CGNS element type for " + cellShortName(type));
}

CgnsTypeReading cgnsTypeReading(int code) {
  CgnsTypeReading r;
  for (const Complete& c : kComplete)
    for (int p = 1; p <= 4; ++p)
      if (c.codes[p - 1] == code) {
        r.type = c.type;
        r.order = p;
        return r;
      }
  for (const int incomplete : kIncomplete)
    if (incomplete == code) {
      r.why = "an incomplete (serendipity) element, not a complete Lagrange one";
      return r;
    }
  if (code == CGNS_ENUMV(NODE)) return r;
  if (code == CGNS_ENUMV(NGON_n) || code == CGNS_ENUMV(NFACE_n))
    r.why = "a polyhedral (face-based) section";
  else
    r.why = "not an element type HOMesh knows";
  return r;
}

std::string cgnsTypeName(int code) {
  if (code >= 0 && code < NofValidElementTypes) return ElementTypeName[code];
  return "type " + std::to_string(code);
}

std::unique_lock<std::mutex> holdCgnsLibrary() {
  static std::mutex library;
  return std::unique_lock<std::mutex>(library);
}

std::vector<int> cgnsPermutationFromGmsh(CellType type, int order) {
  return nodePermutationFromGmsh(type, order, NodeConvention::Cgns);
}

}  // namespace homesh

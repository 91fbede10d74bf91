// The boundary-layer split's worker (internal to boundary_layer/; splitBoundaryLayer runs it,
// layer_split.hpp states what the split promises). One LayerSplitter splits one macro mesh; its
// parts are defined by role: layer_split.cpp (the run, the wall-top pairs, the layer cells),
// layer_columns.cpp (each column's levels and shift), fan_split.cpp (the 2D fans' triangles),
// side_split.cpp (the layer's sides and climbs, projected onto the CAD) and
// first_layer_height.cpp (the first layer's height as measured, for the stats).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <map>
#include <numeric>
#include <optional>
#include <set>
#include <utility>
#include <vector>

#include "boundary_layer/layer_cells.hpp"
#include "boundary_layer/layer_normals.hpp"
#include "boundary_layer/layer_split.hpp"
#include "cad/cad_model.hpp"
#include "core/error.hpp"
#include "core/mesh.hpp"
#include "element/reference_element.hpp"

namespace homesh::layer_splitting {

constexpr std::int64_t kNone = std::numeric_limits<std::int64_t>::max();

// A node of the split layer: up to four columns (named by their macro top vertices, one per
// column even where a fan's columns share a wall vertex) with integer weights and the level
// across the layer, 0 (wall) .. n P (top). The weights are divided by their greatest common
// divisor, so that a node on a side a prism (weights summing to P) shares with a hexahedron
// (summing to P^2) has one key.
using NodeKey = std::array<std::int64_t, 9>;

inline NodeKey makeKey(std::array<std::pair<std::int64_t, int>, 4> w, std::int64_t level) {
  int common = 0;
  for (auto& [id, weight] : w) {
    if (weight == 0) id = kNone;
    common = std::gcd(common, weight);
  }
  std::sort(w.begin(), w.end());
  NodeKey k{};
  for (std::size_t i = 0; i < 4; ++i) {
    k[2 * i] = w[i].first;
    k[2 * i + 1] = w[i].first == kNone || common == 0 ? 0 : w[i].second / common;
  }
  k[8] = level;
  return k;
}

// How the column of nodes above the wall node at lattice point `c` (across coordinate 0) of
// cell `v` is split: at the levels z_0 = 0 < ... < z_n = 1 of the macro map, then shifted.
// The column runs straight from wall W to top T (blendLayerInteriors), so a level s lies at
// the height s H above the wall, H = (T - W) . n along the wall normal n (averaged over the
// cells at the node). With the grown heights H*, the first level is s_1 = z_1 H* / H, so the
// first layer has the height asked for even where the optimiser has moved the top; the
// others keep their progression in what remains. s_1 is kept within [z_1 / 2, 2 z_1] (and
// below the second level's share) so the levels stay ordered. Where the top has also slid
// sideways (T - W not along n) beyond the lean its lengthening gives it by design, the first
// level's node is moved by `shift` back by that excess, towards the normal through W (its
// tangential offset, s_1 times that of the top, would otherwise change the height measured
// between the nodes); at a sharp edge or corner, to the first layer's height from every wall;
// the shift fades linearly to 0 at wall and top. A node shared by neighbours takes the column
// of the first cell that reaches it.
struct Column {
  std::vector<double> levels;
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  double shiftAt(double s) const {
    const double s1 = levels[1];
    return s <= s1 ? s / s1 : levels.size() > 2 ? (1.0 - s) / (1.0 - s1) : 0.0;
  }
};

// A side quadrilateral's or climbing line's frame: which corner is the wall side's start,
// the lattice axis across the layer and whether it points away from the wall.
struct Frame {
  std::array<std::int64_t, 2> wall{};  // wall vertices at along = 0 and along = P
  int alongAxis = 0, acrossAxis = 1;
  bool away = true;
};

// One fan triangle (C, B, D) being split (splitFans): its vertices, the indices of its corner C
// on the wall and of the tops B and D (counter-clockwise) among them, the columns C -> B and
// C -> D, its nodes' coordinates (one row each) and its entity.
struct FanSector {
  const std::int64_t* v = nullptr;
  std::size_t a = 0, b = 0, d = 0;
  const Column* colB = nullptr;
  const Column* colD = nullptr;
  Eigen::MatrixXd x;
  int entity = 0;
};

// A point of a fan's sector: its reference coordinates and its integer coordinates (sigma, L):
// sigma 0 .. P from C -> B to C -> D, level L 0 .. n P; the corner has sigma -1.
struct SectorPoint {
  Eigen::Vector2d xi;
  int sigma, level;
};
// A triangle of the sector's split: the reference triangle's map restricted to it.
using SectorPiece = std::array<SectorPoint, 3>;

class LayerSplitter {
 public:
  LayerSplitter(const Mesh& macro, const std::vector<double>& z, const CadModel* cad,
                const LayerHeights* heights, LayerSplitStats& stats)
      : macro_(macro),
        z_(z),
        cad_(cad),
        grown_(heights != nullptr ? &heights->grown : nullptr),
        plain_(heights != nullptr ? heights->plain : std::set<std::int64_t>()),
        lengthened_(heights != nullptr ? heights->lengthened : std::map<std::int64_t, double>()),
        given_(heights != nullptr && !heights->levels.empty() ? &heights->levels : nullptr),
        stats_(stats),
        p_(macro.order),
        n_(static_cast<int>(z.size()) - 1) {
    if (n_ < 1) throw ParameterError("a layer split needs at least one layer");
    out_ = macro;
    out_.blocks.clear();
  }

  // The split mesh (splitBoundaryLayer), its stats in the `stats` given to the constructor.
  Mesh run();

 private:
  const Mesh& macro_;
  const std::vector<double>& z_;
  const CadModel* cad_;
  const std::vector<double>* grown_;  // wall vertex -> height as grown (NaN elsewhere), or null
  std::set<std::int64_t> plain_;      // wall nodes whose columns are split at z as they are
  std::map<std::int64_t, double> lengthened_;      // LayerHeights::lengthened
  const std::vector<std::vector<double>>* given_;  // LayerHeights::levels, or null
  LayerSplitStats& stats_;
  int p_, n_;
  Mesh out_;
  std::map<std::int64_t, NormalSum> normals_;  // column (top node) -> its cells' wall normals
  // wall vertex -> top vertex, but at a fan's corner (several columns on one wall vertex)
  std::map<std::int64_t, std::int64_t> topOf_;
  std::set<std::int64_t> fanCorners_, wallVertices_;
  std::vector<std::vector<char>> fans_;  // per macro block: its fan flags (empty: none there)
  std::vector<char> cellCorner_;         // per macro layer cell, in split order: at a sharp corner
  std::map<NodeKey, std::int64_t> nodes_;
  std::map<std::int64_t, double> height_;  // wall vertex -> macro layer height there
  std::vector<char> projected_;
  std::map<std::int64_t, Column> columns_;      // column (top node) -> how it is split
  static constexpr double kMaxShiftLean = 1.0;  // tangent of the lean: 45 degrees

  // The macro layer's cells (layer_cells.hpp: prisms and marked hexahedra in 3D,
  // quadrilaterals in 2D).
  bool layerCell(const ElementBlock& b) const { return isLayerCell(macro_, b); }
  static int wallVertices(const ElementBlock& b) { return layerShape(b.type).walls; }
  static std::int64_t topVertex(const ElementBlock& b, const std::int64_t* v, int k) {
    return layerShape(b.type).top(v, k);
  }

  // Records each layer cell's wall -> top vertex pairs (topOf_) and the heights (height_).
  void pairWallAndTop(const ElementBlock& b);
  // The vertex of fan triangle v on the wall (the fan's corner).
  int fanApex(const std::int64_t* v) const;
  // Splits the fan triangles of a triangle block (`fan`: layerFanTriangles), keeping the others.
  // Fan triangle (C, B, D) (C its corner on the wall, counter-clockwise) is a sector whose
  // columns C -> B and C -> D are split at their levels s_0 = 0 < ... < s_n = 1: the first
  // layer is the triangle (C, B_1, D_1), each further one the two triangles (B_k, B_k+1, D_k+1)
  // and (B_k, D_k+1, D_k) of the band between levels, every one the macro triangle's own map on
  // a triangle of its reference element (a sub-map: valid where the macro triangle is). A node
  // has integer coordinates (sigma, L) in the sector, sigma 0 .. P from C -> B to C -> D and
  // level L 0 .. n P, which name it (the columns' nodes are the layer cells' beside them).
  ElementBlock splitFans(const ElementBlock& b, const std::vector<char>& fan);
  // The sector of fan triangle v (entity `entity`): its corner, tops and columns.
  FanSector fanSector(const std::int64_t* v, int entity);
  // The node at lattice point `c` (row r of `values` and `points`) of `piece` of sector s: the
  // corner itself, a node of the macro triangle's top edge, or the node keyed by its columns'
  // weights and level (shared with the layer cells beside the fan), made on the macro map when new.
  std::int64_t fanNode(const FanSector& s, const SectorPiece& piece, int r, const LatticePoint& c,
                       const std::map<LatticePoint, int>& index, const Eigen::MatrixXd& values,
                       const Eigen::MatrixXd& points);

  // The reference coordinate across the layer of lattice level a (0 .. P) of thin layer k, at z.
  double zAt(int k, int a) const {
    const auto kk = static_cast<std::size_t>(k);
    return z_[kk] + (z_[kk + 1] - z_[kk]) * a / p_;
  }

  // How much the column on a wall vertex was lengthened (LayerHeights::lengthened, 1 where none),
  // and at a wall point: the wall vertices' interpolated with the weights `l`.
  double lengthenedAt(std::int64_t vertex) const;
  double lengthening(const std::int64_t* v, int walls, const double* l) const;
  // The height a wall point's layer was grown to: the wall vertices' heights (their columns'
  // lengths, over their lengthening) interpolated linearly (barycentric `l`), as
  // blendLayerInteriors places the tops; NaN without them.
  double grownHeight(const std::int64_t* v, int walls, const double* l) const;

  // The column above lattice point `c` of cell `v` (Column): made by the first cell reaching it.
  const Column& column(const ElementBlock& b, const std::map<LatticePoint, int>& index,
                       const std::int64_t* v, LatticePoint c);
  // The least move, within the span of `normals`, that brings the offset `x` to the height `h`
  // along each of them (the least-squares, least-norm solution of N s = h 1 - N x): at a sharp
  // edge or corner, what puts a level's node at one height from every wall.
  static Eigen::Vector3d towardsHeight(const NormalSum& normals, const Eigen::Vector3d& x,
                                       double h);
  // Sets the column's levels from its first, `wanted` kept within [s_1 / 2, 2 s_1] (and below the
  // second level's share), s its levels as they are: the others keep their progression in what
  // remains. Returns it.
  static double setFirstLevel(Column& col, double wanted);
  // The levels a column of cell v at wall weights `l` starts from: the given levels of the
  // cell's wall vertices interpolated (LayerHeights::levels), else z.
  std::vector<double> startLevels(const std::int64_t* v, int walls, const double* l) const;
  // A fan's column from its corner `corner` to `top` (straight, with no wall of its own): a
  // layer cell's where one shares it, else levels that give the first layer its grown height
  // along the column (z unchanged where the column is plain).
  const Column& fanColumn(std::int64_t corner, std::int64_t top);
  // Whether the walls of the cells sharing the column below `top` meet at a sharp corner.
  bool atCorner(std::int64_t top) const;

  // The first split layer's height along the wall normal at the wall's quadrature points
  // (exact to degree 2P), in stats_: its range and, with grown heights, its worst deviation
  // from z_1 H*.
  void measureFirstLayer();

  // The layer cells of block b split into n thin cells each, on their columns' levels.
  ElementBlock splitCells(const ElementBlock& b);

  // The frame of a side quadrilateral q, or of a climbing line l; nullopt when it is not a side
  // of the layer.
  std::optional<Frame> quadFrame(const std::int64_t* q) const;
  std::optional<Frame> lineFrame(const std::int64_t* l) const;
  // The side quadrilaterals or climbing lines of block b split along their layer's levels, their
  // new nodes projected onto the CAD; the others kept. Throws MeshingError for a side that does
  // not follow the prisms' wall-to-top pairs.
  ElementBlock splitSides(const ElementBlock& b);
  // Projects new node `id` onto CAD entity `entity` (dim 2: a face, 1: a curve) from the macro
  // node `hint`'s parameters; `wall` names the column's wall vertex (for the relative move).
  void project(std::int64_t id, int dim, int entity, std::int64_t hint, std::int64_t wall);
};

}  // namespace homesh::layer_splitting

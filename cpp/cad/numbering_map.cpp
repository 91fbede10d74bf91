#include "cad/numbering_map.hpp"

#include <BRepTools_History.hxx>
#include <BRep_Tool.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Shape.hxx>
#include <TopoDS_Vertex.hxx>

#include <algorithm>

#include "cad/cad_model.hpp"
#include "core/error.hpp"

namespace homesh {

namespace {

constexpr std::array<TopAbs_ShapeEnum, 4> kTypes = {TopAbs_VERTEX, TopAbs_EDGE, TopAbs_FACE,
                                                    TopAbs_SOLID};

TopTools_IndexedMapOfShape numbered(const TopoDS_Shape& shape, int dim) {
  TopTools_IndexedMapOfShape map;
  TopExp::MapShapes(shape, kTypes[static_cast<std::size_t>(dim)], map);
  return map;
}

// The final degenerated edges at the final image of degenerated edge `edge`'s vertex: a
// sphere's pole edge that a fuse merged with its twin without recording it in the history.
std::vector<int> degeneratedAtImage(const TopoDS_Edge& edge,
                                    const TopTools_IndexedMapOfShape& fromVertices,
                                    const std::vector<std::vector<int>>& vertexImages,
                                    const TopTools_IndexedMapOfShape& toEdges,
                                    const TopTools_IndexedMapOfShape& toVertices) {
  std::vector<int> out;
  const int v = fromVertices.FindIndex(TopExp::FirstVertex(edge));
  if (v == 0 || vertexImages[static_cast<std::size_t>(v - 1)].size() != 1) return out;
  const int image = vertexImages[static_cast<std::size_t>(v - 1)].front();
  for (int k = 1; k <= toEdges.Extent(); ++k) {
    const TopoDS_Edge& candidate = TopoDS::Edge(toEdges(k));
    if (BRep_Tool::Degenerated(candidate) &&
        toVertices.FindIndex(TopExp::FirstVertex(candidate)) == image)
      out.push_back(k);
  }
  return out;
}

}  // namespace

NumberingMap NumberingMap::identity(const TopoDS_Shape& shape) {
  NumberingMap m;
  for (int dim = 0; dim < 4; ++dim) {
    const int n = numbered(shape, dim).Extent();
    auto& images = m.images_[static_cast<std::size_t>(dim)];
    for (int i = 1; i <= n; ++i) images.push_back({i});
    m.finalCount_[static_cast<std::size_t>(dim)] = n;
  }
  return m;
}

NumberingMap NumberingMap::fromHistory(const TopoDS_Shape& before, const TopoDS_Shape& after,
                                       const BRepTools_History& history) {
  NumberingMap m;
  const TopTools_IndexedMapOfShape fromVertices = numbered(before, 0),
                                   toVertices = numbered(after, 0);
  for (int dim = 0; dim < 4; ++dim) {
    const TopTools_IndexedMapOfShape from = numbered(before, dim), to = numbered(after, dim);
    auto& images = m.images_[static_cast<std::size_t>(dim)];
    images.resize(static_cast<std::size_t>(from.Extent()));
    for (int i = 1; i <= from.Extent(); ++i) {
      std::vector<int>& finals = images[static_cast<std::size_t>(i - 1)];
      const TopoDS_Shape& s = from(i);
      if (!history.IsRemoved(s)) {
        const TopTools_ListOfShape& modified = history.Modified(s);
        if (modified.IsEmpty()) {
          if (const int k = to.FindIndex(s); k > 0) finals.push_back(k);
        } else {
          for (const TopoDS_Shape& piece : modified)
            if (const int k = to.FindIndex(piece); k > 0) finals.push_back(k);
        }
      }
      // (A fuse records a pole's degenerated edge merged with its twin as removed.)
      if (finals.empty() && dim == 1 && BRep_Tool::Degenerated(TopoDS::Edge(s)))
        finals = degeneratedAtImage(TopoDS::Edge(s), fromVertices, m.images_[0], to, toVertices);
      std::sort(finals.begin(), finals.end());
      finals.erase(std::unique(finals.begin(), finals.end()), finals.end());
    }
    m.finalCount_[static_cast<std::size_t>(dim)] = to.Extent();
  }
  return m;
}

bool NumberingMap::changed() const {
  for (std::size_t dim = 0; dim < 4; ++dim) {
    if (finalCount_[dim] != static_cast<int>(images_[dim].size())) return true;
    for (std::size_t i = 0; i < images_[dim].size(); ++i)
      if (images_[dim][i] != std::vector<int>{static_cast<int>(i) + 1}) return true;
  }
  return false;
}

int NumberingMap::originalCount(int dim) const {
  return static_cast<int>(images_.at(static_cast<std::size_t>(dim)).size());
}

const std::vector<int>& NumberingMap::finalNumbers(int dim, int index) const {
  const auto& images = images_.at(static_cast<std::size_t>(dim));
  if (index < 1 || index > static_cast<int>(images.size()))
    throw ParameterError(cadEntityName(dim, index) + " is not in the model (it has " +
                         std::to_string(images.size()) + ")");
  return images[static_cast<std::size_t>(index - 1)];
}

std::vector<int> NumberingMap::map(int dim, const std::vector<int>& indices,
                                   const std::string& what, const std::string& operation) const {
  std::vector<int> out;
  for (const int i : indices) {
    if (i < 1 || i > originalCount(dim))
      throw ParameterError(what + " " + std::to_string(i) + ": the model has " +
                           std::to_string(originalCount(dim)) + " (" + cadEntityName(dim, 1) +
                           " to " + cadEntityName(dim, originalCount(dim)) + ")");
    const std::vector<int>& finals = finalNumbers(dim, i);
    if (finals.empty())
      throw ParameterError(what + " " + std::to_string(i) + ": " + cadEntityName(dim, i) +
                           std::string(" was removed by ").append(operation));
    out.insert(out.end(), finals.begin(), finals.end());
  }
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

std::vector<std::pair<int, std::vector<int>>> NumberingMap::changes(int dim) const {
  std::vector<std::pair<int, std::vector<int>>> out;
  const auto& images = images_.at(static_cast<std::size_t>(dim));
  for (std::size_t i = 0; i < images.size(); ++i)
    if (images[i] != std::vector<int>{static_cast<int>(i) + 1})
      out.emplace_back(static_cast<int>(i) + 1, images[i]);
  return out;
}

}  // namespace homesh

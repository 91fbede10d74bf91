#include "cad/numbering_map.hpp"

#include <BRepGProp.hxx>
#include <BRepTools_History.hxx>
#include <BRep_Tool.hxx>
#include <GProp_GProps.hxx>
#include <TopExp.hxx>
#include <TopTools_IndexedMapOfShape.hxx>
#include <TopTools_ListOfShape.hxx>
#include <TopoDS.hxx>
#include <TopoDS_Edge.hxx>
#include <TopoDS_Shape.hxx>
#include <TopoDS_Vertex.hxx>

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

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

// Where a sub-shape is: a vertex's point, else the centre of mass with the length, area or
// volume.
struct Place {
  gp_Pnt centre;
  double measure = 0.0;
};

Place placeOf(const TopoDS_Shape& shape, int dim) {
  if (dim == 0) return {BRep_Tool::Pnt(TopoDS::Vertex(shape)), 0.0};
  GProp_GProps props;
  if (dim == 1)
    BRepGProp::LinearProperties(shape, props);
  else if (dim == 2)
    BRepGProp::SurfaceProperties(shape, props);
  else
    BRepGProp::VolumeProperties(shape, props);
  return {props.CentreOfMass(), std::abs(props.Mass())};
}

// The sub-shapes of `after` found by place (NumberingMap::fromHistory's matchTolerance), their
// places measured once, when the first is looked for.
class PlaceMatcher {
 public:
  PlaceMatcher(const TopTools_IndexedMapOfShape& after, int dim, double tolerance)
      : after_(after), dim_(dim), tolerance_(tolerance) {}

  // The number in `after` of the one sub-shape at `shape`'s place (the nearest of several), 0
  // when none is. Lengths, areas and volumes agree to 1e-3: a fix that merged a small edge
  // into its neighbour lengthened it by that edge.
  int find(const TopoDS_Shape& shape) {
    if (!measured_) {
      for (int k = 1; k <= after_.Extent(); ++k) places_.push_back(placeOf(after_(k), dim_));
      measured_ = true;
    }
    const Place p = placeOf(shape, dim_);
    int best = 0;
    double nearest = std::numeric_limits<double>::infinity();
    for (std::size_t k = 0; k < places_.size(); ++k) {
      const Place& q = places_[k];
      const double d = p.centre.Distance(q.centre);
      if (d > tolerance_ || d >= nearest ||
          std::abs(p.measure - q.measure) > 1e-3 * std::max(p.measure, q.measure))
        continue;
      nearest = d;
      best = static_cast<int>(k) + 1;
    }
    return best;
  }

 private:
  const TopTools_IndexedMapOfShape& after_;
  int dim_;
  double tolerance_;
  std::vector<Place> places_;
  bool measured_ = false;
};

}  // namespace

NumberingMap NumberingMap::identity(const TopoDS_Shape& shape) {
  NumberingMap m;
  for (int dim = 0; dim < 4; ++dim) {
    const int n = numbered(shape, dim).Extent();
    auto& images = m.images_[static_cast<std::size_t>(dim)];
    for (int i = 1; i <= n; ++i) images.push_back({i});
    m.removedBy_[static_cast<std::size_t>(dim)].resize(static_cast<std::size_t>(n));
    m.finalCount_[static_cast<std::size_t>(dim)] = n;
  }
  return m;
}

NumberingMap NumberingMap::fromHistory(const TopoDS_Shape& before, const TopoDS_Shape& after,
                                       const BRepTools_History& history,
                                       const std::string& operation, double matchTolerance) {
  NumberingMap m;
  const TopTools_IndexedMapOfShape fromVertices = numbered(before, 0),
                                   toVertices = numbered(after, 0);
  for (int dim = 0; dim < 4; ++dim) {
    const TopTools_IndexedMapOfShape from = numbered(before, dim), to = numbered(after, dim);
    auto& images = m.images_[static_cast<std::size_t>(dim)];
    images.resize(static_cast<std::size_t>(from.Extent()));
    m.removedBy_[static_cast<std::size_t>(dim)].resize(static_cast<std::size_t>(from.Extent()));
    PlaceMatcher byPlace(to, dim, matchTolerance);
    for (int i = 1; i <= from.Extent(); ++i) {
      std::vector<int>& finals = images[static_cast<std::size_t>(i - 1)];
      const TopoDS_Shape& s = from(i);
      const bool removed = history.IsRemoved(s);
      if (!removed) {
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
      if (finals.empty() && !removed && matchTolerance > 0.0)
        if (const int k = byPlace.find(s); k > 0) finals.push_back(k);
      if (finals.empty()) m.removedBy_[static_cast<std::size_t>(dim)][i - 1] = operation;
      std::sort(finals.begin(), finals.end());
      finals.erase(std::unique(finals.begin(), finals.end()), finals.end());
    }
    m.finalCount_[static_cast<std::size_t>(dim)] = to.Extent();
  }
  return m;
}

NumberingMap NumberingMap::then(const NumberingMap& next) const {
  NumberingMap m;
  for (std::size_t dim = 0; dim < 4; ++dim) {
    if (next.originalCount(static_cast<int>(dim)) != finalCount_[dim])
      throw Error("internal: numbering maps composed out of order");
    m.images_[dim].resize(images_[dim].size());
    m.removedBy_[dim] = removedBy_[dim];
    for (std::size_t i = 0; i < images_[dim].size(); ++i) {
      std::vector<int>& finals = m.images_[dim][i];
      for (const int k : images_[dim][i]) {
        const std::vector<int>& more = next.images_[dim][static_cast<std::size_t>(k - 1)];
        finals.insert(finals.end(), more.begin(), more.end());
      }
      std::sort(finals.begin(), finals.end());
      finals.erase(std::unique(finals.begin(), finals.end()), finals.end());
      if (finals.empty() && m.removedBy_[dim][i].empty() && !images_[dim][i].empty())
        m.removedBy_[dim][i] =
            next.removedBy_[dim][static_cast<std::size_t>(images_[dim][i].front() - 1)];
    }
    m.finalCount_[dim] = next.finalCount_[dim];
  }
  return m;
}

std::string NumberingMap::toText() const {
  std::ostringstream out;
  for (std::size_t dim = 0; dim < 4; ++dim) {
    out << dim << ' ' << images_[dim].size() << ' ' << finalCount_[dim] << '\n';
    for (std::size_t i = 0; i < images_[dim].size(); ++i) {
      for (std::size_t k = 0; k < images_[dim][i].size(); ++k)
        out << (k == 0 ? "" : " ") << images_[dim][i][k];
      out << '|' << removedBy_[dim][i] << '\n';
    }
  }
  return out.str();
}

NumberingMap NumberingMap::fromText(const std::string& text) {
  NumberingMap m;
  std::istringstream in(text);
  std::string line;
  int lineNumber = 0;
  const auto fail = [&](const std::string& why) {
    throw ParameterError("numbering map: line " + std::to_string(lineNumber) + ": " + why);
  };
  for (std::size_t dim = 0; dim < 4; ++dim) {
    ++lineNumber;
    std::size_t d = 0, originals = 0;
    int finals = -1;
    if (!std::getline(in, line) || !(std::istringstream(line) >> d >> originals >> finals) ||
        d != dim || finals < 0)
      fail("expected \"" + std::to_string(dim) + " ORIGINAL FINAL\"");
    m.finalCount_[dim] = finals;
    for (std::size_t i = 0; i < originals; ++i) {
      ++lineNumber;
      if (!std::getline(in, line)) fail("the map ends early");
      const std::size_t bar = line.find('|');
      if (bar == std::string::npos) fail("no '|'");
      std::istringstream numbers(line.substr(0, bar));
      std::vector<int> images;
      for (std::string token; numbers >> token;) {
        std::size_t used = 0;
        long k = 0;
        try {
          k = std::stol(token, &used);
        } catch (const std::exception&) {  // (not a number, or out of range)
          used = 0;
        }
        if (used != token.size()) fail("not a number");
        if (k < 1 || k > finals) fail(token + " is not a final number");
        if (!images.empty() && k <= images.back()) fail("final numbers not ascending");
        images.push_back(static_cast<int>(k));
      }
      m.images_[dim].push_back(std::move(images));
      m.removedBy_[dim].push_back(line.substr(bar + 1));
    }
  }
  return m;
}

bool NumberingMap::changed() const {
  for (int dim = 0; dim < 4; ++dim)
    if (changed(dim)) return true;
  return false;
}

bool NumberingMap::changed(int dim) const {
  const auto& images = images_.at(static_cast<std::size_t>(dim));
  if (finalCount_.at(static_cast<std::size_t>(dim)) != static_cast<int>(images.size())) return true;
  for (std::size_t i = 0; i < images.size(); ++i)
    if (images[i] != std::vector<int>{static_cast<int>(i) + 1}) return true;
  return false;
}

int NumberingMap::originalCount(int dim) const {
  return static_cast<int>(images_.at(static_cast<std::size_t>(dim)).size());
}

int NumberingMap::finalCount(int dim) const {
  return finalCount_.at(static_cast<std::size_t>(dim));
}

std::string NumberingMap::givenNames(int dim, int index) const {
  if (!changed(dim)) return "";
  const std::vector<int> given =
      index >= 1 && index <= finalCount(dim) ? originals(dim, index) : std::vector<int>{};
  if (given.empty()) {
    static const char* const kinds[] = {"vertex", "edge", "face", "solid"};
    return std::string("no numbered ") + kinds[std::clamp(dim, 0, 3)];
  }
  std::string text;
  for (std::size_t i = 0; i < given.size(); ++i) {
    if (i > 0) text += i + 1 == given.size() ? " and " : ", ";
    text += cadEntityName(dim, given[i]);
  }
  return text;
}

std::vector<int> NumberingMap::originals(int dim, int index) const {
  std::vector<int> out;
  const auto& images = images_.at(static_cast<std::size_t>(dim));
  for (std::size_t i = 0; i < images.size(); ++i)
    if (std::binary_search(images[i].begin(), images[i].end(), index))
      out.push_back(static_cast<int>(i) + 1);
  return out;
}

const std::string& NumberingMap::removedBy(int dim, int index) const {
  finalNumbers(dim, index);  // (checks the number)
  return removedBy_.at(static_cast<std::size_t>(dim))[static_cast<std::size_t>(index - 1)];
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
    if (finals.empty()) {
      const std::string& by = removedBy(dim, i);
      throw ParameterError(what + " " + std::to_string(i) + ": " + cadEntityName(dim, i) +
                           " was removed by " + (by.empty() ? operation : by));
    }
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

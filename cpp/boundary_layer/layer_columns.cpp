#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <map>
#include <utility>
#include <vector>

#include "boundary_layer/layer_splitter.hpp"

namespace homesh::layer_splitting {

double LayerSplitter::lengthenedAt(std::int64_t vertex) const {
  const auto it = lengthened_.find(vertex);
  return it == lengthened_.end() ? 1.0 : it->second;
}

double LayerSplitter::lengthening(const std::int64_t* v, int walls, const double* l) const {
  double s = 0.0;
  for (int k = 0; k < walls; ++k) s += l[k] * lengthenedAt(v[k]);
  return s;
}

double LayerSplitter::grownHeight(const std::int64_t* v, int walls, const double* l) const {
  if (grown_ == nullptr) return std::nan("");
  double h = 0.0;
  for (int k = 0; k < walls; ++k) {
    const auto id = static_cast<std::size_t>(v[k]);
    h += l[k] * (id < grown_->size() ? (*grown_)[id] : std::nan("")) / lengthenedAt(v[k]);
  }
  return h;
}

const Column& LayerSplitter::column(const ElementBlock& b, const std::map<LatticePoint, int>& index,
                                    const std::int64_t* v, LatticePoint c) {
  const LayerShape shape = layerShape(b.type);
  const std::size_t across = shape.across;
  c[across] = 0;
  const std::int64_t w = v[index.at(c)];
  c[across] = p_;
  const std::int64_t topNode = v[index.at(c)];
  const auto found = columns_.find(topNode);
  if (found != columns_.end()) return found->second;
  Column col;
  const std::array<double, 4> l =
      shape.weights(double(c[0]) / p_, across == 2 ? double(c[1]) / p_ : 0.0);
  // (A plain column keeps z: its thin cells are then sub-maps of the macro cell.)
  col.levels = plain_.count(topNode) != 0 ? z_ : startLevels(v, shape.walls, l.data());
  const double target = grownHeight(v, shape.walls, l.data());
  const auto normal = normals_.find(topNode);
  if (n_ > 1 && plain_.count(topNode) == 0 && std::isfinite(target) && target > 0.0 &&
      normal != normals_.end() && normal->second.sum.norm() > 0.0) {
    const Eigen::Vector3d x0(&macro_.xyz[3 * static_cast<std::size_t>(w)]);
    const Eigen::Vector3d rise =
        Eigen::Vector3d(&macro_.xyz[3 * static_cast<std::size_t>(topNode)]) - x0;
    const Eigen::Vector3d n = normal->second.sum.normalized();
    // A lengthened column at a sharp edge or corner leans between its walls by design and ends
    // at the height from each: measured along each wall's normal, unshifted.
    if (normal->second.sharp() && lengthening(v, shape.walls, l.data()) > 1.0 + 1e-9) {
      const double height = normal->second.minAlong(rise);
      if (height > 0.0) setFirstLevel(col, z_[1] * target / height);
      return columns_.emplace(topNode, std::move(col)).first->second;
    }
    const double height = rise.dot(n);
    if (height > 0.0) {
      const double first = setFirstLevel(col, z_[1] * target / height);
      // Only where the column leans by less than kMaxShiftLean: at a sharp corner the column
      // follows the corner's bisector by design, and no shift gives both walls their height.
      // (Where the adjusted column makes a thin cell invalid, the pipeline splits it plain.)
      const Eigen::Vector3d lean = rise - height * n;
      if (lean.norm() < kMaxShiftLean * height) col.shift = -first * lean;
    }
  }
  return columns_.emplace(topNode, std::move(col)).first->second;
}

double LayerSplitter::setFirstLevel(Column& col, double wanted) {
  const std::vector<double> s = col.levels;
  const double s1 = s[1];
  const double first = std::clamp(wanted, 0.5 * s1, std::min(2.0 * s1, 0.5 * (s1 + s[2])));
  for (std::size_t k = 1; k + 1 < col.levels.size(); ++k)
    col.levels[k] = first + (s[k] - s1) * (1.0 - first) / (1.0 - s1);
  return first;
}

std::vector<double> LayerSplitter::startLevels(const std::int64_t* v, int walls,
                                               const double* l) const {
  if (given_ == nullptr) return z_;
  std::vector<double> levels(z_.size(), 0.0);
  for (int k = 0; k < walls; ++k) {
    const auto id = static_cast<std::size_t>(v[k]);
    if (id >= given_->size() || (*given_)[id].size() != z_.size()) return z_;
    for (std::size_t i = 0; i < levels.size(); ++i) levels[i] += l[k] * (*given_)[id][i];
  }
  return levels;
}

const Column& LayerSplitter::fanColumn(std::int64_t corner, std::int64_t top) {
  const auto found = columns_.find(top);
  if (found != columns_.end()) return found->second;
  Column col;
  col.levels = z_;
  const auto c = static_cast<std::size_t>(corner);
  const double target = grown_ != nullptr && c < grown_->size() ? (*grown_)[c] : std::nan("");
  const double height = (Eigen::Vector3d(&macro_.xyz[3 * static_cast<std::size_t>(top)]) -
                         Eigen::Vector3d(&macro_.xyz[3 * c]))
                            .norm();
  if (n_ > 1 && plain_.count(top) == 0 && std::isfinite(target) && target > 0.0 && height > 0.0)
    setFirstLevel(col, z_[1] * target / height);
  return columns_.emplace(top, std::move(col)).first->second;
}

bool LayerSplitter::atCorner(std::int64_t top) const {
  const auto n = normals_.find(top);
  return n != normals_.end() && n->second.sharp();
}

}  // namespace homesh::layer_splitting

#include "optimise/certified_quality.hpp"

#include <algorithm>

#include "quality/bezier_jacobian.hpp"

namespace homesh::optimiser {

namespace {

// The tolerance of the first, coarse Jacobian bounds of a sweep's quality check (evaluate()).
constexpr double kCoarseTolerance = 0.1;

}  // namespace

template <int D>
void CertifiedQuality<D>::measureInput(const QualitySummary* startQuality) {
  const std::size_t total = mesh_.totalElements;
  scaled_.resize(total);
  estimate_.resize(total);
  tight_.assign(total, 0);
  validity_.resize(total);
  std::vector<std::size_t> all(total);
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  // Build the shared Bezier tables once before the threads need them.
  for (const Block<D>& b : mesh_.blocks) elementJacobianBounds(mesh_.mesh, *b.cells, 0);
  if (!takeStartQuality(startQuality)) evaluate(all);
}

template <int D>
bool CertifiedQuality<D>::takeStartQuality(const QualitySummary* q) {
  const std::size_t total = mesh_.totalElements;
  if (q == nullptr || mesh_.converting || q->scaledJacobian.size() != total ||
      q->scaledJacobianUpper.size() != total || q->validity.size() != total)
    return false;
  scaled_ = q->scaledJacobian;
  estimate_ = q->scaledJacobianUpper;
  validity_ = q->validity;
  tight_.assign(total, 1);
  return true;
}

template <int D>
void CertifiedQuality<D>::evaluate(const std::vector<std::size_t>& elements) {
  bound(elements, kCoarseTolerance);
  for (const std::size_t i : elements) tight_[i] = 0;
  double threshold = *std::min_element(estimate_.begin(), estimate_.end()) + options_.focusMargin;
  if (options_.regionThreshold) threshold = std::max(threshold, *options_.regionThreshold);
  std::vector<std::size_t> refine;
  for (std::size_t i = 0; i < mesh_.totalElements; ++i)
    if (tight_[i] == 0 && !(scaled_[i] >= threshold)) refine.push_back(i);
  bound(refine, kJacobianBoundTolerance);
  for (const std::size_t i : refine) tight_[i] = 1;
}

template <int D>
void CertifiedQuality<D>::bound(const std::vector<std::size_t>& elements, double tolerance) {
  owners_.forEachOwned(elements, 16, [&](std::size_t i, int /*thread*/) {
    const std::size_t g = elements[i];
    const auto [bi, e] = mesh_.locate(g);
    const JacobianBounds bounds =
        elementJacobianBounds(mesh_.mesh, *mesh_.blocks[bi].cells, e, tolerance);
    scaled_[g] = bounds.scaledJacobian();
    estimate_[g] = bounds.scaledJacobianEstimate();
    validity_[g] = bounds.validity;
  });
}

template <int D>
IterationRecord CertifiedQuality<D>::summarise(int iteration, double moved,
                                               Clock::time_point t0) const {
  IterationRecord r;
  r.iteration = iteration;
  r.worst = *std::min_element(scaled_.begin(), scaled_.end());
  for (const Validity v : validity_) {
    if (v == Validity::Invalid) ++r.invalid;
    if (v == Validity::Undecided) ++r.undecided;
  }
  r.maxDisplacement = moved;
  r.seconds = since(t0);
  return r;
}

template class CertifiedQuality<2>;
template class CertifiedQuality<3>;

}  // namespace homesh::optimiser

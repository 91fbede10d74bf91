#include "quality/bernstein.hpp"

#include <cmath>
#include <memory>
#include <mutex>
#include <string>

#include "core/error.hpp"

namespace homesh {
namespace {

double factorial(int n) {
  return std::tgamma(n + 1.0);
}

// Multinomial m! / (a0! a1! ... ad!) with a0 = m - sum(a).
double multinomial(int m, const int* a, int d) {
  double v = factorial(m);
  int a0 = m;
  for (int k = 0; k < d; ++k) {
    v /= factorial(a[k]);
    a0 -= a[k];
  }
  return v / factorial(a0);
}

// Stored multi-indices (a1..ad, sum <= m) of one simplex factor.
std::vector<std::vector<int>> factorLattice(int d, int m) {
  std::vector<std::vector<int>> out;
  for (int k = 0; k <= (d > 2 ? m : 0); ++k)
    for (int j = 0; j + k <= (d > 1 ? m : 0); ++j)
      for (int i = 0; i + j + k <= m; ++i) {
        std::vector<int> a{i};
        if (d > 1) a.push_back(j);
        if (d > 2) a.push_back(k);
        out.push_back(a);
      }
  return out;
}

}  // namespace

BernsteinSpace::BernsteinSpace(BernsteinFactors factors) : factors_(std::move(factors)) {
  indices_ = {{}};
  for (const auto& [d, m] : factors_) {
    if (m < 0) throw Error("Bernstein space with a negative degree");
    dim_ += d;
    std::vector<std::vector<int>> next;
    for (const std::vector<int>& a : factorLattice(d, m))
      for (const std::vector<int>& prefix : indices_) {
        std::vector<int> flat = prefix;
        flat.insert(flat.end(), a.begin(), a.end());
        next.push_back(flat);
      }
    indices_ = std::move(next);
  }
  for (int j = 0; j < size(); ++j) position_[indices_[j]] = j;
}

const BernsteinSpace& BernsteinSpace::get(const BernsteinFactors& factors) {
  static std::mutex mutex;
  static std::map<BernsteinFactors, std::unique_ptr<BernsteinSpace>> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  auto& slot = cache[factors];
  if (!slot) slot = std::make_unique<BernsteinSpace>(factors);
  return *slot;
}

int BernsteinSpace::indexOf(const std::vector<int>& flat) const {
  const auto it = position_.find(flat);
  if (it == position_.end()) throw Error("Bernstein space: multi-index outside the space");
  return it->second;
}

double BernsteinSpace::basis(int j, const double* x) const {
  double value = 1.0;
  int col = 0;
  for (const auto& [d, m] : factors_) {
    const int* a = &indices_[j][col];
    double l0 = 1.0;
    int a0 = m;
    double term = multinomial(m, a, d);
    for (int k = 0; k < d; ++k) {
      term *= std::pow(x[col + k], a[k]);
      l0 -= x[col + k];
      a0 -= a[k];
    }
    value *= term * std::pow(std::max(l0, 0.0), a0);
    col += d;
  }
  return value;
}

double BernsteinSpace::multinomialWeight(int j) const {
  double w = 1.0;
  int col = 0;
  for (const auto& [d, m] : factors_) {
    w *= multinomial(m, &indices_[j][col], d);
    col += d;
  }
  return w;
}

bool BernsteinSpace::isCorner(int j) const {
  int col = 0;
  for (const auto& [d, m] : factors_) {
    int sum = 0, nonzero = 0;
    for (int k = 0; k < d; ++k) {
      sum += indices_[j][col + k];
      nonzero += indices_[j][col + k] > 0 ? 1 : 0;
    }
    // A corner of a simplex: all weight on one barycentric entry.
    if (!(sum == 0 || (sum == m && nonzero == 1))) return false;
    col += d;
  }
  return true;
}

Eigen::VectorXd BernsteinSpace::point(int j) const {
  Eigen::VectorXd p(dim_);
  int col = 0;
  for (const auto& [d, m] : factors_) {
    for (int k = 0; k < d; ++k)
      p(col + k) = m > 0 ? static_cast<double>(indices_[j][col + k]) / m : 0.0;
    col += d;
  }
  return p;
}

BernsteinFactors BernsteinSpace::derivativeFactors(int k) const {
  BernsteinFactors out = factors_;
  int col = 0;
  for (auto& [d, m] : out) {
    if (k < col + d) {
      m -= 1;
      return out;
    }
    col += d;
  }
  throw Error("Bernstein derivative along a coordinate outside the space");
}

Eigen::VectorXd BernsteinSpace::derivative(int k, const Eigen::VectorXd& coeffs) const {
  const BernsteinSpace& lower = get(derivativeFactors(k));
  // The factor holding coordinate k and its degree.
  int col = 0, degree = 0;
  for (const auto& [d, m] : factors_) {
    if (k < col + d) {
      degree = m;
      break;
    }
    col += d;
  }
  Eigen::VectorXd out(lower.size());
  for (int b = 0; b < lower.size(); ++b) {
    std::vector<int> plus = lower.indices_[b];
    const int base = indexOf(plus);  // same stored indices: one more in the implicit entry
    plus[k] += 1;
    out(b) = degree * (coeffs(indexOf(plus)) - coeffs(base));
  }
  return out;
}

BernsteinFactors BernsteinSpace::productFactors(const BernsteinFactors& a,
                                                const BernsteinFactors& b) {
  if (a.size() != b.size()) throw Error("Bernstein product of different shapes");
  BernsteinFactors out = a;
  for (std::size_t f = 0; f < a.size(); ++f) {
    if (a[f].first != b[f].first) throw Error("Bernstein product of different shapes");
    out[f].second += b[f].second;
  }
  return out;
}

namespace {

struct ProductTerm {
  int a, b, c;
  double weight;
};

// The (a, b) -> c terms of a product of two spaces, cached.
const std::vector<ProductTerm>& productTable(const BernsteinSpace& sa, const BernsteinSpace& sb) {
  static std::mutex mutex;
  static std::map<std::pair<BernsteinFactors, BernsteinFactors>, std::vector<ProductTerm>> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  auto& table = cache[{sa.factors(), sb.factors()}];
  if (!table.empty()) return table;
  const BernsteinSpace& sc =
      BernsteinSpace::get(BernsteinSpace::productFactors(sa.factors(), sb.factors()));
  table.reserve(static_cast<std::size_t>(sa.size()) * sb.size());
  std::vector<int> flat(sc.dim());
  for (int i = 0; i < sa.size(); ++i)
    for (int j = 0; j < sb.size(); ++j) {
      for (int k = 0; k < sc.dim(); ++k) flat[k] = sa.multiIndex(i)[k] + sb.multiIndex(j)[k];
      const int c = sc.indexOf(flat);
      table.push_back(
          {i, j, c, sa.multinomialWeight(i) * sb.multinomialWeight(j) / sc.multinomialWeight(c)});
    }
  return table;
}

}  // namespace

Eigen::VectorXd BernsteinSpace::multiply(const Eigen::VectorXd& a, const BernsteinSpace& other,
                                         const Eigen::VectorXd& b) const {
  const BernsteinSpace& result = get(productFactors(factors_, other.factors_));
  Eigen::VectorXd c = Eigen::VectorXd::Zero(result.size());
  for (const ProductTerm& t : productTable(*this, other)) c(t.c) += t.weight * a(t.a) * b(t.b);
  return c;
}

}  // namespace homesh

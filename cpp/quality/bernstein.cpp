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
  // Lines parallel to each edge of each factor: group functions by their other entries.
  int col = 0;
  for (std::size_t f = 0; f < factors_.size(); ++f) {
    const auto [d, m] = factors_[f];
    const auto entry = [&, d = d, m = m](const std::vector<int>& flat, int slot) {
      if (slot > 0) return flat[col + slot - 1];
      int rest = m;
      for (int k = 0; k < d; ++k) rest -= flat[col + k];
      return rest;
    };
    for (int i = 0; i <= d; ++i)
      for (int j = i + 1; j <= d; ++j) {
        std::map<std::vector<int>, std::map<int, int>> lines;  // other entries -> (entry i, fn)
        for (int fn = 0; fn < size(); ++fn) {
          std::vector<int> key = indices_[fn];
          for (int k = 0; k <= d; ++k)
            key.push_back(k == i || k == j ? -1 : entry(indices_[fn], k));
          for (int k = 0; k < d; ++k) key[col + k] = -1;
          lines[key][entry(indices_[fn], i)] = fn;
        }
        EdgeLines e;
        e.factor = static_cast<int>(f);
        e.i = i;
        e.j = j;
        for (const auto& [key, line] : lines) {
          e.start.push_back(static_cast<int>(e.index.size()));
          for (const auto& [ai, fn] : line) e.index.push_back(fn);
        }
        e.start.push_back(static_cast<int>(e.index.size()));
        edgeLines_.push_back(std::move(e));
      }
    col += d;
  }
}

void BernsteinSpace::bisect(const EdgeLines& edge, const double* coeffs, double* keepJ,
                            double* keepI) {
  double b[64] = {};
  for (std::size_t l = 0; l + 1 < edge.start.size(); ++l) {
    const int* idx = &edge.index[edge.start[l]];
    const int s = edge.start[l + 1] - edge.start[l] - 1;  // the line's degree
    if (s < 0) continue;
    if (s >= 64) throw Error("Bernstein bisection: degree too high");
    for (int k = 0; k <= s; ++k) b[k] = coeffs[idx[k]];
    keepJ[idx[0]] = b[0];
    keepI[idx[s]] = b[s];
    for (int level = 1; level <= s; ++level) {
      for (int k = 0; k <= s - level; ++k) b[k] = 0.5 * (b[k] + b[k + 1]);
      keepJ[idx[level]] = b[0];
      keepI[idx[s - level]] = b[s - level];
    }
  }
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

const std::vector<BernsteinSpace::ProductTerm>& BernsteinSpace::productTerms(
    const BernsteinSpace& other) const {
  static std::mutex mutex;
  static std::map<std::pair<BernsteinFactors, BernsteinFactors>, std::vector<ProductTerm>> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  auto& table = cache[{factors_, other.factors_}];
  if (!table.empty()) return table;
  const BernsteinSpace& sc = get(productFactors(factors_, other.factors_));
  table.reserve(static_cast<std::size_t>(size()) * other.size());
  std::vector<int> flat(sc.dim());
  for (int i = 0; i < size(); ++i)
    for (int j = 0; j < other.size(); ++j) {
      for (int k = 0; k < sc.dim(); ++k) flat[k] = indices_[i][k] + other.indices_[j][k];
      const int c = sc.indexOf(flat);
      table.push_back(
          {i, j, c, multinomialWeight(i) * other.multinomialWeight(j) / sc.multinomialWeight(c)});
    }
  return table;
}

Eigen::VectorXd BernsteinSpace::multiply(const Eigen::VectorXd& a, const BernsteinSpace& other,
                                         const Eigen::VectorXd& b) const {
  const BernsteinSpace& result = get(productFactors(factors_, other.factors_));
  Eigen::VectorXd c = Eigen::VectorXd::Zero(result.size());
  for (const ProductTerm& t : productTerms(other)) c(t.c) += t.weight * a(t.a) * b(t.b);
  return c;
}

}  // namespace homesh

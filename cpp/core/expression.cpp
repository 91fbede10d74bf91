#include "core/expression.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <utility>

#include "core/error.hpp"

namespace homesh {
namespace {

using Node = Expression::Node;
using Op = Node::Op;

const char* const kFunctions1[] = {"sin", "cos", "tan", "exp", "log", "sqrt", "abs"};
const char* const kFunctions2[] = {"min", "max"};

double call1(int f, double a) {
  switch (f) {
    case 0:
      return std::sin(a);
    case 1:
      return std::cos(a);
    case 2:
      return std::tan(a);
    case 3:
      return std::exp(a);
    case 4:
      return std::log(a);
    case 5:
      return std::sqrt(a);
    default:
      return std::fabs(a);
  }
}

// Recursive descent: sum := product (('+'|'-') product)*; product := unary (('*'|'/') unary)*;
// unary := '-' unary | '+' unary | power; power := atom ('^' unary)?.
class Parser {
 public:
  Parser(const std::string& text, const std::string& what, std::vector<Node>& nodes)
      : s_(text), what_(what), nodes_(nodes) {}

  int run() {
    const int root = sum();
    skip();
    if (pos_ != s_.size()) fail("unexpected '" + std::string(1, s_[pos_]) + "'");
    return root;
  }

 private:
  const std::string& s_;
  const std::string& what_;
  std::vector<Node>& nodes_;
  std::size_t pos_ = 0;

  [[noreturn]] void fail(const std::string& why) const {
    throw ParameterError(what_ + " '" + s_ + "' is not an expression of x, y, z: " + why +
                         " at character " + std::to_string(pos_ + 1));
  }
  void skip() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_])) != 0) ++pos_;
  }
  bool eat(char c) {
    skip();
    if (pos_ < s_.size() && s_[pos_] == c) {
      ++pos_;
      return true;
    }
    return false;
  }
  int add(Op op, int left = -1, int right = -1, double value = 0.0, int function = 0) {
    Node n;
    n.op = op;
    n.left = left;
    n.right = right;
    n.value = value;
    n.function = function;
    nodes_.push_back(n);
    return static_cast<int>(nodes_.size()) - 1;
  }
  int sum() {
    int left = product();
    for (;;) {
      if (eat('+'))
        left = add(Op::Add, left, product());
      else if (eat('-'))
        left = add(Op::Sub, left, product());
      else
        return left;
    }
  }
  int product() {
    int left = unary();
    for (;;) {
      if (eat('*'))
        left = add(Op::Mul, left, unary());
      else if (eat('/'))
        left = add(Op::Div, left, unary());
      else
        return left;
    }
  }
  int unary() {
    if (eat('-')) return add(Op::Neg, unary());
    if (eat('+')) return unary();
    const int base = atom();
    if (eat('^')) return add(Op::Pow, base, unary());
    return base;
  }
  int atom() {
    skip();
    if (pos_ >= s_.size()) fail("the expression ends too early");
    const char c = s_[pos_];
    if (c == '(') {
      ++pos_;
      const int inner = sum();
      if (!eat(')')) fail("missing ')'");
      return inner;
    }
    if (std::isdigit(static_cast<unsigned char>(c)) != 0 || c == '.') {
      const char* begin = s_.c_str() + pos_;
      char* end = nullptr;
      const double v = std::strtod(begin, &end);
      if (end == begin) fail("a malformed number");
      pos_ += static_cast<std::size_t>(end - begin);
      return add(Op::Number, -1, -1, v);
    }
    if (std::isalpha(static_cast<unsigned char>(c)) != 0) {
      std::string name;
      while (pos_ < s_.size() && std::isalnum(static_cast<unsigned char>(s_[pos_])) != 0)
        name += s_[pos_++];
      if (name == "x") return add(Op::X);
      if (name == "y") return add(Op::Y);
      if (name == "z") return add(Op::Z);
      if (name == "pi") return add(Op::Number, -1, -1, M_PI);
      for (int f = 0; f < 7; ++f)
        if (name == kFunctions1[f]) {
          if (!eat('(')) fail("'(' expected after " + name);
          const int arg = sum();
          if (!eat(')')) fail("missing ')' after the argument of " + name);
          return add(Op::Call1, arg, -1, 0.0, f);
        }
      for (int f = 0; f < 2; ++f)
        if (name == kFunctions2[f]) {
          if (!eat('(')) fail("'(' expected after " + name);
          const int a = sum();
          if (!eat(',')) fail(name + " takes two arguments");
          const int b = sum();
          if (!eat(')')) fail("missing ')' after the arguments of " + name);
          return add(Op::Call2, a, b, 0.0, f);
        }
      pos_ -= name.size();
      fail("unknown name '" + name + "' (variables are x, y, z)");
    }
    fail("unexpected '" + std::string(1, c) + "'");
  }
};

double evaluate(const std::vector<Node>& nodes, int i, double x, double y, double z) {
  const Node& n = nodes[static_cast<std::size_t>(i)];
  const auto l = [&] { return evaluate(nodes, n.left, x, y, z); };
  const auto r = [&] { return evaluate(nodes, n.right, x, y, z); };
  switch (n.op) {
    case Op::Number:
      return n.value;
    case Op::X:
      return x;
    case Op::Y:
      return y;
    case Op::Z:
      return z;
    case Op::Add:
      return l() + r();
    case Op::Sub:
      return l() - r();
    case Op::Mul:
      return l() * r();
    case Op::Div:
      return l() / r();
    case Op::Pow:
      return std::pow(l(), r());
    case Op::Neg:
      return -l();
    case Op::Call1:
      return call1(n.function, l());
    case Op::Call2:
      return n.function == 0 ? std::min(l(), r()) : std::max(l(), r());
  }
  return 0.0;
}

}  // namespace

Expression Expression::parse(const std::string& text, const std::string& what) {
  Expression e;
  e.text_ = text;
  e.root_ = Parser(e.text_, what, e.nodes_).run();
  return e;
}

double Expression::operator()(double x, double y, double z) const {
  return evaluate(nodes_, root_, x, y, z);
}

bool Expression::isConstant() const {
  return std::none_of(nodes_.begin(), nodes_.end(), [](const Node& n) {
    return n.op == Op::X || n.op == Op::Y || n.op == Op::Z;
  });
}

}  // namespace homesh

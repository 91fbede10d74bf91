// A scalar expression of the coordinates x, y, z, as NekMesh's .mcf allows for
// BndLayerThickness ("0.01+0.05*x").
//
// Grammar: numbers, x y z, pi, + - * / ^ (right-associative power), unary minus, parentheses,
// and the functions sin cos tan exp log sqrt abs (one argument), min max (two arguments).
// Parsing happens once; evaluation is a walk of the parsed tree (no allocation).
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace homesh {

class Expression {
 public:
  // Throws ParameterError naming `what` (the parameter) and the position of the first
  // character that does not fit the grammar.
  static Expression parse(const std::string& text, const std::string& what);

  double operator()(double x, double y, double z) const;
  const std::string& text() const { return text_; }
  // True when the expression does not use x, y or z.
  bool isConstant() const;

  struct Node {
    enum class Op { Number, X, Y, Z, Add, Sub, Mul, Div, Pow, Neg, Call1, Call2 } op = Op::Number;
    double value = 0.0;
    int function = 0;           // index into the function table for Call1 / Call2
    int left = -1, right = -1;  // child nodes
  };

 private:
  std::string text_;
  std::vector<Node> nodes_;  // the tree
  int root_ = -1;
};

}  // namespace homesh

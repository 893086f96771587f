// Symbolic scalar used to trace a law's template formula into an expression graph, from which
// `draglab law export` writes standalone C and Fortran. Private to drag_db.
//
// Every operation builds a node; a node that the formula reuses (the same C++ variable) is shared,
// so the emitted code evaluates it once, in the same order of operations as the library. Branches
// are written in the formulas with select(condition, a, b), which for Expr becomes a ternary node.
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace draglab {
namespace codegen {

enum class Op {
  kConstant,
  kInput,      // phi, re, extra[i]
  kParameter,  // params[i]
  kAdd,
  kSub,
  kMul,
  kDiv,
  kNeg,
  kSqrt,
  kExp,
  kLog,
  kLog10,
  kAtan,
  kAbs,
  kPow,
  kSelect,  // children: condition, if_true, if_false
  kLess,
  kLessEqual,
  kGreater,
  kGreaterEqual,
};

struct Node {
  Op op = Op::kConstant;
  double value = 0.0;   // kConstant
  std::string name;     // kInput / kParameter: identifier in the emitted code
  int index = 0;        // kInput / kParameter: position
  std::vector<std::shared_ptr<const Node>> children;
};

using NodePtr = std::shared_ptr<const Node>;

/// A boolean expression (result of a comparison).
class Condition {
 public:
  explicit Condition(NodePtr node) : node_(std::move(node)) {}
  const NodePtr& node() const { return node_; }

 private:
  NodePtr node_;
};

/// A real-valued expression.
class Expr {
 public:
  Expr() : Expr(0.0) {}
  Expr(double constant);  // NOLINT(google-explicit-constructor): formulas write T(1.0), 2.0 * x.
  explicit Expr(NodePtr node) : node_(std::move(node)) {}
  static Expr input(const std::string& name, int index);
  static Expr parameter(const std::string& name, int index);

  const NodePtr& node() const { return node_; }
  Expr& operator+=(const Expr& o);
  Expr& operator-=(const Expr& o);
  Expr& operator*=(const Expr& o);
  Expr& operator/=(const Expr& o);

 private:
  NodePtr node_;
};

Expr operator+(const Expr& a, const Expr& b);
Expr operator-(const Expr& a, const Expr& b);
Expr operator*(const Expr& a, const Expr& b);
Expr operator/(const Expr& a, const Expr& b);
Expr operator-(const Expr& a);
inline Expr operator+(const Expr& a, double b) { return a + Expr(b); }
inline Expr operator+(double a, const Expr& b) { return Expr(a) + b; }
inline Expr operator-(const Expr& a, double b) { return a - Expr(b); }
inline Expr operator-(double a, const Expr& b) { return Expr(a) - b; }
inline Expr operator*(const Expr& a, double b) { return a * Expr(b); }
inline Expr operator*(double a, const Expr& b) { return Expr(a) * b; }
inline Expr operator/(const Expr& a, double b) { return a / Expr(b); }
inline Expr operator/(double a, const Expr& b) { return Expr(a) / b; }

Condition operator<(const Expr& a, const Expr& b);
Condition operator<=(const Expr& a, const Expr& b);
Condition operator>(const Expr& a, const Expr& b);
Condition operator>=(const Expr& a, const Expr& b);
inline Condition operator<(const Expr& a, double b) { return a < Expr(b); }
inline Condition operator<=(const Expr& a, double b) { return a <= Expr(b); }
inline Condition operator>(const Expr& a, double b) { return a > Expr(b); }
inline Condition operator>=(const Expr& a, double b) { return a >= Expr(b); }

Expr sqrt(const Expr& a);
Expr exp(const Expr& a);
Expr log(const Expr& a);
Expr log10(const Expr& a);
Expr atan(const Expr& a);
Expr abs(const Expr& a);
Expr pow(const Expr& a, const Expr& b);
inline Expr pow(const Expr& a, double b) { return pow(a, Expr(b)); }
inline Expr pow(double a, const Expr& b) { return pow(Expr(a), b); }
Expr select(const Condition& c, const Expr& if_true, const Expr& if_false);

}  // namespace codegen
}  // namespace draglab

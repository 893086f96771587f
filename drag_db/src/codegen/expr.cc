#include "codegen/expr.h"

namespace draglab {
namespace codegen {
namespace {

NodePtr make(Op op, std::vector<NodePtr> children) {
  auto n = std::make_shared<Node>();
  n->op = op;
  n->children = std::move(children);
  return n;
}

Expr unary(Op op, const Expr& a) { return Expr(make(op, {a.node()})); }
Expr binary(Op op, const Expr& a, const Expr& b) { return Expr(make(op, {a.node(), b.node()})); }
Condition compare(Op op, const Expr& a, const Expr& b) {
  return Condition(make(op, {a.node(), b.node()}));
}

}  // namespace

Expr::Expr(double constant) {
  auto n = std::make_shared<Node>();
  n->op = Op::kConstant;
  n->value = constant;
  node_ = n;
}

Expr Expr::input(const std::string& name, int index) {
  auto n = std::make_shared<Node>();
  n->op = Op::kInput;
  n->name = name;
  n->index = index;
  return Expr(NodePtr(n));
}

Expr Expr::parameter(const std::string& name, int index) {
  auto n = std::make_shared<Node>();
  n->op = Op::kParameter;
  n->name = name;
  n->index = index;
  return Expr(NodePtr(n));
}

Expr& Expr::operator+=(const Expr& o) { return *this = *this + o; }
Expr& Expr::operator-=(const Expr& o) { return *this = *this - o; }
Expr& Expr::operator*=(const Expr& o) { return *this = *this * o; }
Expr& Expr::operator/=(const Expr& o) { return *this = *this / o; }

Expr operator+(const Expr& a, const Expr& b) { return binary(Op::kAdd, a, b); }
Expr operator-(const Expr& a, const Expr& b) { return binary(Op::kSub, a, b); }
Expr operator*(const Expr& a, const Expr& b) { return binary(Op::kMul, a, b); }
Expr operator/(const Expr& a, const Expr& b) { return binary(Op::kDiv, a, b); }
Expr operator-(const Expr& a) { return unary(Op::kNeg, a); }

Condition operator<(const Expr& a, const Expr& b) { return compare(Op::kLess, a, b); }
Condition operator<=(const Expr& a, const Expr& b) { return compare(Op::kLessEqual, a, b); }
Condition operator>(const Expr& a, const Expr& b) { return compare(Op::kGreater, a, b); }
Condition operator>=(const Expr& a, const Expr& b) { return compare(Op::kGreaterEqual, a, b); }

Expr sqrt(const Expr& a) { return unary(Op::kSqrt, a); }
Expr exp(const Expr& a) { return unary(Op::kExp, a); }
Expr log(const Expr& a) { return unary(Op::kLog, a); }
Expr log10(const Expr& a) { return unary(Op::kLog10, a); }
Expr atan(const Expr& a) { return unary(Op::kAtan, a); }
Expr abs(const Expr& a) { return unary(Op::kAbs, a); }
Expr pow(const Expr& a, const Expr& b) { return binary(Op::kPow, a, b); }

Expr select(const Condition& c, const Expr& if_true, const Expr& if_false) {
  return Expr(make(Op::kSelect, {c.node(), if_true.node(), if_false.node()}));
}

}  // namespace codegen
}  // namespace draglab

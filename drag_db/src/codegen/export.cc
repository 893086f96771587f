// Code export (export.h): C and Fortran from the symbolic trace of a law's formula, JSON records.
//
// The trace (codegen::Expr) is a DAG. It is emitted in SSA style: every node used more than once
// (the same C++ variable in the formula) gets one temporary, evaluated once, in topological order;
// nodes used once are written inline, fully parenthesised, so the operations and their order are
// exactly those of the library. A select(c, a, b) becomes an if/else block whose arms hold the
// nodes only that arm needs (each node lives in the innermost block that encloses all its uses),
// so an unselected arm is never evaluated.
#include "draglab/drag_db/export.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <unordered_map>
#include <vector>

#include "codegen/expr.h"
#include "drag_db_version.h"
#include "draglab/drag_db/law_form.h"
#include "draglab/error.h"

namespace draglab {
namespace {

using codegen::Expr;
using codegen::Node;
using codegen::Op;

enum class Language { kC, kFortran };

// Nodes whose inline text would be longer than this get a temporary (readability, and it keeps
// Fortran statements well inside the 132-column limit before line wrapping).
constexpr std::size_t kMaxInlineLength = 64;
// Fortran free-form lines are limited to 132 characters; wrap well before.
constexpr std::size_t kFortranLineWidth = 100;
// Width of the wrapped text in header comments.
constexpr std::size_t kCommentWidth = 92;

// ---- numbers ---------------------------------------------------------------------------------

/// Shortest decimal text that reads back as exactly `x` (at most 17 significant digits).
std::string round_trip(double x) {
  char buf[40];
  int precision = 1;
  for (; precision < 17; ++precision) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, x);
    if (std::strtod(buf, nullptr) == x) break;
  }
  // Print numbers up to 1e15 without an exponent (10, not 1e+01): %g switches to exponent form
  // when the decimal exponent reaches the precision.
  if (std::isfinite(x) && x != 0.0) {
    const int exponent = static_cast<int>(std::floor(std::log10(std::fabs(x))));
    if (exponent >= 0 && exponent < 15) precision = std::max(precision, exponent + 1);
  }
  std::snprintf(buf, sizeof buf, "%.*g", precision, x);
  return buf;
}

void require_finite(double x, const std::string& what) {
  if (!std::isfinite(x)) {
    throw Error(ErrorCode::kInternal,
                "cannot export a non-finite constant (" + what + "): the formula needs one");
  }
}

std::string c_literal(double x) {
  require_finite(x, "C literal");
  std::string s = round_trip(x);
  if (s.find_first_of(".e") == std::string::npos) s += ".0";  // a double, never an int
  return std::signbit(x) ? "(" + s + ")" : s;
}

std::string fortran_literal(double x) {
  require_finite(x, "Fortran literal");
  std::string s = round_trip(x);
  const std::size_t e = s.find('e');
  std::string mantissa = s.substr(0, e);
  if (mantissa.find('.') == std::string::npos) mantissa += ".0";
  s = mantissa + (e == std::string::npos ? "" : s.substr(e)) + "_c_double";
  return std::signbit(x) ? "(" + s + ")" : s;
}

std::string literal(Language lang, double x) {
  return lang == Language::kC ? c_literal(x) : fortran_literal(x);
}

/// A validity-box bound, which may be infinite (an unbounded side of the box).
std::string bound_literal(Language lang, double x) {
  if (std::isnan(x)) throw Error(ErrorCode::kInternal, "NaN bound in a validity box");
  if (std::isinf(x)) {
    if (lang == Language::kC) return x > 0 ? "HUGE_VAL" : "(-HUGE_VAL)";
    return x > 0 ? "huge(1.0_c_double)" : "(-huge(1.0_c_double))";
  }
  return literal(lang, x);
}

std::string format_bound(double x) {
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  return round_trip(x);
}

// ---- text helpers ----------------------------------------------------------------------------

std::string sanitize_identifier(const std::string& s) {
  std::string out;
  for (char c : s) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9');
    out += ok ? c : '_';
  }
  if (out.empty() || !((out[0] >= 'a' && out[0] <= 'z') || (out[0] >= 'A' && out[0] <= 'Z'))) {
    out = "law_" + out;
  }
  return out;
}

std::string to_lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

/// Word-wraps `text` into lines of at most `width` characters (words longer than that stay whole).
std::vector<std::string> wrap_words(const std::string& text, std::size_t width) {
  std::vector<std::string> lines;
  std::istringstream words(text);
  std::string word, line;
  while (words >> word) {
    if (!line.empty() && line.size() + 1 + word.size() > width) {
      lines.push_back(line);
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
  }
  if (!line.empty()) lines.push_back(line);
  return lines;
}

/// "Label:  text" with continuation lines indented under the text.
void add_field(std::vector<std::string>& out, const std::string& label, const std::string& text) {
  const std::string pad(label.size(), ' ');
  const auto lines = wrap_words(text, kCommentWidth - label.size());
  if (lines.empty()) {
    out.push_back(label + "-");
    return;
  }
  for (std::size_t i = 0; i < lines.size(); ++i) out.push_back((i == 0 ? label : pad) + lines[i]);
}

/// Makes comment text safe inside a C block comment.
std::string c_comment_safe(std::string s) {
  for (std::size_t p = s.find("*/"); p != std::string::npos; p = s.find("*/", p)) {
    s.replace(p, 2, "* /");
  }
  return s;
}

/// Splits a long Fortran statement at spaces into continuation lines.
std::vector<std::string> wrap_fortran(const std::string& base_indent,
                                      const std::string& statement) {
  std::vector<std::string> out;
  // Leading blanks of the statement count as indentation.
  const std::size_t first = std::min(statement.find_first_not_of(' '), statement.size());
  const std::string indent = base_indent + statement.substr(0, first);
  std::string rest = statement.substr(first);
  std::string prefix = indent;
  while (prefix.size() + rest.size() > kFortranLineWidth) {
    const std::size_t limit = kFortranLineWidth - prefix.size() - 2;
    std::size_t cut = rest.rfind(' ', limit);
    if (cut == std::string::npos || cut == 0) cut = rest.find(' ', limit);
    if (cut == std::string::npos) break;  // one unbreakable token: leave it long
    out.push_back(prefix + rest.substr(0, cut) + " &");
    rest = rest.substr(cut + 1);
    prefix = indent + "    & ";
  }
  out.push_back(prefix + rest);
  return out;
}

// ---- the expression graph --------------------------------------------------------------------

bool is_leaf(Op op) { return op == Op::kConstant || op == Op::kInput || op == Op::kParameter; }

bool is_comparison(Op op) {
  return op == Op::kLess || op == Op::kLessEqual || op == Op::kGreater || op == Op::kGreaterEqual;
}

/// The trace of one formula, with the placement of every node in the if/else block structure.
class Graph {
 public:
  explicit Graph(const Node* root) : root_(root) {
    collect(root);
    place();
  }

  const std::vector<const Node*>& order() const { return order_; }  // children before users
  int index(const Node* n) const { return index_.at(n); }
  int uses(const Node* n) const { return uses_[index(n)]; }
  int home(const Node* n) const { return home_[index(n)]; }
  int num_scopes() const { return static_cast<int>(scope_parent_.size()); }
  /// The two scopes (if-arm, else-arm) opened by a select node.
  std::pair<int, int> arms(const Node* select) const { return arms_.at(select); }
  bool references_input(const std::string& name) const {
    for (const Node* n : order_) {
      if (n->op == Op::kInput && n->name == name) return true;
    }
    return false;
  }

 private:
  void collect(const Node* n) {
    // Iterative post-order DFS (formulas may be deep chains of operations).
    std::vector<std::pair<const Node*, std::size_t>> stack{{n, 0}};
    index_.emplace(n, -1);
    while (!stack.empty()) {
      auto& [node, next_child] = stack.back();
      if (next_child < node->children.size()) {
        const Node* child = node->children[next_child++].get();
        if (index_.emplace(child, -1).second) stack.push_back({child, 0});
        continue;
      }
      index_[node] = static_cast<int>(order_.size());
      order_.push_back(node);
      stack.pop_back();
    }
    uses_.assign(order_.size(), 0);
    for (const Node* node : order_) {
      for (const auto& child : node->children) ++uses_[index(child.get())];
    }
  }

  int new_scope(int parent) {
    scope_parent_.push_back(parent);
    scope_depth_.push_back(parent < 0 ? 0 : scope_depth_[parent] + 1);
    return static_cast<int>(scope_parent_.size()) - 1;
  }

  int common_scope(int a, int b) const {
    while (scope_depth_[a] > scope_depth_[b]) a = scope_parent_[a];
    while (scope_depth_[b] > scope_depth_[a]) b = scope_parent_[b];
    while (a != b) {
      a = scope_parent_[a];
      b = scope_parent_[b];
    }
    return a;
  }

  void require_in(const Node* n, int scope) {
    int& h = home_[index(n)];
    h = (h < 0) ? scope : common_scope(h, scope);
  }

  // Users come before their operands in reverse post-order, so each node's home scope (the
  // innermost block enclosing all its uses) is final when the node is reached.
  void place() {
    home_.assign(order_.size(), -1);
    home_[index(root_)] = new_scope(-1);
    for (auto it = order_.rbegin(); it != order_.rend(); ++it) {
      const Node* n = *it;
      const int h = home_[index(n)];
      if (n->op == Op::kSelect) {
        const int then_scope = new_scope(h);
        const int else_scope = new_scope(h);
        arms_[n] = {then_scope, else_scope};
        require_in(n->children[0].get(), h);
        require_in(n->children[1].get(), then_scope);
        require_in(n->children[2].get(), else_scope);
      } else {
        for (const auto& child : n->children) require_in(child.get(), h);
      }
    }
  }

  const Node* root_;
  std::vector<const Node*> order_;
  std::unordered_map<const Node*, int> index_;
  std::vector<int> uses_;
  std::vector<int> home_;
  std::vector<int> scope_parent_, scope_depth_;
  std::unordered_map<const Node*, std::pair<int, int>> arms_;
};

/// Writes the body of one function computing a traced formula.
class BodyWriter {
 public:
  BodyWriter(Language lang, const Graph& graph, std::vector<std::string> parameter_names)
      : lang_(lang), graph_(graph), parameter_names_(std::move(parameter_names)) {
    decide_temporaries();
  }

  /// Statements (with `base_indent`), and the expression of the result.
  void write(const std::string& base_indent, std::vector<std::string>& lines, std::string& result) {
    lines_ = &lines;
    indent_ = base_indent;
    const Node* root = graph_.order().back();
    scope_nodes_.assign(graph_.num_scopes(), {});
    for (const Node* n : graph_.order()) {
      if (temp_[graph_.index(n)]) scope_nodes_[graph_.home(n)].push_back(n);
    }
    write_scope(graph_.home(root));
    result = ref(root, true);
  }

  /// Temporary names in order of definition (for Fortran declarations).
  const std::vector<std::string>& temporaries() const { return temporaries_; }
  /// Indices of the parameters the formula uses.
  std::set<int> used_parameters() const {
    std::set<int> used;
    for (const Node* n : graph_.order()) {
      if (n->op == Op::kParameter) used.insert(n->index);
    }
    return used;
  }

 private:
  void decide_temporaries() {
    const auto& order = graph_.order();
    temp_.assign(order.size(), false);
    name_.assign(order.size(), "");
    std::vector<std::size_t> length(order.size(), 0);
    for (const Node* n : order) {
      const int i = graph_.index(n);
      if (is_leaf(n->op)) {
        length[i] = leaf_text(n).size();
        continue;
      }
      std::size_t len = 8;  // operator, parentheses and spaces
      for (const auto& c : n->children) {
        const int ci = graph_.index(c.get());
        len += temp_[ci] ? 4 : length[ci];
      }
      length[i] = len;
      if (is_comparison(n->op)) continue;  // always inline in its if (...)
      temp_[i] = n->op == Op::kSelect || graph_.uses(n) > 1 || len > kMaxInlineLength;
    }
  }

  std::string leaf_text(const Node* n) const {
    switch (n->op) {
      case Op::kConstant:
        return literal(lang_, n->value);
      case Op::kParameter:
        return parameter_names_.at(static_cast<std::size_t>(n->index));
      case Op::kInput:
      default:
        if (n->name == "extra") {
          return lang_ == Language::kC ? "extra[" + std::to_string(n->index) + "]"
                                       : "extra(" + std::to_string(n->index + 1) + ")";
        }
        return n->name;
    }
  }

  /// The text that refers to node `n` from an expression (its temporary, or inline text).
  std::string ref(const Node* n, bool top = false) const {
    const int i = graph_.index(n);
    if (temp_[i]) return name_[i];
    return inline_text(n, top);
  }

  std::string inline_text(const Node* n, bool top) const {
    if (is_leaf(n->op)) return leaf_text(n);
    const bool c = lang_ == Language::kC;
    auto arg = [&](int k) { return ref(n->children[static_cast<std::size_t>(k)].get()); };
    auto binary = [&](const char* op) {
      const std::string s = arg(0) + " " + op + " " + arg(1);
      return top ? s : "(" + s + ")";
    };
    auto call = [&](const char* f) { return std::string(f) + "(" + arg(0) + ")"; };
    switch (n->op) {
      case Op::kAdd:
        return binary("+");
      case Op::kSub:
        return binary("-");
      case Op::kMul:
        return binary("*");
      case Op::kDiv:
        return binary("/");
      case Op::kNeg:
        return top ? "-" + arg(0) : "(-" + arg(0) + ")";
      case Op::kSqrt:
        return call("sqrt");
      case Op::kExp:
        return call("exp");
      case Op::kLog:
        return call("log");
      case Op::kLog10:
        return call("log10");
      case Op::kAtan:
        return call("atan");
      case Op::kAbs:
        return call(c ? "fabs" : "abs");
      case Op::kPow:
        return c ? "pow(" + arg(0) + ", " + arg(1) + ")" : binary("**");
      case Op::kLess:
        return binary("<");
      case Op::kLessEqual:
        return binary("<=");
      case Op::kGreater:
        return binary(">");
      case Op::kGreaterEqual:
        return binary(">=");
      default:
        throw Error(ErrorCode::kInternal, "code export: unexpected node in expression");
    }
  }

  void line(const std::string& s) {
    if (lang_ == Language::kFortran) {
      for (const std::string& l : wrap_fortran(indent_, s)) lines_->push_back(l);
    } else {
      lines_->push_back(indent_ + s);
    }
  }

  void write_scope(int scope) {
    for (const Node* n : scope_nodes_[scope]) write_node(n);
  }

  void write_node(const Node* n) {
    const int i = graph_.index(n);
    name_[i] = "t" + std::to_string(temporaries_.size() + 1);
    temporaries_.push_back(name_[i]);
    const std::string& t = name_[i];
    const bool c = lang_ == Language::kC;
    if (n->op != Op::kSelect) {
      line(c ? "const double " + t + " = " + inline_text(n, true) + ";"
             : t + " = " + inline_text(n, true));
      return;
    }
    const auto [then_scope, else_scope] = graph_.arms(n);
    const std::string condition = ref(n->children[0].get(), true);
    const std::string saved = indent_;
    if (c) line("double " + t + ";");
    line(c ? "if (" + condition + ") {" : "if (" + condition + ") then");
    indent_ += "  ";
    write_scope(then_scope);
    line(t + " = " + ref(n->children[1].get(), true) + (c ? ";" : ""));
    indent_ = saved;
    line(c ? "} else {" : "else");
    indent_ += "  ";
    write_scope(else_scope);
    line(t + " = " + ref(n->children[2].get(), true) + (c ? ";" : ""));
    indent_ = saved;
    line(c ? "}" : "end if");
  }

  Language lang_;
  const Graph& graph_;
  std::vector<std::string> parameter_names_;
  std::vector<bool> temp_;
  std::vector<std::string> name_;
  std::vector<std::vector<const Node*>> scope_nodes_;
  std::vector<std::string> temporaries_;
  std::vector<std::string>* lines_ = nullptr;
  std::string indent_;
};

// ---- what both languages share ---------------------------------------------------------------

struct LawTrace {
  const LawForm* form = nullptr;
  int num_extra = 0;
  std::vector<std::string> parameter_names;  // p_<name>, unique, lower case
  Expr F;
};

LawTrace trace(const LawRecord& record) {
  LawTrace t;
  t.form = &find_law_form(record.form);
  const auto& specs = t.form->description.parameters;
  if (record.parameters.size() != specs.size()) {
    throw Error(ErrorCode::kInvalidArgument, record.reference() + ": form '" + record.form +
                                                 "' takes " + std::to_string(specs.size()) +
                                                 " parameters, the record has " +
                                                 std::to_string(record.parameters.size()));
  }
  t.num_extra = t.form->num_extra_inputs;
  if (record.validity.extra.size() != static_cast<std::size_t>(t.num_extra)) {
    throw Error(ErrorCode::kInvalidArgument, record.reference() +
                                                 ": the validity box does not list the form's " +
                                                 std::to_string(t.num_extra) + " extra input(s)");
  }
  std::set<std::string> taken;
  std::vector<Expr> params;
  for (std::size_t i = 0; i < record.parameters.size(); ++i) {
    if (!std::isfinite(record.parameters[i].value)) {
      throw Error(ErrorCode::kInvalidArgument, record.reference() + ": parameter '" +
                                                   record.parameters[i].name + "' is not finite");
    }
    // Fortran is case-insensitive: names must differ in lower case.
    std::string name = "p_" + to_lower(sanitize_identifier(record.parameters[i].name));
    if (!taken.insert(name).second) {
      name += "_" + std::to_string(i);
      taken.insert(name);
    }
    t.parameter_names.push_back(name);
    params.push_back(Expr::parameter(name, static_cast<int>(i)));
  }
  std::vector<Expr> extra;
  for (int k = 0; k < t.num_extra; ++k) extra.push_back(Expr::input("extra", k));
  t.F = t.form->F_symbolic(Expr::input("phi", 0), Expr::input("re", 1),
                           extra.empty() ? nullptr : extra.data(), params.data());
  return t;
}

/// Header comment lines (without comment markers), shared by C and Fortran.
std::vector<std::string> header_lines(const LawRecord& r, const LawTrace& t, Language lang,
                                      const std::string& id) {
  const bool c = lang == Language::kC;
  const LawFormDescription& d = t.form->description;
  std::vector<std::string> h;
  add_field(h, "", r.reference() + " -- " + d.title);
  h.push_back("");
  add_field(h, "",
            std::string("Generated by draglab ") + kDragDbVersion +
                " from the library's own formula; do not edit. Regenerate with: draglab law "
                "export " +
                r.reference() + " --format " + (c ? "c" : "fortran"));
  h.push_back("");
  add_field(h, "Law:          ",
            r.reference() + " (form " + r.form + ", status " + to_string(r.status) + ")");
  if (r.status == LawStatus::kRetracted) {
    add_field(h, "RETRACTED:    ", r.retraction_reason);
  }
  add_field(h, "Content hash: ", "sha256 " + r.content_hash);
  add_field(h,
            "Citation:     ", r.provenance.citation.empty() ? d.citation : r.provenance.citation);
  std::string provenance = r.provenance.kind;
  if (!r.provenance.dataset_id.empty()) provenance += "; dataset " + r.provenance.dataset_id;
  if (!r.provenance.data_hash.empty()) provenance += "; data hash " + r.provenance.data_hash;
  if (!r.provenance.code_version.empty()) {
    provenance += "; written by draglab " + r.provenance.code_version;
  }
  add_field(h, "Provenance:   ", provenance);
  if (!r.notes.empty()) add_field(h, "Notes:        ", r.notes);
  h.push_back("Parameters:");
  for (std::size_t i = 0; i < r.parameters.size(); ++i) {
    const LawParameter& p = r.parameters[i];
    std::string text = t.parameter_names[i] + " = " + round_trip(p.value) + " [" + p.unit + "]";
    if (i < d.parameters.size() && !d.parameters[i].description.empty()) {
      text += "  " + d.parameters[i].description;
    }
    add_field(h, "  ", text);
  }
  h.push_back("");
  h.push_back(
      "Conventions (draglab canonical; the law's native convention is converted inside F):");
  h.push_back("  phi  = solids volume fraction, eps = 1 - phi the gas volume fraction");
  h.push_back("  u    = |u_g - u_s| interstitial slip velocity (superficial velocity U = eps u)");
  h.push_back("  Re   = rho_g eps d_p u / mu_g (superficial, particle-diameter based)");
  h.push_back(
      "  F    = F_d / (3 pi mu_g d_p eps u): drag only, mean-pressure-gradient part "
      "excluded");
  h.push_back(
      "  beta = 18 mu_g phi eps F / d_p^2 [kg m^-3 s^-1], momentum exchange per unit "
      "volume");
  h.push_back("  dga  = beta / phi = 18 mu_g eps F / d_p^2 [kg m^-3 s^-1] (MFiX's lDgA)");
  h.push_back("  (K = F / (1 - phi) would be the total force incl. the mean pressure gradient.)");
  add_field(h, "  Native convention: ",
            std::string("force ") + to_string(r.convention.force) + ", normalisation " +
                to_string(r.convention.normalisation) + ", Re " + to_string(r.convention.reynolds) +
                ", TFM model " + to_string(r.convention.tfm_model));
  for (int k = 0; k < t.num_extra; ++k) {
    const ExtraInputSpec& e = r.validity.extra[static_cast<std::size_t>(k)];
    add_field(h, "  ",
              std::string("extra") +
                  (c ? "[" + std::to_string(k) + "]" : "(" + std::to_string(k + 1) + ")") + " = " +
                  e.name + ": " + e.description);
  }
  h.push_back("");
  std::string box = "Validity box: " + format_bound(r.validity.phi.min) +
                    " <= phi <= " + format_bound(r.validity.phi.max) + ", " +
                    format_bound(r.validity.re.min) +
                    " <= Re <= " + format_bound(r.validity.re.max);
  for (const ExtraInputSpec& e : r.validity.extra) {
    box += ", " + format_bound(e.range.min) + " <= " + e.name + " <= " + format_bound(e.range.max);
  }
  add_field(h, "", box);
  h.push_back("");
  add_field(h, "",
            "Input handling. " + id + "_F, " + id + "_beta and " + id +
                "_dga check nothing: they are the fast kernels for inputs the caller has "
                "already validated (0 <= phi < 1, 0 <= Re < inf, inside the validity box); "
                "outside that their result is unspecified. The _checked variants validate "
                "first and return a status (" +
                (c ? "function result" : "argument stat") +
                "): 0 ok; 1 invalid input (NaN or inf, phi outside [0, 1) i.e. eps outside "
                "(0, 1], Re < 0, mu_g, rho_g or d_p not > 0, slip < 0, unknown range_policy" +
                (c ? ", null pointer" : "") +
                "), output untouched; 2 outside the validity box: with range_policy 0 "
                "(error) the output is untouched, with 1 (clamp into the box) or 2 "
                "(extrapolate) it is written, so the caller can count these events; 8 "
                "non-finite result (a bug), output untouched. The codes are those of "
                "draglab.h. Only the selected arm of a branch is evaluated, so Re = 0 raises "
                "no floating-point exception.");
  return h;
}

std::string f_signature_args(const LawTrace& t, Language lang) {
  if (t.num_extra == 0) return "";
  return lang == Language::kC ? ", const double* extra" : ", extra";
}

// ---- C ---------------------------------------------------------------------------------------

std::string export_c(const LawRecord& r) {
  const LawTrace t = trace(r);
  const std::string id = export_identifier(r);
  const Graph graph(t.F.node().get());
  BodyWriter body(Language::kC, graph, t.parameter_names);
  std::vector<std::string> statements;
  std::string result;
  body.write("  ", statements, result);

  std::ostringstream o;
  o << "/*\n";
  for (const std::string& l : header_lines(r, t, Language::kC, id)) {
    o << (l.empty() ? " *" : " * " + c_comment_safe(l)) << "\n";
  }
  o << " */\n";
  o << "#include <math.h>\n\n";
  o << "#ifdef __cplusplus\nextern \"C\" {\n#endif\n\n";

  const std::string extra_param = f_signature_args(t, Language::kC);
  const std::string extra_arg = t.num_extra > 0 ? ", extra" : "";
  const std::string dims = "double eps_g, double mu_g, double rho_g, double slip, double d_p";

  // F
  o << "/* Canonical drag-only F(phi, Re), dimensionless. No input checks (see above). */\n";
  o << "double " << id << "_F(double phi, double re" << extra_param << ") {\n";
  if (!graph.references_input("phi")) o << "  (void)phi;\n";
  if (!graph.references_input("re")) o << "  (void)re;\n";
  if (t.num_extra > 0 && !graph.references_input("extra")) o << "  (void)extra;\n";
  for (int i : body.used_parameters()) {
    o << "  const double " << t.parameter_names[static_cast<std::size_t>(i)] << " = "
      << c_literal(r.parameters[static_cast<std::size_t>(i)].value) << ";\n";
  }
  for (const std::string& s : statements) o << s << "\n";
  o << "  return " << result << ";\n}\n\n";

  // beta and dga: same operations, in the same order, as Law::beta (conventions.h).
  const std::string phi_re =
      "  const double phi = 1.0 - eps_g;\n"
      "  const double re = rho_g * eps_g * d_p * slip / mu_g;\n";
  o << "/* Friction coefficient beta [kg m^-3 s^-1] from gas fraction eps_g, gas viscosity mu_g\n"
       " * [Pa s], gas density rho_g [kg/m^3], interstitial slip |u_g - u_s| [m/s], particle\n"
       " * diameter d_p [m]. No input checks. */\n";
  o << "double " << id << "_beta(" << dims << extra_param << ") {\n"
    << phi_re << "  return phi * (1.0 - phi) * " << id << "_F(phi, re" << extra_arg
    << ") * 18.0 * (mu_g / (d_p * d_p));\n}\n\n";
  o << "/* MFiX's DRAG_USR output lDgA = beta / phi = 18 mu_g eps_g F / d_p^2 [kg m^-3 s^-1]\n"
       " * (finite at phi = 0). Same arguments as _beta. No input checks. */\n";
  o << "double " << id << "_dga(" << dims << extra_param << ") {\n"
    << phi_re << "  return eps_g * " << id << "_F(phi, re" << extra_arg
    << ") * 18.0 * (mu_g / (d_p * d_p));\n}\n\n";

  // F_checked
  const auto& box = r.validity;
  auto bl = [](double x) { return bound_literal(Language::kC, x); };
  o << "/* F with input checks and a range policy (0 error, 1 clamp, 2 extrapolate); returns a\n"
       " * status (0 ok, 1 invalid input, 2 outside the validity box, 8 non-finite result). */\n";
  o << "int " << id << "_F_checked(double phi, double re" << extra_param
    << ",\n    int range_policy, double* F) {\n";
  o << "  double x_phi = phi, x_re = re, value;\n";
  if (t.num_extra > 0) o << "  double x_extra[" << t.num_extra << "];\n";
  o << "  int status = 0;\n";
  o << "  if (F == 0 || range_policy < 0 || range_policy > 2) return 1;\n";
  o << "  if (!isfinite(phi) || phi < 0.0 || phi >= 1.0) return 1;\n";
  o << "  if (!isfinite(re) || re < 0.0) return 1;\n";
  if (t.num_extra > 0) {
    o << "  if (extra == 0) return 1;\n";
    for (int k = 0; k < t.num_extra; ++k) {
      o << "  if (!isfinite(extra[" << k << "])) return 1;\n";
      o << "  x_extra[" << k << "] = extra[" << k << "];\n";
    }
  }
  std::string outside = "phi < " + bl(box.phi.min) + " || phi > " + bl(box.phi.max) + " || re < " +
                        bl(box.re.min) + " || re > " + bl(box.re.max);
  for (int k = 0; k < t.num_extra; ++k) {
    const InputRange& e = box.extra[static_cast<std::size_t>(k)].range;
    const std::string x = "extra[" + std::to_string(k) + "]";
    outside += " ||\n      " + x + " < " + bl(e.min) + " || " + x + " > " + bl(e.max);
  }
  auto clamp = [&](const std::string& v, const std::string& x, double lo, double hi) {
    return "    " + v + " = " + x + " < " + bl(lo) + " ? " + bl(lo) + " : (" + x + " > " + bl(hi) +
           " ? " + bl(hi) + " : " + x + ");\n";
  };
  o << "  if (" << outside << ") {\n";
  o << "    if (range_policy == 0) return 2;\n";
  o << "    status = 2;\n";
  o << "  }\n";
  o << "  if (status == 2 && range_policy == 1) {\n";
  o << clamp("x_phi", "phi", box.phi.min, box.phi.max);
  o << clamp("x_re", "re", box.re.min, box.re.max);
  for (int k = 0; k < t.num_extra; ++k) {
    const InputRange& e = box.extra[static_cast<std::size_t>(k)].range;
    o << clamp("x_extra[" + std::to_string(k) + "]", "extra[" + std::to_string(k) + "]", e.min,
               e.max);
  }
  o << "  }\n";
  o << "  value = " << id << "_F(x_phi, x_re" << (t.num_extra > 0 ? ", x_extra" : "") << ");\n";
  o << "  if (!isfinite(value)) return 8;\n";
  o << "  *F = value;\n";
  o << "  return status;\n}\n\n";

  // beta_checked, dga_checked
  auto checked_dimensional = [&](const std::string& what, const std::string& formula,
                                 const std::string& doc) {
    o << "/* " << doc << " with input checks; status and range_policy as in _F_checked. */\n";
    o << "int " << id << "_" << what << "_checked(" << dims << extra_param
      << ",\n    int range_policy, double* out) {\n";
    o << "  double phi, re, F = 0.0;\n  int status;\n";
    o << "  if (out == 0) return 1;\n";
    o << "  if (!isfinite(eps_g) || !(eps_g > 0.0) || eps_g > 1.0) return 1;\n";
    o << "  if (!isfinite(mu_g) || !(mu_g > 0.0)) return 1;\n";
    o << "  if (!isfinite(rho_g) || !(rho_g > 0.0)) return 1;\n";
    o << "  if (!isfinite(d_p) || !(d_p > 0.0)) return 1;\n";
    o << "  if (!isfinite(slip) || slip < 0.0) return 1;\n";
    o << "  phi = 1.0 - eps_g;\n";
    o << "  re = rho_g * eps_g * d_p * slip / mu_g;\n";
    o << "  status = " << id << "_F_checked(phi, re" << extra_arg << ", range_policy, &F);\n";
    o << "  if (status != 0 && !(status == 2 && range_policy != 0)) return status;\n";
    o << "  *out = " << formula << ";\n";
    o << "  return status;\n}\n\n";
  };
  checked_dimensional("beta", "phi * (1.0 - phi) * F * 18.0 * (mu_g / (d_p * d_p))", "beta");
  checked_dimensional("dga", "eps_g * F * 18.0 * (mu_g / (d_p * d_p))", "MFiX's lDgA");

  o << "#ifdef __cplusplus\n}  /* extern \"C\" */\n#endif\n";
  return o.str();
}

// ---- Fortran ---------------------------------------------------------------------------------

std::string export_fortran(const LawRecord& r) {
  const LawTrace t = trace(r);
  const std::string id = export_identifier(r);
  const std::string module = id + "_drag";
  const Graph graph(t.F.node().get());
  BodyWriter body(Language::kFortran, graph, t.parameter_names);
  std::vector<std::string> statements;
  std::string result;
  body.write("    ", statements, result);

  auto bl = [](double x) { return bound_literal(Language::kFortran, x); };
  auto lit = [](double x) { return fortran_literal(x); };
  const bool has_extra = t.num_extra > 0;
  const std::string extra_arg = has_extra ? ", extra" : "";
  const std::string extra_decl =
      "    real(c_double), intent(in) :: extra(" + std::to_string(t.num_extra) + ")";
  std::vector<std::string> out;
  auto emit = [&](const std::string& s) {
    for (const std::string& l : wrap_fortran("", s)) out.push_back(l);
  };

  for (const std::string& l : header_lines(r, t, Language::kFortran, id)) {
    out.push_back(l.empty() ? "!" : "! " + l);
  }
  const std::vector<std::string> mfix = {
      "",
      "Use from MFiX (DRAG_TYPE = 'USER_DRAG'): put this module in front of the DRAG_USR "
      "subroutine in usr_drag.f (MFiX compiles its .f sources as free form) or add this file "
      "to the solver build, then:",
  };
  for (const std::string& m : mfix) {
    for (const std::string& l : wrap_words(m, kCommentWidth)) out.push_back("! " + l);
    if (m.empty()) out.push_back("!");
  }
  const std::string extra_call = has_extra ? ", y" : "";
  out.push_back("!");
  out.push_back(
      "!   SUBROUTINE DRAG_USR(IJK, M_NP, lDgA, EPg, Mug, ROg, VREL, DPM, ROs, lUg, "
      "lVg, lWg)");
  out.push_back("!     use error_manager");
  out.push_back("!     use " + module + ", only: " + id + "_dga_checked");
  out.push_back("!     ...  (declarations of the arguments as in the stub)");
  out.push_back("!     integer :: stat");
  if (has_extra) out.push_back("!     double precision :: y(" + std::to_string(t.num_extra) + ")");
  if (has_extra) out.push_back("!     y = ...  ! the extra input(s) listed above, e.g. DPM / <d>");
  out.push_back("!     lDgA = 0.0d0");
  out.push_back("!     call " + id + "_dga_checked(EPg, Mug, ROg, VREL, DPM" + extra_call +
                ", 1, lDgA, stat)  ! 1 = clamp");
  out.push_back("!     if (stat == 1 .or. stat == 8) then");
  out.push_back("!       write(err_msg, *) 'drag law " + r.reference() +
                ": invalid input, stat =', stat");
  out.push_back("!       call log_error()");
  out.push_back("!     end if");
  out.push_back("!   END SUBROUTINE DRAG_USR");
  out.push_back("!");
  const std::string meaning =
      "What MFiX expects in lDgA: the model-A gas-solids coefficient per unit solids volume "
      "fraction, lDgA = beta / phi = 18 Mug EPg F / DPM**2 [kg m^-3 s^-1] (this is what " +
      id +
      "_dga returns; it is finite at EPg = 1). MFiX itself multiplies it by EP_SM (TFM model "
      "A), by EP_SM/EPg (TFM model B: \"Model B coeff = Model A coeff/EP_g\") or by the "
      "particle volume PVOL (DES, giving the per-particle force coefficient 3 pi Mug DPM EPg "
      "F), exactly as for its built-in DRAG_BVK (lDgA = F * 18 Mug EPg / DPM**2). So return "
      "the same lDgA whatever the model, and do not divide by EPg yourself. Checked against "
      "the MFiX 21.3 sources (model/drag_gs.f, model/des/drag_gp_des.f); the DRAG_USR "
      "arguments changed in the 2015-1 release, so check them against your version. In "
      "polydisperse TFM runs MFiX passes each phase's diameter as DPM: this law's phi is the "
      "total solids fraction 1 - EPg.";
  for (const std::string& l : wrap_words(meaning, kCommentWidth)) out.push_back("! " + l);

  emit("module " + module);
  emit("  use, intrinsic :: iso_c_binding, only: c_double");
  emit("  implicit none");
  emit("  private");
  emit("  public :: " + id + "_F, " + id + "_beta, " + id + "_dga, " + id + "_F_checked, " + id +
       "_beta_checked, " + id + "_dga_checked");
  emit("contains");
  out.push_back("");

  // F
  out.push_back("  ! Canonical drag-only F(phi, Re), dimensionless. No input checks (see above).");
  emit("  pure function " + id + "_F(phi, re" + extra_arg + ") result(F)");
  emit("    real(c_double), intent(in) :: phi, re");
  if (has_extra) emit(extra_decl);
  emit("    real(c_double) :: F");
  for (int i : body.used_parameters()) {
    emit("    real(c_double), parameter :: " + t.parameter_names[static_cast<std::size_t>(i)] +
         " = " + lit(r.parameters[static_cast<std::size_t>(i)].value));
  }
  if (!body.temporaries().empty()) {
    std::string decl;
    for (const std::string& name : body.temporaries()) decl += (decl.empty() ? "" : ", ") + name;
    for (const std::string& l : wrap_fortran("    ", "real(c_double) :: " + decl)) {
      out.push_back(l);
    }
  }
  for (const std::string& s : statements) out.push_back(s);
  for (const std::string& l : wrap_fortran("    ", "F = " + result)) out.push_back(l);
  emit("  end function " + id + "_F");
  out.push_back("");

  // beta, dga
  const std::string dims = "eps_g, mu_g, rho_g, slip, d_p";
  auto dimensional = [&](const std::string& what, const std::string& formula,
                         const std::string& doc) {
    out.push_back("  ! " + doc);
    emit("  pure function " + id + "_" + what + "(" + dims + extra_arg + ") result(res)");
    emit("    real(c_double), intent(in) :: " + dims);
    if (has_extra) emit(extra_decl);
    emit("    real(c_double) :: res, phi, re");
    emit("    phi = 1.0_c_double - eps_g");
    emit("    re = rho_g * eps_g * d_p * slip / mu_g");
    emit("    res = " + formula);
    emit("  end function " + id + "_" + what);
    out.push_back("");
  };
  dimensional("beta",
              "phi * (1.0_c_double - phi) * " + id + "_F(phi, re" + extra_arg +
                  ") * 18.0_c_double * (mu_g / (d_p * d_p))",
              "Friction coefficient beta [kg m^-3 s^-1]; SI inputs, no input checks.");
  dimensional(
      "dga",
      "eps_g * " + id + "_F(phi, re" + extra_arg + ") * 18.0_c_double * (mu_g / (d_p * d_p))",
      "MFiX's lDgA = beta / phi [kg m^-3 s^-1]; SI inputs, no input checks.");

  // F_checked
  const auto& box = r.validity;
  auto clamp = [&](const std::string& v, const std::string& x, double lo, double hi) {
    emit("      " + v + " = merge(" + bl(lo) + ", merge(" + bl(hi) + ", " + x + ", " + x + " > " +
         bl(hi) + "), " + x + " < " + bl(lo) + ")");
  };
  out.push_back("  ! F with input checks and a range policy (0 error, 1 clamp, 2 extrapolate).");
  out.push_back(
      "  ! stat: 0 ok, 1 invalid input, 2 outside the validity box, 8 non-finite result;");
  out.push_back("  ! F is left untouched unless stat is 0, or 2 with range_policy 1 or 2.");
  emit("  pure subroutine " + id + "_F_checked(phi, re" + extra_arg + ", range_policy, F, stat)");
  emit("    real(c_double), intent(in) :: phi, re");
  if (has_extra) emit(extra_decl);
  emit("    integer, intent(in) :: range_policy");
  emit("    real(c_double), intent(inout) :: F");
  emit("    integer, intent(out) :: stat");
  emit("    real(c_double) :: x_phi, x_re, value");
  if (has_extra) emit("    real(c_double) :: x_extra(" + std::to_string(t.num_extra) + ")");
  if (has_extra) emit("    integer :: k");
  emit("    stat = 1");
  emit("    if (range_policy < 0 .or. range_policy > 2) return");
  emit("    ! Comparisons with NaN are false, so NaN fails these tests too.");
  emit("    if (.not. (phi >= 0.0_c_double .and. phi < 1.0_c_double)) return");
  emit("    if (.not. (re >= 0.0_c_double .and. re <= huge(re))) return");
  if (has_extra) {
    emit("    do k = 1, " + std::to_string(t.num_extra));
    emit("      if (.not. (abs(extra(k)) <= huge(extra(k)))) return");
    emit("    end do");
    emit("    x_extra = extra");
  }
  emit("    x_phi = phi");
  emit("    x_re = re");
  emit("    stat = 0");
  std::string outside = "phi < " + bl(box.phi.min) + " .or. phi > " + bl(box.phi.max) +
                        " .or. re < " + bl(box.re.min) + " .or. re > " + bl(box.re.max);
  for (int k = 0; k < t.num_extra; ++k) {
    const InputRange& e = box.extra[static_cast<std::size_t>(k)].range;
    const std::string x = "extra(" + std::to_string(k + 1) + ")";
    outside += " .or. " + x + " < " + bl(e.min) + " .or. " + x + " > " + bl(e.max);
  }
  emit("    if (" + outside + ") then");
  emit("      stat = 2");
  emit("      if (range_policy == 0) return");
  emit("    end if");
  emit("    if (stat == 2 .and. range_policy == 1) then");
  clamp("x_phi", "phi", box.phi.min, box.phi.max);
  clamp("x_re", "re", box.re.min, box.re.max);
  for (int k = 0; k < t.num_extra; ++k) {
    const InputRange& e = box.extra[static_cast<std::size_t>(k)].range;
    clamp("x_extra(" + std::to_string(k + 1) + ")", "extra(" + std::to_string(k + 1) + ")", e.min,
          e.max);
  }
  emit("    end if");
  emit("    value = " + id + "_F(x_phi, x_re" + (has_extra ? ", x_extra" : "") + ")");
  emit("    if (.not. (abs(value) <= huge(value))) then");
  emit("      stat = 8");
  emit("      return");
  emit("    end if");
  emit("    F = value");
  emit("  end subroutine " + id + "_F_checked");
  out.push_back("");

  // beta_checked, dga_checked
  auto checked_dimensional = [&](const std::string& what, const std::string& formula,
                                 const std::string& doc) {
    out.push_back("  ! " + doc + " with input checks; stat and range_policy as in _F_checked.");
    emit("  pure subroutine " + id + "_" + what + "_checked(" + dims + extra_arg +
         ", range_policy, res, stat)");
    emit("    real(c_double), intent(in) :: " + dims);
    if (has_extra) emit(extra_decl);
    emit("    integer, intent(in) :: range_policy");
    emit("    real(c_double), intent(inout) :: res");
    emit("    integer, intent(out) :: stat");
    emit("    real(c_double) :: phi, re, F");
    emit("    stat = 1");
    emit("    if (.not. (eps_g > 0.0_c_double .and. eps_g <= 1.0_c_double)) return");
    emit("    if (.not. (mu_g > 0.0_c_double .and. mu_g <= huge(mu_g))) return");
    emit("    if (.not. (rho_g > 0.0_c_double .and. rho_g <= huge(rho_g))) return");
    emit("    if (.not. (d_p > 0.0_c_double .and. d_p <= huge(d_p))) return");
    emit("    if (.not. (slip >= 0.0_c_double .and. slip <= huge(slip))) return");
    emit("    phi = 1.0_c_double - eps_g");
    emit("    re = rho_g * eps_g * d_p * slip / mu_g");
    emit("    F = 0.0_c_double");
    emit("    call " + id + "_F_checked(phi, re" + extra_arg + ", range_policy, F, stat)");
    emit("    if (stat /= 0 .and. .not. (stat == 2 .and. range_policy /= 0)) return");
    emit("    res = " + formula);
    emit("  end subroutine " + id + "_" + what + "_checked");
    out.push_back("");
  };
  checked_dimensional(
      "beta", "phi * (1.0_c_double - phi) * F * 18.0_c_double * (mu_g / (d_p * d_p))", "beta");
  checked_dimensional("dga", "eps_g * F * 18.0_c_double * (mu_g / (d_p * d_p))", "MFiX's lDgA");

  emit("end module " + module);
  std::ostringstream o;
  for (const std::string& l : out) o << l << "\n";
  return o.str();
}

// ---- JSON ------------------------------------------------------------------------------------

nlohmann::ordered_json number_or_null(double x) {
  if (std::isfinite(x)) return x;
  return nullptr;  // JSON has no inf/NaN; an unbounded side of a box is null
}

std::string export_json(const LawRecord& r) {
  const LawForm* form = nullptr;
  try {
    form = &find_law_form(r.form);
  } catch (const Error&) {
    form = nullptr;  // the record is still exportable; descriptions are just missing
  }
  nlohmann::ordered_json j;
  j["name"] = r.name;
  j["version"] = r.version;
  j["reference"] = r.reference();
  j["form"] = r.form;
  if (form != nullptr) j["form_title"] = form->description.title;
  j["status"] = to_string(r.status);
  if (r.status == LawStatus::kRetracted) j["retraction_reason"] = r.retraction_reason;
  j["content_hash"] = r.content_hash;
  j["created_at"] = r.created_at;
  nlohmann::ordered_json params = nlohmann::ordered_json::array();
  for (std::size_t i = 0; i < r.parameters.size(); ++i) {
    const LawParameter& p = r.parameters[i];
    nlohmann::ordered_json jp;
    jp["name"] = p.name;
    jp["value"] = number_or_null(p.value);
    jp["unit"] = p.unit;
    if (form != nullptr && i < form->description.parameters.size()) {
      jp["description"] = form->description.parameters[i].description;
    }
    params.push_back(jp);
  }
  j["parameters"] = params;
  // Covariance as n rows of n values (stored row-major); null when the record has none.
  const std::size_t n = r.parameters.size();
  if (!r.covariance.empty() && r.covariance.size() == n * n) {
    nlohmann::ordered_json rows = nlohmann::ordered_json::array();
    for (std::size_t a = 0; a < n; ++a) {
      nlohmann::ordered_json row = nlohmann::ordered_json::array();
      for (std::size_t b = 0; b < n; ++b) row.push_back(number_or_null(r.covariance[a * n + b]));
      rows.push_back(row);
    }
    j["covariance"] = rows;
  } else {
    j["covariance"] = nullptr;
  }
  j["convention"] = {{"force", to_string(r.convention.force)},
                     {"normalisation", to_string(r.convention.normalisation)},
                     {"reynolds", to_string(r.convention.reynolds)},
                     {"tfm_model", to_string(r.convention.tfm_model)}};
  j["canonical"] = {{"F", "F_d / (3 pi mu d eps u), drag only, u interstitial slip"},
                    {"Re", "rho eps d u / mu (superficial)"},
                    {"beta", "18 mu phi eps F / d^2 [kg m^-3 s^-1]"},
                    {"K", "F / (1 - phi), total force incl. mean pressure gradient"}};
  nlohmann::ordered_json extra = nlohmann::ordered_json::array();
  for (const ExtraInputSpec& e : r.validity.extra) {
    extra.push_back({{"name", e.name},
                     {"description", e.description},
                     {"min", number_or_null(e.range.min)},
                     {"max", number_or_null(e.range.max)}});
  }
  j["validity"] = {
      {"phi",
       {{"min", number_or_null(r.validity.phi.min)}, {"max", number_or_null(r.validity.phi.max)}}},
      {"re",
       {{"min", number_or_null(r.validity.re.min)}, {"max", number_or_null(r.validity.re.max)}}},
      {"extra", extra}};
  j["provenance"] = {{"kind", r.provenance.kind},
                     {"citation", r.provenance.citation},
                     {"dataset_id", r.provenance.dataset_id},
                     {"data_hash", r.provenance.data_hash},
                     {"fitter_settings", r.provenance.fitter_settings},
                     {"code_version", r.provenance.code_version}};
  j["notes"] = r.notes;
  j["generated_by"] = std::string("draglab ") + kDragDbVersion;
  return j.dump(2) + "\n";
}

}  // namespace

ExportFormat export_format_from_string(const std::string& s) {
  const std::string lower = to_lower(s);
  if (lower == "c") return ExportFormat::kC;
  if (lower == "fortran" || lower == "f90") return ExportFormat::kFortran;
  if (lower == "json") return ExportFormat::kJson;
  throw Error(ErrorCode::kInvalidArgument,
              "export format '" + s + "' is not one of: c, fortran, json");
}

const char* to_string(ExportFormat format) {
  switch (format) {
    case ExportFormat::kFortran:
      return "fortran";
    case ExportFormat::kJson:
      return "json";
    case ExportFormat::kC:
    default:
      return "c";
  }
}

const char* file_extension(ExportFormat format) {
  switch (format) {
    case ExportFormat::kFortran:
      return "f90";
    case ExportFormat::kJson:
      return "json";
    case ExportFormat::kC:
    default:
      return "c";
  }
}

std::string export_identifier(const LawRecord& record) {
  std::string name = sanitize_identifier(record.name);
  // Fortran names are at most 63 characters; the longest derived one is ID + "_beta_checked".
  constexpr std::size_t kMaxName = 36;
  if (name.size() > kMaxName) {
    name = name.substr(0, kMaxName - 9) + "_" + record.content_hash.substr(0, 8);
  }
  return to_lower(name) + "_v" + std::to_string(record.version);
}

std::string export_law(const LawRecord& record, ExportFormat format) {
  switch (format) {
    case ExportFormat::kFortran:
      return export_fortran(record);
    case ExportFormat::kJson:
      return export_json(record);
    case ExportFormat::kC:
    default:
      return export_c(record);
  }
}

}  // namespace draglab

// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Syntax tree of the IC model language (.icm), the concrete form of the thesis' notation
// (Kravtsov 2011, ch. 4.3-4.4; docs/icm.md). Every node keeps its source position (1-based line
// and column) so that the engine can report errors against the model text.

#include <memory>
#include <string>
#include <vector>

namespace ictk::lang::icm
{

struct Pos
{
  int line = 0;
  int column = 0;
};

/// A name as written, with its position.
struct Name
{
  Pos pos;
  std::string text;
};

struct Expr;
using ExprPtr = std::shared_ptr<Expr>;

struct Expr
{
  enum class Kind
  {
    Number,
    Bool,
    String,
    Name,       ///< text
    CellType,   ///< P-CELL ... T-CELL (text)
    Dim,        ///< 0D ... 4D (number)
    Member,     ///< kids[0].text
    Index,      ///< kids[0][kids[1]]
    Call,       ///< text(kids...): a built-in or a model function (`IC::` prefix dropped)
    Unary,      ///< text kids[0]: "-" or "!"
    Binary,     ///< kids[0] text kids[1]
    Brace,      ///< { kids... }
    Placeholder ///< "..." (notation mode only)
  };
  Kind kind = Kind::Number;
  Pos pos;
  std::string text;
  double number = 0;
  int height = 1; ///< of the subtree (bounded by the parser)
  std::vector<ExprPtr> kids;
};

struct Stmt;
using StmtPtr = std::shared_ptr<Stmt>;

struct Stmt
{
  enum class Kind
  {
    Block,  ///< body
    Local,  ///< type name = value
    Assign, ///< target op value (op is "=", "+=", "-=", "*=" or "/=")
    Eval,   ///< value; (a call for its effect)
    If,     ///< if (cond) body else elseBody
    For,    ///< for name in from..to body (bounded)
    Return, ///< return value
    Placeholder
  };
  Kind kind = Kind::Block;
  Pos pos;
  std::string type; ///< Local: the type as written
  std::string name; ///< Local / For: the variable
  std::string op;   ///< Assign: the operator
  ExprPtr target, value, cond, from, to;
  std::vector<StmtPtr> body, elseBody;
};

/// A formal parameter of a reaction, predicate or function: `REAL globalT`.
struct Formal
{
  Pos pos;
  std::string type;
  std::string name;
};

/// `[Cell.]init|terminate|update|updatePost|react(formals) { ... }`, a predicate
/// (`bool evaluate(...)`) or a function (`function name(...)`).
struct Procedure
{
  Pos pos;
  Name cell; ///< empty unless the reaction belongs to a named cell (Cell.update(...))
  Name name;
  std::string resultType; ///< predicate: "bool"; function: optional
  std::vector<Formal> formals;
  std::vector<StmtPtr> body;
};

/// `name = values;` inside a cell, attribute or event (type, shape, dim, domain, lifespan,
/// priority, timespan, mapping, deformation).
struct Property
{
  Pos pos;
  std::string name;
  std::vector<ExprPtr> values;
  bool isHyperFun = false;  ///< `shape = hyperfun { ... }`
  std::string hyperFunText; ///< the text between the braces, verbatim
  Pos hyperFunPos;          ///< where that text starts (for readHyperFun diagnostics)
};

/// One entry of a `parameters` or STATE_PARAMETERS block.
struct ParamDecl
{
  enum class Kind
  {
    Typed, ///< name : TYPE(args);  name : array of TYPE;
    Init,  ///< translation(args);  (a predefined parameter)
    Alias, ///< path name;  (names a parameter of a cell or instance)
    Placeholder
  };
  Kind kind = Kind::Typed;
  Pos pos;
  Name name;
  Name type;
  bool array = false;
  std::vector<ExprPtr> args;
  ExprPtr alias;
};

/// `USE T.CELLS \ { a b } U { c };`
struct Use
{
  Pos pos;
  ExprPtr what;
  std::vector<Name> minus, plus;
};

/// A cell or attribute definition: `name [<- source] { properties parameters REACTIONS }`.
struct CellDef
{
  Pos pos;
  Name name;
  Name source;
  std::vector<Property> properties;
  std::vector<ParamDecl> parameters;
  std::vector<Procedure> reactions;
  const Property* property(const std::string& name) const;
};

struct AttributesSection;

/// Cells: definitions, references, USE, and the instance's custom reactions of cells.
struct CellsSection
{
  Pos pos;
  std::vector<CellDef> defs;
  std::vector<Name> refs;
  std::vector<Use> uses;
  std::vector<Procedure> reactions;
  std::vector<AttributesSection> attributes;
};

/// A topological relation (containment / boundary) `a b [name];`, a dependency
/// `master slave [priority | HIERARCHICAL] [name];`, or an attribute link `cell attr;` /
/// `cell.attributes = attr;`.
struct Relation
{
  Pos pos;
  std::vector<ExprPtr> ends; ///< the two ends
  bool hasPriority = false;
  double priority = 1.0; ///< the thesis' default
  bool hierarchical = false;
  Name name;
};

struct RelationsSection
{
  Pos pos;
  std::vector<Relation> containment, boundary, dependency;
  std::vector<Use> containmentUses, boundaryUses, dependencyUses;
};

struct AttributesSection
{
  Pos pos;
  std::vector<CellDef> defs;
  std::vector<std::pair<Name, Name>> bindings; ///< attr = mapper;
  Name defaultAttribute;
  std::vector<Use> uses;
  std::vector<Relation> links; ///< cell -> attribute (ends[0] cell, ends[1] attribute name)
  std::vector<Procedure> reactions;
};

/// An IC template (`T : TEMPLATE_IC { ... }`) or instance (`K [: T] { ... }`).
struct Instance
{
  Pos pos;
  Name name;
  bool isTemplate = false;
  Name base; ///< the template an instance starts from (`K1 : INITIAL_TEMPLATE`)
  std::vector<ParamDecl> stateParameters, parameters;
  std::vector<CellsSection> cells;
  std::vector<RelationsSection> relations;
  std::vector<AttributesSection> attributes;
  std::vector<Procedure> reactions;
  std::vector<Procedure> predicates;
};

struct Timespan
{
  Pos pos;
  Name name;
  std::vector<ExprPtr> args;
};

struct Event
{
  Pos pos;
  Name name;
  std::vector<ParamDecl> parameters;
  std::vector<Property> properties; ///< priority, timespan
};

/// A whole .icm file.
struct Model
{
  std::string fileName;
  std::string directory; ///< the folder of the file (readIcmFile), for `file("x.hf")`
  Name name;             ///< `name = X;`
  std::vector<Timespan> timespans;
  std::vector<Event> events;
  std::vector<CellsSection> cells;
  std::vector<AttributesSection> attributes;
  std::vector<ParamDecl> stateParameters, parameters;
  std::vector<Instance> instances; ///< templates and instances, in file order
  std::vector<Procedure> functions;
  /// `ANIMATIONS { name { keys = {t, x, y, z}, ...; interpolation = linear; ... } }`: named
  /// animation curves (thesis Table 3) for animation(), animationValue(), animationDuration().
  std::vector<CellDef> animations;
  /// `cycles = previous | reevaluate | cut;`: how dependency cycles are evaluated (docs/icm.md).
  Name cycles;
  /// `steps = keep | grow;`: after a step refined by TIME_REJECTED is accepted, keep its size
  /// until the requested time (the default) or double it again (docs/icm.md).
  Name steps;
  // Fragments (notation mode only): sections outside any instance.
  std::vector<RelationsSection> relations;
  std::vector<Procedure> reactions, predicates;

  const CellDef* cell(const std::string& name) const;
  const Instance* instance(const std::string& name) const;
  const Event* event(const std::string& name) const;
  const CellDef* animation(const std::string& name) const;
};

} // namespace ictk::lang::icm

// SPDX-License-Identifier: BSD-3-Clause
// The recursive-descent parser of the IC model language (IcmParser.h; grammar in docs/icm.md).
// One file of more than 1,000 lines on purpose: it is one class, Parser, whose grammar functions
// (top-level items, sections, cells, attributes, instances, relations, reactions, statements,
// expressions) call each other and share the token cursor, the error recovery and the nesting and
// node budgets. Splitting it by section would put the whole class in a header and spread one
// grammar over several files without making any part independent of the rest.
#include "Lang/IcmParser.h"

#include "Lang/IcmLexer.h"

#include <string>

namespace ictk::lang::icm
{

namespace
{

struct Abort
{};
struct Fatal
{};

class Parser
{
public:
  Parser(
    const hf::SourceText& source, hf::DiagnosticSink& sink, const Limits& limits, bool notation)
    : sink_(sink)
    , limits_(limits)
    , notation_(notation)
  {
    const std::size_t maxTokens = limits.maxSyntaxNodes < 16 ? 16 : limits.maxSyntaxNodes;
    toks_ = tokenize(source, sink, maxTokens);
  }

  Model run()
  {
    Model m;
    try
    {
      while (!is(Tok::End))
      {
        const std::size_t before = i_;
        try
        {
          topItem(m);
        }
        catch (const Abort&)
        {
          i_ = before;
          recover();
        }
        if (i_ == before)
        {
          if (is(Tok::RBrace))
          {
            error(cur(), "unmatched '}'");
          }
          take();
        }
      }
    }
    catch (const Fatal&)
    {
    }
    return m;
  }

private:
  std::vector<Token> toks_;
  std::size_t i_ = 0;
  hf::DiagnosticSink& sink_;
  const Limits& limits_;
  bool notation_;
  int depth_ = 0;
  std::size_t nodes_ = 0;

  struct Depth
  {
    Parser& p;
    explicit Depth(Parser& parser)
      : p(parser)
    {
      if (++p.depth_ > p.limits_.maxNesting)
      {
        p.error(p.cur(),
          "nesting too deep (more than " + std::to_string(p.limits_.maxNesting) + " levels)");
        throw Fatal{};
      }
    }
    ~Depth() { --p.depth_; }
    Depth(const Depth&) = delete;
    Depth& operator=(const Depth&) = delete;
  };

  // ---- tokens -------------------------------------------------------------------------------
  const Token& cur() const { return toks_[i_]; }
  const Token& at(std::size_t ahead) const
  {
    return i_ + ahead < toks_.size() ? toks_[i_ + ahead] : toks_.back();
  }
  bool is(Tok k) const { return cur().kind == k; }
  bool isWord(const char* w) const { return is(Tok::Ident) && cur().text == w; }
  bool isWordAt(std::size_t ahead, const char* w) const
  {
    return at(ahead).kind == Tok::Ident && at(ahead).text == w;
  }
  Token take()
  {
    Token t = cur();
    if (i_ + 1 < toks_.size())
    {
      ++i_;
    }
    return t;
  }
  bool accept(Tok k)
  {
    if (is(k))
    {
      take();
      return true;
    }
    return false;
  }
  static Pos pos(const Token& t) { return Pos{ t.line, t.column }; }

  static std::string describe(const Token& t)
  {
    switch (t.kind)
    {
      case Tok::Ident:
        return "'" + t.text + "'";
      case Tok::Number:
        return "number " + t.text;
      case Tok::String:
        return "string \"" + t.text + "\"";
      case Tok::CellType:
      case Tok::Dim:
        return t.text;
      default:
        return tokName(t.kind);
    }
  }

  void error(const Token& t, const std::string& message)
  {
    if (!sink_.error(t.line, t.column, message) || sink_.full())
    {
      throw Fatal{};
    }
  }
  [[noreturn]] void fail(const Token& t, const std::string& message)
  {
    error(t, message);
    throw Abort{};
  }
  [[noreturn]] void expected(const std::string& what)
  {
    if (is(Tok::Invalid))
    {
      throw Abort{}; // already reported by the lexer
    }
    fail(cur(), "expected " + what + ", found " + describe(cur()));
  }
  Token expect(Tok k, const std::string& what)
  {
    if (!is(k))
    {
      expected(what);
    }
    return take();
  }
  Name name(const std::string& what)
  {
    const Token t = expect(Tok::Ident, what);
    return Name{ pos(t), t.text };
  }
  void node()
  {
    if (++nodes_ > limits_.maxSyntaxNodes)
    {
      error(cur(),
        "the model is too large (more than " + std::to_string(limits_.maxSyntaxNodes) +
          " syntax nodes)");
      throw Fatal{};
    }
  }

  // Skips a broken item from its first token: to a ';' (consumed) or a '}' that closes the
  // enclosing block (not consumed). A braced group is skipped whole; when it is a block (after a
  // name or ')', not a list after '=' or ','), it ends the item.
  void recover()
  {
    int depth = 0;
    bool block = false;
    while (!is(Tok::End))
    {
      if (is(Tok::LBrace))
      {
        if (depth == 0)
        {
          const Tok before = i_ > 0 ? toks_[i_ - 1].kind : Tok::End;
          block = before == Tok::Ident || before == Tok::RParen || before == Tok::End ||
            before == Tok::Semi || before == Tok::RBrace || before == Tok::LBrace;
        }
        ++depth;
      }
      else if (is(Tok::RBrace))
      {
        if (depth == 0)
        {
          return;
        }
        if (--depth == 0 && block)
        {
          take();
          if (is(Tok::Semi))
          {
            take();
          }
          return;
        }
      }
      else if (is(Tok::Semi) && depth == 0)
      {
        take();
        return;
      }
      take();
    }
  }

  // '{' items '}', each item parsed by `item`; a broken item is skipped.
  template <class F>
  void block(const std::string& what, F&& item)
  {
    Depth guard(*this);
    const Token open = expect(Tok::LBrace, "'{' to open " + what);
    while (!is(Tok::RBrace))
    {
      if (is(Tok::End))
      {
        fail(open, "'{' of " + what + " is never closed");
      }
      const std::size_t before = i_;
      try
      {
        item();
      }
      catch (const Abort&)
      {
        i_ = before;
        recover();
      }
      if (i_ == before && !is(Tok::RBrace) && !is(Tok::End))
      {
        take(); // always make progress
      }
    }
    take();
  }

  // `...` or a lone `:` where an item may stand (notation mode only).
  bool placeholderItem()
  {
    if (is(Tok::Ellipsis) || is(Tok::Colon))
    {
      if (!notation_)
      {
        fail(cur(), "placeholder " + describe(cur()) + " in a model: write the actual value");
      }
      take();
      accept(Tok::Semi);
      return true;
    }
    return false;
  }

  // ---- top level ----------------------------------------------------------------------------
  void topItem(Model& m)
  {
    if (placeholderItem())
    {
      return;
    }
    if (isWord("name") && at(1).kind == Tok::Assign)
    {
      take();
      take();
      m.name = name("the model name");
      expect(Tok::Semi, "';'");
    }
    else if (isWord("cycles") && at(1).kind == Tok::Assign)
    {
      take();
      take();
      m.cycles = name("the cycle policy (previous, reevaluate or cut)");
      expect(Tok::Semi, "';'");
    }
    else if (isWord("steps") && at(1).kind == Tok::Assign)
    {
      take();
      take();
      m.steps = name("the step policy after TIME_REJECTED (keep or grow)");
      expect(Tok::Semi, "';'");
    }
    else if (isWord("ANIMATIONS"))
    {
      take();
      block("ANIMATIONS", [&] { m.animations.push_back(cellDef()); });
    }
    else if (isWord("TIMESPANS"))
    {
      take();
      block("TIMESPANS", [&] { timespan(m); });
    }
    else if (isWord("EVENTS"))
    {
      take();
      block("EVENTS", [&] { event(m); });
    }
    else if (isWord("CELLS"))
    {
      m.cells.push_back(cells());
    }
    else if (isWord("ATTRIBUTES"))
    {
      m.attributes.push_back(attributes());
    }
    else if (isWord("STATE_PARAMETERS"))
    {
      take();
      parameters("STATE_PARAMETERS", m.stateParameters);
    }
    else if (isWord("parameters"))
    {
      take();
      parameters("parameters", m.parameters);
    }
    else if (isWord("function"))
    {
      take();
      Procedure f;
      f.pos = pos(cur());
      f.name = name("a function name");
      formals(f);
      f.body = blockBody();
      m.functions.push_back(std::move(f));
    }
    else if (isWord("RELATIONS") || isWord("REACTIONS") || isWord("PREDICATE"))
    {
      if (!notation_)
      {
        fail(cur(), cur().text + " outside an instance or template");
      }
      if (isWord("RELATIONS"))
      {
        m.relations.push_back(relations());
      }
      else if (isWord("REACTIONS"))
      {
        take();
        reactions(m.reactions);
      }
      else
      {
        take();
        predicate(m.predicates);
      }
    }
    else if (is(Tok::Ident))
    {
      m.instances.push_back(instance());
    }
    else
    {
      expected("a section (TIMESPANS, EVENTS, ANIMATIONS, CELLS, ATTRIBUTES, STATE_PARAMETERS, a "
               "template, an instance or a function)");
    }
  }

  void timespan(Model& m)
  {
    if (placeholderItem())
    {
      return;
    }
    Timespan t;
    t.pos = pos(cur());
    t.name = name("a time span name");
    expect(Tok::Colon, "':'");
    if (!isWord("TIMESPAN"))
    {
      expected("TIMESPAN");
    }
    take();
    if (is(Tok::LParen))
    {
      t.args = callArgs();
    }
    expect(Tok::Semi, "';'");
    m.timespans.push_back(std::move(t));
  }

  void event(Model& m)
  {
    if (placeholderItem())
    {
      return;
    }
    Event e;
    e.pos = pos(cur());
    e.name = name("an event name");
    block("event " + e.name.text,
      [&]
      {
        if (placeholderItem())
        {
          return;
        }
        if (isWord("parameters"))
        {
          take();
          parameters("parameters", e.parameters);
          return;
        }
        e.properties.push_back(property());
      });
    m.events.push_back(std::move(e));
  }

  // ---- cells --------------------------------------------------------------------------------
  Property property()
  {
    Property p;
    p.pos = pos(cur());
    p.name = expect(Tok::Ident, "a property (type, shape, dim, domain, ...)").text;
    expect(Tok::Assign, "'=' after '" + p.name + "'");
    if (is(Tok::HyperFun))
    {
      const Token t = take();
      p.isHyperFun = true;
      p.hyperFunText = t.text;
      p.hyperFunPos = Pos{ t.textLine, t.textColumn };
      accept(Tok::Semi);
      return p;
    }
    p.values.push_back(expr());
    while (accept(Tok::Comma))
    {
      p.values.push_back(expr());
    }
    expect(Tok::Semi, "';' after the value of '" + p.name + "'");
    return p;
  }

  CellDef cellDef()
  {
    CellDef c;
    c.pos = pos(cur());
    c.name = name("a cell name");
    if (accept(Tok::Arrow))
    {
      c.source = name("the source cell after '<-'");
    }
    block("cell " + c.name.text,
      [&]
      {
        if (placeholderItem())
        {
          return;
        }
        if (isWord("parameters"))
        {
          take();
          parameters("parameters", c.parameters);
        }
        else if (isWord("REACTIONS"))
        {
          take();
          reactions(c.reactions);
        }
        else
        {
          c.properties.push_back(property());
        }
      });
    accept(Tok::Semi);
    return c;
  }

  CellsSection cells()
  {
    CellsSection s;
    s.pos = pos(take());
    block("CELLS",
      [&]
      {
        if (placeholderItem())
        {
          return;
        }
        if (isWord("USE"))
        {
          s.uses.push_back(use());
        }
        else if (isWord("REACTIONS"))
        {
          take();
          reactions(s.reactions);
        }
        else if (isWord("ATTRIBUTES"))
        {
          s.attributes.push_back(attributes());
        }
        else if (is(Tok::Ident) && (at(1).kind == Tok::LBrace || at(1).kind == Tok::Arrow))
        {
          s.defs.push_back(cellDef());
        }
        else if (is(Tok::Ident))
        {
          while (is(Tok::Ident))
          {
            s.refs.push_back(name("a cell name"));
          }
          expect(Tok::Semi, "';' after the cell names");
        }
        else
        {
          expected("a cell definition, cell names, USE or REACTIONS");
        }
      });
    return s;
  }

  std::vector<Name> nameSet()
  {
    std::vector<Name> out;
    if (accept(Tok::LBrace))
    {
      while (is(Tok::Ident))
      {
        out.push_back(name("a name"));
        accept(Tok::Comma);
      }
      expect(Tok::RBrace, "'}' closing the set of names");
    }
    else
    {
      while (is(Tok::Ident))
      {
        out.push_back(name("a name"));
      }
      if (out.empty())
      {
        expected("a name or '{'");
      }
    }
    return out;
  }

  Use use()
  {
    Use u;
    u.pos = pos(take());
    u.what = path("what to use (e.g. TEMPLATE.CELLS)");
    if (accept(Tok::Backslash))
    {
      if (!is(Tok::LBrace))
      {
        expected("'{' after '\\'");
      }
      u.minus = nameSet();
    }
    if (isWord("U"))
    {
      take();
      u.plus = nameSet();
    }
    expect(Tok::Semi, "';' after USE");
    return u;
  }

  // name { '.' name | '[' number-or-string ']' }
  ExprPtr path(const std::string& what)
  {
    if (!is(Tok::Ident))
    {
      expected(what);
    }
    const Token first = take();
    ExprPtr e = make(Expr::Kind::Name, first);
    e->text = first.text;
    for (;;)
    {
      if (is(Tok::Dot))
      {
        take();
        const Name member = name("a member name after '.'");
        ExprPtr m = make(Expr::Kind::Member, cur());
        m->pos = member.pos;
        m->text = member.text;
        m->kids.push_back(e);
        e = grown(m);
      }
      else if (is(Tok::LBracket))
      {
        const Token open = take();
        ExprPtr ix = make(Expr::Kind::Index, open);
        ix->kids.push_back(e);
        if (is(Tok::Number) || is(Tok::String))
        {
          const Token t = take();
          ExprPtr k = make(t.kind == Tok::Number ? Expr::Kind::Number : Expr::Kind::String, t);
          k->number = t.number;
          k->text = t.text;
          ix->kids.push_back(k);
        }
        else if (is(Tok::Ident))
        {
          // `inst.Rd[cellA, cellB]`: the unnamed relations between two cells.
          do
          {
            const Token t = expect(Tok::Ident, "a cell name");
            ExprPtr k = make(Expr::Kind::Name, t);
            k->text = t.text;
            ix->kids.push_back(k);
          } while (accept(Tok::Comma) && ix->kids.size() < 16);
        }
        else
        {
          expected("a number, a string or cell names in '[...]'");
        }
        expect(Tok::RBracket, "']'");
        e = grown(ix);
      }
      else
      {
        return e;
      }
    }
  }

  void parameters(const std::string& what, std::vector<ParamDecl>& out)
  {
    block(what,
      [&]
      {
        if (placeholderItem())
        {
          return;
        }
        ParamDecl p;
        p.pos = pos(cur());
        if (is(Tok::Ident) && at(1).kind == Tok::Colon)
        {
          p.kind = ParamDecl::Kind::Typed;
          p.name = name("a parameter name");
          take();
          if (isWord("array") && isWordAt(1, "of"))
          {
            take();
            take();
            p.array = true;
          }
          p.type = name("a type (REAL, INT, BOOL, VECTOR3, STRING, TRANSFORM)");
          if (is(Tok::LParen))
          {
            p.args = callArgs();
          }
          if (!accept(Tok::Semi) && !notation_)
          {
            expected("';' after the parameter");
          }
        }
        else if (is(Tok::Ident) && at(1).kind == Tok::LParen)
        {
          p.kind = ParamDecl::Kind::Init;
          p.name = name("a parameter name");
          p.args = callArgs();
          expect(Tok::Semi, "';'");
        }
        else
        {
          p.kind = ParamDecl::Kind::Alias;
          p.alias = path("a parameter declaration 'name : TYPE(value);' or an alias 'path name;'");
          p.name = name("the alias name after the path");
          expect(Tok::Semi, "';'");
        }
        out.push_back(std::move(p));
      });
  }

  // ---- attributes ---------------------------------------------------------------------------
  AttributesSection attributes()
  {
    AttributesSection s;
    s.pos = pos(take());
    block("ATTRIBUTES",
      [&]
      {
        if (placeholderItem())
        {
          return;
        }
        if (isWord("USE"))
        {
          s.uses.push_back(use());
        }
        else if (isWord("REACTIONS"))
        {
          take();
          reactions(s.reactions);
        }
        else if (isWord("RELATIONS"))
        {
          take();
          block("the attribute RELATIONS",
            [&]
            {
              if (placeholderItem())
              {
                return;
              }
              Relation r;
              r.pos = pos(cur());
              r.ends.push_back(path("a cell"));
              accept(Tok::Assign);
              const Token a = expect(Tok::Ident, "an attribute name");
              ExprPtr e = make(Expr::Kind::Name, a);
              e->text = a.text;
              r.ends.push_back(e);
              expect(Tok::Semi, "';'");
              s.links.push_back(std::move(r));
            });
        }
        else if (isWord("default") && at(1).kind == Tok::Assign)
        {
          take();
          take();
          s.defaultAttribute = name("the default attribute");
          expect(Tok::Semi, "';'");
        }
        else if (is(Tok::Ident) && at(1).kind == Tok::Assign)
        {
          Name attr = name("an attribute name");
          take();
          Name mapper = name("a mapping name");
          expect(Tok::Semi, "';'");
          s.bindings.emplace_back(std::move(attr), std::move(mapper));
        }
        else if (is(Tok::Ident) && (at(1).kind == Tok::LBrace || at(1).kind == Tok::Arrow))
        {
          s.defs.push_back(cellDef());
        }
        else if (is(Tok::Ident))
        {
          // `T.ATTRIBUTES;`: the thesis' App. C writes USE without the word.
          const Token t = cur();
          Use u;
          u.pos = pos(t);
          u.what = path("an attribute reference");
          expect(Tok::Semi, "';'");
          if (!notation_)
          {
            error(t, "write 'USE' before a reference to other attributes");
          }
          s.uses.push_back(std::move(u));
        }
        else
        {
          expected("an attribute definition, 'name = mapping;', default, USE or RELATIONS");
        }
      });
    return s;
  }

  // ---- templates and instances --------------------------------------------------------------
  Instance instance()
  {
    Instance in;
    in.pos = pos(cur());
    in.name = name("an instance name");
    if (accept(Tok::Colon))
    {
      if (isWord("TEMPLATE_IC"))
      {
        take();
        in.isTemplate = true;
      }
      else
      {
        in.base = name("TEMPLATE_IC or the name of a template");
      }
    }
    else if (accept(Tok::Arrow))
    {
      in.base = name("a template name");
    }
    if (!is(Tok::LBrace))
    {
      expected("'{' to open instance " + in.name.text + " (or a section keyword)");
    }
    block((in.isTemplate ? "template " : "instance ") + in.name.text,
      [&]
      {
        if (placeholderItem())
        {
          return;
        }
        if (isWord("CELLS"))
        {
          in.cells.push_back(cells());
        }
        else if (isWord("ATTRIBUTES"))
        {
          in.attributes.push_back(attributes());
        }
        else if (isWord("RELATIONS"))
        {
          in.relations.push_back(relations());
        }
        else if (isWord("REACTIONS"))
        {
          take();
          reactions(in.reactions);
        }
        else if (isWord("PREDICATE"))
        {
          take();
          predicate(in.predicates);
        }
        else if (isWord("STATE_PARAMETERS"))
        {
          take();
          parameters("STATE_PARAMETERS", in.stateParameters);
        }
        else if (isWord("parameters"))
        {
          take();
          parameters("parameters", in.parameters);
        }
        else
        {
          expected("CELLS, ATTRIBUTES, RELATIONS, REACTIONS, PREDICATE, STATE_PARAMETERS or "
                   "parameters");
        }
      });
    accept(Tok::Semi);
    return in;
  }

  // ---- relations ----------------------------------------------------------------------------
  RelationsSection relations()
  {
    RelationsSection s;
    s.pos = pos(take());
    block("RELATIONS",
      [&]
      {
        if (placeholderItem())
        {
          return;
        }
        const Token kw = cur();
        if (isWord("containment") || isWord("boundary"))
        {
          take();
          const bool containment = kw.text == "containment";
          block(kw.text,
            [&]
            {
              if (placeholderItem())
              {
                return;
              }
              if (isWord("USE"))
              {
                (containment ? s.containmentUses : s.boundaryUses).push_back(use());
                return;
              }
              (containment ? s.containment : s.boundary).push_back(relation(false, kw.text));
            });
        }
        else if (isWord("dependency"))
        {
          take();
          block("dependency",
            [&]
            {
              if (placeholderItem())
              {
                return;
              }
              if (isWord("USE"))
              {
                s.dependencyUses.push_back(use());
                return;
              }
              s.dependency.push_back(relation(true, "dependency"));
            });
        }
        else
        {
          expected("containment, boundary or dependency");
        }
      });
    return s;
  }

  // One relation: the words up to ';', then checked for arity and kind.
  Relation relation(bool dependency, const std::string& kind)
  {
    Relation r;
    r.pos = pos(cur());
    std::vector<std::pair<Token, ExprPtr>> words; // the token that starts each word
    while (!is(Tok::Semi))
    {
      const Token t = cur();
      if (is(Tok::Ident))
      {
        words.emplace_back(t, path("a relation end"));
      }
      else if (is(Tok::Number) || is(Tok::String) || is(Tok::Minus))
      {
        const bool negative = accept(Tok::Minus);
        const Token v = take();
        if (v.kind != Tok::Number && negative)
        {
          fail(v, "expected a number after '-'");
        }
        ExprPtr e = make(v.kind == Tok::Number ? Expr::Kind::Number : Expr::Kind::String, t);
        e->number = negative ? -v.number : v.number;
        e->text = v.text;
        words.emplace_back(t, e);
      }
      else if (is(Tok::RBrace) || is(Tok::End))
      {
        expected("';' after the relation");
      }
      else
      {
        fail(t, "unexpected " + describe(t) + " in a " + kind + " relation");
      }
      if (words.size() > 8)
      {
        fail(t, "too many words in a " + kind + " relation");
      }
    }
    const Token semi = take();
    const auto isPath = [](const ExprPtr& e)
    {
      return e->kind == Expr::Kind::Name || e->kind == Expr::Kind::Member ||
        e->kind == Expr::Kind::Index;
    };
    const auto simpleName = [](const ExprPtr& e)
    {
      return e->kind == Expr::Kind::Name;
    };
    if (words.size() < 2 || !isPath(words[0].second) || !isPath(words[1].second))
    {
      const Token& where = words.empty() ? semi : words[0].first;
      fail(where,
        dependency ? "a dependency needs a master and a slave ('A.x B.y [priority | "
                     "HIERARCHICAL] [name];'), found " +
            std::to_string(words.size()) + " end(s)"
                   : "a " + kind + " relation needs two cells ('A B [name];'), found " +
            std::to_string(words.size()) + " end(s)");
    }
    r.ends = { words[0].second, words[1].second };
    std::size_t k = 2;
    if (!dependency)
    {
      for (int e = 0; e < 2; ++e)
      {
        if (!simpleName(words[static_cast<std::size_t>(e)].second))
        {
          fail(words[static_cast<std::size_t>(e)].first,
            "the ends of a " + kind + " relation are cell names, not paths");
        }
      }
    }
    else if (words.size() > 2)
    {
      const ExprPtr& q = words[2].second;
      const bool hier = q->kind == Expr::Kind::Name && q->text == "HIERARCHICAL";
      if (q->kind == Expr::Kind::Number)
      {
        r.hasPriority = true;
        r.priority = q->number;
        k = 3;
      }
      else if (hier)
      {
        r.hierarchical = true;
        k = 3;
      }
      else if (words.size() > 3 || !simpleName(q))
      {
        fail(words[2].first,
          "the priority of a dependency must be a number or HIERARCHICAL, "
          "found " +
            describe(words[2].first));
      }
    }
    if (k < words.size())
    {
      if (!simpleName(words[k].second) || words[k].second->text == "HIERARCHICAL")
      {
        fail(words[k].first, "expected a relation name, found " + describe(words[k].first));
      }
      r.name = Name{ words[k].second->pos, words[k].second->text };
      ++k;
    }
    if (k < words.size())
    {
      fail(words[k].first,
        dependency ? "too many words in a dependency: 'master slave [priority | HIERARCHICAL] "
                     "[name];'"
                   : "too many words in a " + kind + " relation: 'A B [name];'");
    }
    return r;
  }

  // ---- reactions and code -------------------------------------------------------------------
  void formals(Procedure& p)
  {
    expect(Tok::LParen, "'(' opening the parameter list");
    if (!is(Tok::RParen))
    {
      do
      {
        Formal f;
        f.pos = pos(cur());
        f.type = name("a parameter type").text;
        f.name = name("a parameter name").text;
        p.formals.push_back(std::move(f));
        if (p.formals.size() > 64)
        {
          fail(cur(), "too many parameters");
        }
      } while (accept(Tok::Comma));
    }
    expect(Tok::RParen, "')' closing the parameter list");
  }

  void reactions(std::vector<Procedure>& out)
  {
    block("REACTIONS",
      [&]
      {
        if (placeholderItem())
        {
          return;
        }
        Procedure p;
        p.pos = pos(cur());
        p.name = name("a reaction (init, terminate, update, updatePost, react)");
        if (accept(Tok::Dot))
        {
          p.cell = p.name;
          p.name = name("a reaction name after the cell");
        }
        formals(p);
        p.body = blockBody();
        out.push_back(std::move(p));
      });
  }

  void predicate(std::vector<Procedure>& out)
  {
    block("PREDICATE",
      [&]
      {
        if (placeholderItem())
        {
          return;
        }
        Procedure p;
        p.pos = pos(cur());
        p.resultType = name("'bool evaluate(...)'").text;
        p.name = name("'evaluate'");
        formals(p);
        p.body = blockBody();
        out.push_back(std::move(p));
      });
  }

  std::vector<StmtPtr> blockBody()
  {
    std::vector<StmtPtr> body;
    block("a block", [&] { body.push_back(statement()); });
    return body;
  }

  StmtPtr makeStmt(Stmt::Kind kind, const Token& t)
  {
    node();
    auto s = std::make_shared<Stmt>();
    s->kind = kind;
    s->pos = pos(t);
    return s;
  }

  StmtPtr statement()
  {
    Depth guard(*this);
    const Token t = cur();
    if (is(Tok::Ellipsis) || is(Tok::Colon))
    {
      placeholderItem();
      return makeStmt(Stmt::Kind::Placeholder, t);
    }
    if (is(Tok::LBrace))
    {
      StmtPtr s = makeStmt(Stmt::Kind::Block, t);
      s->body = blockBody();
      return s;
    }
    if (isWord("if"))
    {
      take();
      StmtPtr s = makeStmt(Stmt::Kind::If, t);
      expect(Tok::LParen, "'(' after if");
      s->cond = expr();
      expect(Tok::RParen, "')' closing the condition");
      s->body.push_back(statement());
      if (isWord("else"))
      {
        take();
        s->elseBody.push_back(statement());
      }
      return s;
    }
    if (isWord("for"))
    {
      take();
      StmtPtr s = makeStmt(Stmt::Kind::For, t);
      s->name = name("the loop variable").text;
      if (!isWord("in"))
      {
        expected("'in' (for i in 0..n)");
      }
      take();
      s->from = additive();
      expect(Tok::DotDot, "'..' between the loop bounds");
      s->to = additive();
      s->body = blockBody();
      return s;
    }
    if (isWord("return"))
    {
      take();
      StmtPtr s = makeStmt(Stmt::Kind::Return, t);
      if (!is(Tok::Semi))
      {
        s->value = expr();
      }
      expect(Tok::Semi, "';' after return");
      return s;
    }
    if (is(Tok::Ident) && at(1).kind == Tok::Ident && at(2).kind == Tok::Assign)
    {
      StmtPtr s = makeStmt(Stmt::Kind::Local, t);
      s->type = take().text;
      s->name = take().text;
      take();
      s->value = expr();
      expect(Tok::Semi, "';' after the declaration");
      return s;
    }
    ExprPtr e = expr();
    const Tok k = cur().kind;
    if (k == Tok::Assign || k == Tok::PlusAssign || k == Tok::MinusAssign || k == Tok::StarAssign ||
      k == Tok::SlashAssign)
    {
      const Token op = take();
      if (e->kind != Expr::Kind::Name && e->kind != Expr::Kind::Member &&
        e->kind != Expr::Kind::Index)
      {
        fail(t, "the left side of " + describe(op) + " is not a variable or a property");
      }
      StmtPtr s = makeStmt(Stmt::Kind::Assign, t);
      s->op = op.text;
      s->target = e;
      s->value = expr();
      expect(Tok::Semi, "';' after the assignment");
      return s;
    }
    StmtPtr s = makeStmt(Stmt::Kind::Eval, t);
    s->value = e;
    expect(Tok::Semi, "';' after the statement");
    return s;
  }

  // ---- expressions --------------------------------------------------------------------------
  ExprPtr make(Expr::Kind kind, const Token& t)
  {
    node();
    auto e = std::make_shared<Expr>();
    e->kind = kind;
    e->pos = pos(t);
    return e;
  }

  ExprPtr binary(const Token& op, ExprPtr a, ExprPtr b)
  {
    ExprPtr e = make(Expr::Kind::Binary, op);
    e->text = op.text;
    e->kids = { std::move(a), std::move(b) };
    return grown(e);
  }

  // Sets the height of a node from its kids; a chain of operators or members longer than the
  // limit is refused (the checker and the destructor recurse along it).
  ExprPtr grown(ExprPtr e)
  {
    int h = 0;
    for (const ExprPtr& k : e->kids)
    {
      h = k->height > h ? k->height : h;
    }
    e->height = h + 1;
    if (e->height > maxHeight())
    {
      error(cur(),
        "expression too long (more than " + std::to_string(maxHeight()) + " levels of operators)");
      throw Fatal{};
    }
    return e;
  }
  int maxHeight() const { return limits_.maxNesting < 1 ? 5 : limits_.maxNesting * 5; }

  ExprPtr expr()
  {
    Depth guard(*this);
    ExprPtr e = conjunction();
    while (is(Tok::Or))
    {
      const Token op = take();
      e = binary(op, e, conjunction());
    }
    return e;
  }
  ExprPtr conjunction()
  {
    ExprPtr e = comparison();
    while (is(Tok::And))
    {
      const Token op = take();
      e = binary(op, e, comparison());
    }
    return e;
  }
  ExprPtr comparison()
  {
    ExprPtr e = additive();
    if (is(Tok::Eq) || is(Tok::Ne) || is(Tok::Lt) || is(Tok::Le) || is(Tok::Gt) || is(Tok::Ge))
    {
      const Token op = take();
      e = binary(op, e, additive());
      if (is(Tok::Eq) || is(Tok::Ne) || is(Tok::Lt) || is(Tok::Le) || is(Tok::Gt) || is(Tok::Ge))
      {
        fail(cur(), "comparisons do not chain: use && between them");
      }
    }
    return e;
  }
  ExprPtr additive()
  {
    ExprPtr e = multiplicative();
    while (is(Tok::Plus) || is(Tok::Minus))
    {
      const Token op = take();
      e = binary(op, e, multiplicative());
    }
    return e;
  }
  ExprPtr multiplicative()
  {
    ExprPtr e = unary();
    while (is(Tok::Star) || is(Tok::Slash))
    {
      const Token op = take();
      e = binary(op, e, unary());
    }
    return e;
  }
  ExprPtr unary()
  {
    if (is(Tok::Minus) || is(Tok::Not) || is(Tok::Plus))
    {
      Depth guard(*this);
      const Token op = take();
      ExprPtr operand = unary();
      if (op.kind == Tok::Plus)
      {
        return operand;
      }
      ExprPtr e = make(Expr::Kind::Unary, op);
      e->text = op.text;
      e->kids.push_back(operand);
      return grown(e);
    }
    return postfix();
  }
  std::vector<ExprPtr> callArgs()
  {
    Depth guard(*this);
    expect(Tok::LParen, "'('");
    std::vector<ExprPtr> args;
    if (!is(Tok::RParen))
    {
      do
      {
        args.push_back(expr());
      } while (accept(Tok::Comma));
    }
    expect(Tok::RParen, "')' closing the arguments");
    return args;
  }
  ExprPtr postfix()
  {
    ExprPtr e = primary();
    for (;;)
    {
      if (is(Tok::Dot))
      {
        take();
        const Name member = name("a member name after '.'");
        ExprPtr m = make(Expr::Kind::Member, cur());
        m->pos = member.pos;
        m->text = member.text;
        m->kids.push_back(e);
        e = grown(m);
      }
      else if (is(Tok::LBracket))
      {
        Depth guard(*this);
        const Token open = take();
        ExprPtr ix = make(Expr::Kind::Index, open);
        ix->kids.push_back(e);
        ix->kids.push_back(expr());
        expect(Tok::RBracket, "']'");
        e = grown(ix);
      }
      else if (is(Tok::LParen))
      {
        const Token open = cur();
        ExprPtr call = make(Expr::Kind::Call, open);
        const Expr* root = e.get();
        while (!root->kids.empty())
        {
          root = root->kids[0].get();
        }
        call->pos = root->pos;
        call->text = e->kind == Expr::Kind::Name ? e->text : std::string();
        call->kids.push_back(e);
        for (ExprPtr& a : callArgs())
        {
          call->kids.push_back(std::move(a));
        }
        e = grown(call);
      }
      else
      {
        return e;
      }
    }
  }
  ExprPtr primary()
  {
    const Token t = cur();
    switch (t.kind)
    {
      case Tok::Number:
      {
        take();
        ExprPtr e = make(Expr::Kind::Number, t);
        e->number = t.number;
        e->text = t.text;
        return e;
      }
      case Tok::String:
      {
        take();
        ExprPtr e = make(Expr::Kind::String, t);
        e->text = t.text;
        return e;
      }
      case Tok::CellType:
      {
        take();
        ExprPtr e = make(Expr::Kind::CellType, t);
        e->text = t.text;
        return e;
      }
      case Tok::Dim:
      {
        take();
        ExprPtr e = make(Expr::Kind::Dim, t);
        e->number = t.number;
        e->text = t.text;
        return e;
      }
      case Tok::Ident:
      {
        take();
        if (t.text == "true" || t.text == "false")
        {
          ExprPtr e = make(Expr::Kind::Bool, t);
          e->number = t.text == "true" ? 1 : 0;
          e->text = t.text;
          return e;
        }
        ExprPtr e = make(Expr::Kind::Name, t);
        e->text = t.text;
        while (is(Tok::Scope))
        {
          take();
          e->text += "::" + name("a name after '::'").text;
        }
        return e;
      }
      case Tok::LParen:
      {
        take();
        ExprPtr e = expr();
        expect(Tok::RParen, "')'");
        return e;
      }
      case Tok::LBrace:
      {
        Depth guard(*this);
        take();
        ExprPtr e = make(Expr::Kind::Brace, t);
        if (!is(Tok::RBrace))
        {
          do
          {
            e->kids.push_back(expr());
          } while (accept(Tok::Comma));
        }
        expect(Tok::RBrace, "'}' closing the list");
        return grown(e);
      }
      case Tok::Ellipsis:
        if (notation_)
        {
          take();
          return make(Expr::Kind::Placeholder, t);
        }
        fail(t, "placeholder '...' in a model: write the actual value");
      default:
        expected("an expression");
    }
  }
};

} // namespace

Model parse(
  const hf::SourceText& source, hf::DiagnosticSink& sink, const Limits& limits, bool notation)
{
  Parser p(source, sink, limits, notation);
  Model m = p.run();
  m.fileName = source.fileName();
  return m;
}

} // namespace ictk::lang::icm

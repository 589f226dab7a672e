// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// HyperFun syntax tree. Nodes live in flat arrays and refer to each other by index, so that a
// large tree is freed without recursion; chains of left-associative operators are one n-ary node,
// so that `f1 | f2 | ... | fn` does not make a deep tree. Only brackets, calls, unary operators and
// blocks nest, and the parser bounds their depth by Limits::maxNesting.
//
// Grammar (HyperFun's, interpreter_lib/int_parse_N.c, with conditions merged into expressions):
//   program   := function*
//   function  := name '(' param {',' param} ')' '{' statement* '}'      params: x[n], a[m], s[k]
//   statement := 'array' name '[' N ']' {',' name '[' N ']'} ';'
//              | name '=' expr ';'  |  name '=' '[' expr {',' expr} ']' ';'
//              | name '[' expr ']' '=' expr ';'
//              | name '(' args ')' ';'                                   (a call for its effect)
//              | 'if' expr 'then' statement* ['else' statement*] 'endif' ';'
//              | 'while' expr 'loop' statement* 'endloop' ';'
//   expr      := logic, from the lowest precedence:
//                and or xor  <  not  <  = /= < <= > >=  <  + - | & \ @  <  * /  <  ^  <  unary + -
//                ~
//   All binary operators are left-associative (also ^, as HyperFun), and a unary operator binds
//   tighter than ^ (HyperFun: -x^2 is (-x)^2).

#include "Lang/HyperFunLexer.h"

#include <string>
#include <vector>

namespace ictk::lang::hf
{

struct ExprNode
{
  enum class Kind : std::uint8_t
  {
    Number,
    Variable, ///< a scalar or an array named as a whole (a library argument)
    Index,    ///< name[kids[0]]
    Call,     ///< name(kids...)
    Unary,    ///< ops[0] kids[0]
    Chain     ///< kids[0] ops[0] kids[1] ops[1] ... (left to right)
  };
  Kind kind = Kind::Number;
  int line = 0;
  int column = 0;
  double number = 0;
  std::string name;     ///< lower-cased
  std::string spelling; ///< as written
  std::vector<int> kids;
  std::vector<TokenKind> ops;
  std::vector<std::pair<int, int>> opPositions; ///< (line, column) of each operator
};

struct Statement
{
  enum class Kind : std::uint8_t
  {
    ArrayDecl,
    Assign,
    AssignIndex,
    AssignList,
    If,
    While,
    Call
  };
  struct Declared
  {
    std::string name, spelling;
    int size = 0;
    int line = 0, column = 0;
  };
  Kind kind = Kind::Assign;
  int line = 0;
  int column = 0;
  std::string name;
  std::string spelling;
  int expr = -1;  ///< value, condition or call
  int index = -1; ///< AssignIndex: the index expression
  std::vector<int> list;
  std::vector<Declared> declared;
  std::vector<int> thenBody;
  std::vector<int> elseBody;
};

struct Function
{
  struct Param
  {
    std::string name, spelling;
    int size = 0;
    int line = 0, column = 0;
  };
  std::string name;
  std::string spelling;
  int line = 0;
  int column = 0;
  int endLine = 0;
  int endColumn = 0;
  std::vector<Param> params;
  std::vector<int> body;
};

struct Program
{
  std::vector<ExprNode> exprs;
  std::vector<Statement> statements;
  std::vector<Function> functions;
};

/// Parses the whole text, reporting syntax errors to `sink` and recovering at statement and
/// function boundaries. Returns what could be parsed.
Program parse(const SourceText& source, DiagnosticSink& sink, const Limits& limits);

} // namespace ictk::lang::hf

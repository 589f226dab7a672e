// SPDX-License-Identifier: BSD-3-Clause
// Cell, attribute, instance and model parameters (thesis L1018-1029, L1411-1415, Table 2 L4091).
//
// P_c^i(t) = { global parameters p_G, local parameters p_L } (L1020): local ones are visible only
// inside their owner, global ones outside it. "Parameters are expressions involving other
// parameters" (L1025): a parameter is either a plain value (set by reactions or animations,
// L1029) or an frep::Expr over the other parameters' slots (Expr::parameter(slot)), evaluated in
// dependency order (a topological sort; a cycle is an error that names the parameters on it).
//
// Slots are assigned in definition order and never reused, so the evaluation order is a pure
// function of the definitions (no hashing, no threads).
#pragma once

#include "FRep/Expr.h"

#include <cstdint>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace ictk::dyn
{

enum class Scope
{
  Local, ///< visible only inside its owner (L1020)
  Global ///< exposed outside its owner (L1020)
};

using ParamSlot = std::uint32_t;

/// Thrown when the expressions form a cycle; what() and `cycle` name the parameters on it.
class ParameterCycleError : public std::runtime_error
{
public:
  ParameterCycleError(const std::string& what, std::vector<std::string> names)
    : std::runtime_error(what)
    , cycle(std::move(names))
  {
  }
  std::vector<std::string> cycle; ///< qualified names, first repeated at the end: a -> b -> a
};

class ParameterTable
{
public:
  /// A plain parameter `owner.name` (owner "" = the model; its qualified name is just `name`).
  /// Throws std::invalid_argument if the qualified name exists already.
  ParamSlot add(const std::string& owner, const std::string& name, Scope scope, double value);
  /// A parameter defined by an expression over other slots. Every referenced slot must exist and
  /// be visible from `owner` (global, or local to the same owner); otherwise
  /// std::invalid_argument. Forward references are allowed through setExpression.
  ParamSlot addExpression(
    const std::string& owner, const std::string& name, Scope scope, const frep::Expr& e);

  /// Sets a plain value (turns an expression parameter into a plain one).
  void setValue(ParamSlot slot, double v);
  void setValue(const std::string& qualifiedName, double v) { setValue(slot(qualifiedName), v); }
  /// (Re)defines the expression of a parameter (same visibility checks as addExpression).
  void setExpression(ParamSlot slot, const frep::Expr& e);

  std::size_t size() const { return entries_.size(); }
  std::optional<ParamSlot> find(const std::string& qualifiedName) const;
  /// find() or std::out_of_range naming the parameter.
  ParamSlot slot(const std::string& qualifiedName) const;
  const std::string& name(ParamSlot s) const { return entries_.at(s).qualified; }
  const std::string& owner(ParamSlot s) const { return entries_.at(s).owner; }
  Scope scope(ParamSlot s) const { return entries_.at(s).scope; }
  bool hasExpression(ParamSlot s) const { return entries_.at(s).expr.has_value(); }
  /// Whether a reader inside `reader` (an owner name, "" for the model) may read slot s.
  bool visibleFrom(ParamSlot s, const std::string& reader) const;
  /// The slots an expression parameter reads (ascending; empty for plain values).
  std::vector<ParamSlot> inputs(ParamSlot s) const;

  /// Expression parameters in an order where each comes after the expression parameters it
  /// reads (Kahn's algorithm, smallest ready slot first). Throws ParameterCycleError.
  std::vector<ParamSlot> evaluationOrder() const;
  /// Recomputes every expression parameter in evaluationOrder().
  void evaluate();

  double value(ParamSlot s) const { return values_.at(s); }
  double value(const std::string& qualifiedName) const { return values_.at(slot(qualifiedName)); }
  const std::vector<double>& values() const { return values_; }

private:
  struct Entry
  {
    std::string owner, qualified;
    Scope scope = Scope::Global;
    std::optional<frep::Expr> expr;
  };
  void checkVisible(const std::string& owner, const frep::Expr& e) const;

  std::vector<Entry> entries_;
  std::vector<double> values_;
  std::map<std::string, ParamSlot> byName_;
};

} // namespace ictk::dyn

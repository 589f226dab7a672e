// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Modelling domains (thesis section 3.4.1, Table 1, L1105-L1114) and FRep shapes typed by them.

#include "FRep/Expr.h"

#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace ictk::frep
{

/// The seven modelling domains of thesis Table 1.
enum class Domain : std::uint8_t
{
  X,
  T,
  XY,
  XT,
  XYZ,
  XYT,
  XYZT
};

const char* domainName(Domain d);
/// Bit i set when Axis(i) is a coordinate of the domain.
std::uint8_t domainAxes(Domain d);
int domainDimension(Domain d);
/// The coordinates of the domain in order, e.g. XYT -> {X, Y, T}.
std::vector<Axis> domainCoordinates(Domain d);
/// The domain whose coordinate set is exactly `axes`, if it is one of the seven.
std::optional<Domain> domainFromAxes(std::uint8_t axes);
std::optional<Domain> domainFromName(const std::string& name);
bool domainContains(Domain outer, Domain inner);

/// Raised when an operation combines entities of incompatible modelling domains
/// (thesis footnote 4, L1118: a CSG operation between a 2D circle and a 3D block).
class DomainError : public std::invalid_argument
{
public:
  using std::invalid_argument::invalid_argument;
};

/// An FRep object: f >= 0 inside (thesis L517-L526, threshold 0), over a modelling domain.
/// The expression may use only the domain's coordinates (checked on construction).
class Shape
{
public:
  Shape(Expr f, Domain domain, std::string label = {});

  const Expr& function() const { return f_; }
  Domain domain() const { return domain_; }
  /// A short name used in diagnostics ("sphere", "union", ...).
  const std::string& label() const { return label_; }
  Shape withLabel(std::string label) const { return Shape(f_, domain_, std::move(label)); }
  /// "'block' (domain XYZ)" for messages.
  std::string describe() const;

private:
  Expr f_;
  Domain domain_;
  std::string label_;
};

/// Throws DomainError naming `operation` and both operands unless they share one domain.
void requireSameDomain(const char* operation, const Shape& a, const Shape& b);
/// Throws DomainError unless the shape's domain contains every axis in `axes`.
void requireAxes(const char* operation, const Shape& s, std::uint8_t axes);

/// "Reduce dimensionality" re-projection (thesis L1128-L1135): the lower-dimensional shape `s`
/// is transferred into the domain `target`; coordinate i of s's domain is read from axis
/// `axisMap[i]` of the target. The result is constant along the target axes that are not mapped
/// (an extrusion). Example (L1139): a circle on XY placed on the XZ plane of XYZ is
/// `reproject(circle, Domain::XYZ, {Axis::X, Axis::Z})`.
Shape reproject(const Shape& s, Domain target, const std::vector<Axis>& axisMap);

} // namespace ictk::frep

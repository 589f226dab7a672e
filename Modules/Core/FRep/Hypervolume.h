// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Constructive hypervolumes (thesis 2.2.3, L681-L717): geometry plus attribute functions, each
// defined on a space partition with inside/outside defaults.

#include "FRep/Domain.h"
#include "FRep/Evaluators.h"

#include <string>
#include <vector>

namespace ictk::frep
{

/// One attribute A_i = (S_i, g_i, theta1_i, theta0_i). Components: 1 for a scalar (density),
/// 3 or 4 for a colour or vector, rows*cols for a tensor (row-major).
struct Attribute
{
  std::string name;
  std::vector<Expr> components;
  /// Space partition g_i: the attribute is S_i where g_i >= 0. Defaults to everywhere.
  Expr partition = Expr(1.0);
  /// theta1_i: the value inside the geometry where g_i < 0.
  std::vector<double> insideDefault;
  /// theta0_i: the value outside the geometry where g_i < 0.
  std::vector<double> outsideDefault;
  /// 0 for scalars and vectors; for a tensor the number of rows (components = rows * cols).
  int tensorRows = 0;
};

class Hypervolume
{
public:
  explicit Hypervolume(Shape geometry, double threshold = 0.0);

  /// Adds an attribute; throws std::invalid_argument on empty or duplicate names, component
  /// counts that disagree with the defaults, or coordinates outside the geometry's domain.
  Hypervolume& addAttribute(Attribute attribute);

  const Shape& geometry() const { return geometry_; }
  double threshold() const { return threshold_; }
  const std::vector<Attribute>& attributes() const { return attributes_; }
  const Attribute* findAttribute(const std::string& name) const;
  /// Total number of attribute components.
  std::size_t attributeComponentCount() const;

  /// One tape computing, in order: f, then for each attribute g_i and its components.
  TapePtr compile() const;

private:
  Shape geometry_;
  double threshold_;
  std::vector<Attribute> attributes_;
};

/// The space-time of a 2D model (domain XYT: a shape in the plane changing over time) as the XYZ
/// solid it is, z standing for t: geometry, partitions and attribute components with t replaced
/// by z. This is how the thesis shows space-time objects (figs. 93-95): the solid's slices
/// z = t are the model's cross-sections. Throws DomainError for another domain.
Hypervolume spaceTimeSolid(const Hypervolume& hv);

/// Evaluates a hypervolume at points: f and the attribute values with the default rule of thesis
/// L715, read consistently (thesis_ch2_3.md section 0.5): S_i where g_i >= 0, theta1 where
/// f >= T, theta0 elsewhere.
class HypervolumeEvaluator
{
public:
  explicit HypervolumeEvaluator(const Hypervolume& hv, const std::vector<double>& parameters = {});
  /// Writes f into `value` and attributeComponentCount() values into `attributes`.
  void eval(const std::array<double, 4>& p, double& value, double* attributes);
  /// Point membership relation (thesis eq. 2, L673-L677): 0 outside, 1 on the boundary, 2 inside.
  int membership(const std::array<double, 4>& p);

private:
  const Hypervolume& hv_;
  PointEvaluator evaluator_;
  std::vector<double> outputs_;
};

} // namespace ictk::frep

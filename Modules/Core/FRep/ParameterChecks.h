// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The parameter checks of the FRep shape libraries (Primitives.cxx, Implants.cxx): every failure
// is a std::invalid_argument whose message names the shape and the parameter, e.g.
// "sphere: radius r must be positive (got -1)", so a bad model file points at its mistake.

#include "FRep/Primitives.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace ictk::frep::detail
{

[[noreturn]] inline void fail(const char* primitive, const std::string& what)
{
  throw std::invalid_argument(std::string(primitive) + ": " + what);
}

inline std::string show(double v)
{
  std::ostringstream out;
  out.precision(12);
  out << v;
  return out.str();
}

inline void requireFinite(const char* primitive, const std::string& name, double v)
{
  if (!std::isfinite(v))
  {
    fail(primitive, name + " must be finite (got " + show(v) + ")");
  }
}

template <std::size_t N>
void requireFinite(const char* primitive, const std::string& name, const std::array<double, N>& v)
{
  for (double c : v)
  {
    if (!std::isfinite(c))
    {
      fail(primitive, name + " must have finite coordinates (got " + show(c) + ")");
    }
  }
}

inline void requirePositive(const char* primitive, const std::string& name, double v)
{
  requireFinite(primitive, name, v);
  if (!(v > 0))
  {
    fail(primitive, name + " must be positive (got " + show(v) + ")");
  }
}

} // namespace ictk::frep::detail

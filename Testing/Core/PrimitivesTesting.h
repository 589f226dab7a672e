// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// What the tests of the FRep primitive library share (TestPrimitives.cxx, TestConvolution.cxx):
// evaluation at a point by the reference evaluator, a random point generator that gives the same
// points on every platform, and the check of a constructor's std::invalid_argument.
#include "FRep/Evaluators.h"
#include "FRep/Primitives.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

namespace primitivestest
{
using namespace ictk::frep;

inline constexpr double pi = 3.14159265358979323846;
inline const double notANumber = std::numeric_limits<double>::quiet_NaN();
inline const double infinity = std::numeric_limits<double>::infinity();

inline double at(const Expr& e, double x, double y = 0, double z = 0, double t = 0)
{
  return evaluateReference(e, { x, y, z, t });
}

inline double at(const Shape& s, double x, double y = 0, double z = 0, double t = 0)
{
  return at(s.function(), x, y, z, t);
}

inline double at(const Shape& s, const Vec3& p)
{
  return at(s.function(), p[0], p[1], p[2]);
}

inline double at(const Expr& e, const Vec3& p)
{
  return at(e, p[0], p[1], p[2]);
}

/// Uniform numbers with a mapping of our own, so that the random points are the same everywhere.
class Random
{
public:
  explicit Random(std::uint64_t seed)
    : engine_(seed)
  {
  }
  double uniform(double lo, double hi)
  {
    return lo + (hi - lo) * static_cast<double>(engine_() >> 11) * 0x1.0p-53;
  }
  Vec3 point(double lo, double hi) { return { uniform(lo, hi), uniform(lo, hi), uniform(lo, hi) }; }

private:
  std::mt19937_64 engine_;
};

/// Expects std::invalid_argument whose message contains every word.
inline void expectInvalid(const std::function<void()>& build, const std::vector<std::string>& words)
{
  try
  {
    build();
    ADD_FAILURE() << "no exception; expected one mentioning '" << words.front() << "'";
  }
  catch (const std::invalid_argument& e)
  {
    const std::string message = e.what();
    for (const std::string& w : words)
    {
      EXPECT_NE(message.find(w), std::string::npos) << "'" << w << "' missing from: " << message;
    }
  }
}

} // namespace primitivestest

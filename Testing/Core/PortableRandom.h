// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The random numbers of the kernel's tests (TestEvaluators, TestJit, TestCauchySegment): the same
// sequence with every standard library, which std::uniform_real_distribution does not give, so
// that a failure seen on one machine is seen on all.

#include <array>
#include <cstdint>
#include <random>

namespace ictk::fixtures
{

struct PortableRandom
{
  explicit PortableRandom(unsigned seed)
    : engine(seed)
  {
  }
  /// Uniform in [lo, hi), from the generator's top 53 bits.
  double uniform(double lo, double hi)
  {
    return lo + (hi - lo) * (static_cast<double>(engine() >> 11) * 0x1.0p-53);
  }
  /// One of 0 .. n - 1.
  int index(int n) { return static_cast<int>(engine() % static_cast<std::uint64_t>(n)); }
  /// A point uniform in the cube [lo, hi)^3.
  std::array<double, 3> point(double lo, double hi)
  {
    return { uniform(lo, hi), uniform(lo, hi), uniform(lo, hi) };
  }
  std::mt19937_64 engine;
};

} // namespace ictk::fixtures

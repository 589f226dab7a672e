// SPDX-License-Identifier: BSD-3-Clause
#pragma once
// Procedural solid textures (seed 004's TextureTree, papers.md 3.5: "marble, wood, granite-like
// noise"): a scalar pattern s(p) in [0, 1] that mixes two colours, written once for both scalar
// types of the kernel, double (direct evaluation) and Expr (lowered to the expression DAG, so the
// textures are attributes that every evaluator, sampler, mesher and tet labeller reads).
//
// The noise is deterministic: value noise on the integer lattice, its lattice values from an
// arithmetic hash (multiplications, additions and floor only, no sine, so every evaluator gives
// the same bits up to rounding), interpolated with the C^1 weights u = f^2 (3 - 2f).
//
//   hash(i, j, k): a = fr(0.1031 i), b = fr(0.1031 j), c = fr(0.1031 k),
//                  d = a (c + 33.33) + b (b + 33.33) + c (a + 33.33),
//                  hash = fr((a + d + b + d) (c + d))             (fr(x) = x - floor(x))
//   noise(p)     = trilinear mix of hash at the 8 corners of p's lattice cell, weights u(fr(p))
//   fbm(p, n)    = sum_{o < n} 2^-o noise(2^o p) / sum_{o < n} 2^-o          (in [0, 1])
//
// Patterns, in the frame of the texture node (warps above it move the texture with the geometry,
// papers.md line 207), with period or scale lambda, turbulence amplitude a and n octaves:
//   marble:  s = (1 + sin(2 pi (x + a fbm(p / lambda, n)) / lambda)) / 2   (veins across x)
//   wood:    s = fr((sqrt(x^2 + y^2) + a fbm(p / lambda, n)) / lambda)       (rings about z)
//   granite: s = fbm(p / lambda, n)                                          (speckles)
// The colour is (1 - s) colourA + s colourB.

#include <cmath>

namespace ictk::frep::texture
{

/// The patterns of the texture nodes.
enum class Pattern
{
  Marble,
  Wood,
  Granite
};

constexpr double Pi = 3.14159265358979323846;

/// The largest number of octaves (2^-7 of the first's weight; more is below any colour's step).
constexpr int MaxOctaves = 8;

namespace detail
{
template <class S>
S fr(const S& x)
{
  using std::floor;
  return x - floor(x);
}

template <class S>
S hash(const S& i, const S& j, const S& k)
{
  const S a = fr(i * 0.1031), b = fr(j * 0.1031), c = fr(k * 0.1031);
  const S d = a * (c + 33.33) + b * (b + 33.33) + c * (a + 33.33);
  return fr((a + d + (b + d)) * (c + d));
}

template <class S>
S mix(const S& a, const S& b, const S& u)
{
  return a + (b - a) * u;
}
} // namespace detail

/// Value noise in [0, 1]: at a lattice point (i, j, k) it is hash(i, j, k).
template <class S>
S noise(const S& x, const S& y, const S& z)
{
  using detail::fr;
  using detail::hash;
  using detail::mix;
  using std::floor;
  const S i = floor(x), j = floor(y), k = floor(z);
  const S fx = x - i, fy = y - j, fz = z - k;
  const S ux = fx * fx * (3.0 - 2.0 * fx);
  const S uy = fy * fy * (3.0 - 2.0 * fy);
  const S uz = fz * fz * (3.0 - 2.0 * fz);
  const S i1 = i + 1.0, j1 = j + 1.0, k1 = k + 1.0;
  const S x00 = mix(hash(i, j, k), hash(i1, j, k), ux);
  const S x10 = mix(hash(i, j1, k), hash(i1, j1, k), ux);
  const S x01 = mix(hash(i, j, k1), hash(i1, j, k1), ux);
  const S x11 = mix(hash(i, j1, k1), hash(i1, j1, k1), ux);
  return mix(mix(x00, x10, uy), mix(x01, x11, uy), uz);
}

/// Fractal sum of `octaves` (1..MaxOctaves) octaves of noise, normalised to [0, 1].
template <class S>
S fbm(const S& x, const S& y, const S& z, int octaves)
{
  S sum = noise(x, y, z);
  double weight = 1, total = 1, scale = 1;
  for (int o = 1; o < octaves; ++o)
  {
    weight *= 0.5;
    scale *= 2.0;
    total += weight;
    sum = sum + weight * noise(x * scale, y * scale, z * scale);
  }
  return sum * (1.0 / total);
}

/// The pattern's s(p) in [0, 1] (the formulas above); lambda > 0, 1 <= octaves <= MaxOctaves.
template <class S>
S pattern(
  Pattern kind, const S& x, const S& y, const S& z, double lambda, double amplitude, int octaves)
{
  using std::sin;
  using std::sqrt;
  const double inv = 1.0 / lambda;
  // Marble and wood without turbulence need no noise (and their expressions stay small).
  const S turbulence =
    kind == Pattern::Granite || amplitude != 0 ? fbm(x * inv, y * inv, z * inv, octaves) : S(0.0);
  switch (kind)
  {
    case Pattern::Marble:
      return 0.5 + 0.5 * sin((x + amplitude * turbulence) * (2.0 * Pi * inv));
    case Pattern::Wood:
      return detail::fr((sqrt(x * x + y * y) + amplitude * turbulence) * inv);
    case Pattern::Granite:
    default:
      return turbulence;
  }
}

} // namespace ictk::frep::texture

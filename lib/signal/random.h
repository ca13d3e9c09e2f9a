#pragma once
/// @file Portable, seeded Gaussian noise (docs/models.md section 9; plant sensor noise).
///
/// std::normal_distribution's algorithm is implementation-defined, so the same seed gives
/// different records under libstdc++, libc++ and MSVC. Here everything after the engine is
/// ours: std::mt19937_64 (its output sequence is fixed by the C++ standard), 53-bit uniforms,
/// Marsaglia's polar form of the Box-Muller transform, and a logarithm built from IEEE-exact
/// operations only (+, -, *, /, sqrt, frexp), so a record is bit-identical on any conforming
/// compiler and libm (with FP contraction off, as CMakeLists.txt sets).
#include <cstdint>
#include <random>

namespace rths::signal {

/// Generator state: one plain, copyable struct (copying it replays the sequence).
struct GaussianState {
  std::mt19937_64 engine;       ///< standard-specified 64-bit Mersenne twister
  double spare = 0.0;           ///< second deviate of the last polar pair
  bool has_spare = false;       ///< true if `spare` has not been returned yet
};

/// A generator at the start of the stream for `seed` (any value is allowed).
GaussianState MakeGaussian(std::uint64_t seed);

/// Uniform deviate on [0, 1) with 53 random bits: (engine() >> 11) * 2^-53. Allocates nothing.
double NextUniform(GaussianState* state);

/// Standard normal deviate N(0, 1), Marsaglia polar method: draw u, v uniform on (-1, 1) until
/// 0 < s = u^2 + v^2 < 1, then return u sqrt(-2 ln s / s) now and v sqrt(-2 ln s / s) next
/// time. Allocates nothing.
double NextGaussian(GaussianState* state);

/// Natural logarithm of x > 0 (finite) from frexp and an atanh series:
/// x = m 2^e with m in [sqrt(1/2), sqrt(2)), ln x = e ln 2 + 2 atanh((m - 1)/(m + 1)).
/// Accurate to a few ulp and bit-reproducible everywhere (no libm transcendental is used).
/// Returns NaN for x <= 0 or non-finite x.
double PortableLog(double x);

}  // namespace rths::signal

#pragma once
// What many test files share (one definition, so that a target's files can be compiled as one
// unit): π, 2π and machine epsilon, the harmonic of a sampled periodic record, the largest
// relative difference of two matrices, and bitwise equality of doubles.
#include <Eigen/Core>

#include <bit>
#include <complex>
#include <cstdint>
#include <limits>
#include <numbers>

namespace jointid::test {

inline constexpr double pi = std::numbers::pi;
inline constexpr double two_pi = 2.0 * std::numbers::pi;
inline constexpr double eps = std::numeric_limits<double>::epsilon();

// Harmonic k of a periodic record sampled over whole periods: x = Re Σ X_k e^{ikωt}.
inline std::complex<double> harmonic(const Eigen::VectorXd& x, const Eigen::VectorXd& t,
                                     double omega, int k) {
  std::complex<double> sum = 0.0;
  for (Eigen::Index i = 0; i < x.size(); ++i)
    sum += x(i) * std::polar(1.0, -k * omega * t(i));
  return (k == 0 ? 1.0 : 2.0) / static_cast<double>(x.size()) * sum;
}

// ‖a − b‖ / ‖b‖ (Frobenius norms).
template <class A, class B> double relative_difference(const A& a, const B& b) {
  return (a - b).norm() / b.norm();
}

// The same bits: a value written and read back unchanged.
inline bool same_bits(double a, double b) {
  return std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b);
}

} // namespace jointid::test

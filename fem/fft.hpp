#pragma once
/// Discrete Fourier transforms of real signals through FFTW (Debian's libfftw3), with FFTW's
/// unnormalised convention: forward X_k = Σ_n x_n e^{−2πikn/N}, k = 0 … N/2; inverse
/// x_n = Σ_k X_k e^{2πikn/N} over all N bins (so inverse(forward(x)) = N·x). FFTW's planner is
/// not thread-safe: plans are made and destroyed under one lock; executing them is free.
#include <Eigen/Core>
#include <memory>

namespace jointid::fem {

/// A transform of one length, planned once and executed many times (e.g. Welch's segments).
class RealFft {
public:
  /// Throws std::invalid_argument for n < 2.
  explicit RealFft(int n);
  ~RealFft();
  RealFft(const RealFft&) = delete;
  RealFft& operator=(const RealFft&) = delete;

  int size() const { return n_; }
  /// X_k, k = 0 … n/2, of the n samples x (x.size() must be n; std::invalid_argument else).
  Eigen::VectorXcd forward(const Eigen::Ref<const Eigen::VectorXd>& x);
  /// The real signal of length n whose forward transform is X (n/2 + 1 bins, the others by
  /// Hermitian symmetry; the imaginary parts of DC and, for even n, Nyquist are ignored),
  /// without the 1/n: inverse(forward(x)) = n·x.
  Eigen::VectorXd inverse(const Eigen::Ref<const Eigen::VectorXcd>& X);

private:
  struct Plans;
  int n_;
  std::unique_ptr<Plans> plans_;
};

} // namespace jointid::fem

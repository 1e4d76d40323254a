#include "fem/fft.hpp"

#include <fftw3.h>

#include <complex>
#include <mutex>
#include <stdexcept>
#include <string>

namespace jointid::fem {

namespace {
std::mutex& planner_lock() {
  static std::mutex lock;
  return lock;
}
} // namespace

struct RealFft::Plans {
  double* real = nullptr;
  fftw_complex* spectrum = nullptr;
  fftw_plan forward = nullptr, inverse = nullptr;
};

RealFft::RealFft(int n) : n_(n), plans_(std::make_unique<Plans>()) {
  if (n < 2) throw std::invalid_argument("FFT: expected a length >= 2, got " + std::to_string(n));
  const std::lock_guard<std::mutex> guard(planner_lock());
  plans_->real = fftw_alloc_real(static_cast<std::size_t>(n));
  plans_->spectrum = fftw_alloc_complex(static_cast<std::size_t>(n / 2 + 1));
  if (!plans_->real || !plans_->spectrum) {
    fftw_free(plans_->real);
    fftw_free(plans_->spectrum);
    throw std::bad_alloc();
  }
  // FFTW_ESTIMATE: planning does not overwrite the buffers and takes no measurable time.
  plans_->forward = fftw_plan_dft_r2c_1d(n, plans_->real, plans_->spectrum, FFTW_ESTIMATE);
  plans_->inverse = fftw_plan_dft_c2r_1d(n, plans_->spectrum, plans_->real, FFTW_ESTIMATE);
}

RealFft::~RealFft() {
  const std::lock_guard<std::mutex> guard(planner_lock());
  fftw_destroy_plan(plans_->forward);
  fftw_destroy_plan(plans_->inverse);
  fftw_free(plans_->real);
  fftw_free(plans_->spectrum);
}

Eigen::VectorXcd RealFft::forward(const Eigen::Ref<const Eigen::VectorXd>& x) {
  if (x.size() != n_)
    throw std::invalid_argument("FFT: expected " + std::to_string(n_) + " samples, got " +
                                std::to_string(x.size()));
  for (int i = 0; i < n_; ++i)
    plans_->real[i] = x(i);
  fftw_execute(plans_->forward);
  Eigen::VectorXcd X(n_ / 2 + 1);
  for (int k = 0; k <= n_ / 2; ++k)
    X(k) = {plans_->spectrum[k][0], plans_->spectrum[k][1]};
  return X;
}

Eigen::VectorXd RealFft::inverse(const Eigen::Ref<const Eigen::VectorXcd>& X) {
  if (X.size() != n_ / 2 + 1)
    throw std::invalid_argument("inverse FFT: expected " + std::to_string(n_ / 2 + 1) +
                                " bins, got " + std::to_string(X.size()));
  for (int k = 0; k <= n_ / 2; ++k) {
    plans_->spectrum[k][0] = X(k).real();
    plans_->spectrum[k][1] = X(k).imag();
  }
  fftw_execute(plans_->inverse); // c2r overwrites its input: it is refilled every call
  Eigen::VectorXd x(n_);
  for (int i = 0; i < n_; ++i)
    x(i) = plans_->real[i];
  return x;
}

} // namespace jointid::fem

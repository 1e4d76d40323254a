#pragma once
// A substructure whose response is known in closed form: one mode at 7:uy (3 Hz, 1 % damping,
// φ = 0.25 /√kg), a linear joint to ground there (k, c). Its receptance with the joint is
// X/F = H / (1 + H (k + iωc)), H = φ² / (ω₀² − ω² + 2iζω₀ω), the joint's force −(k y + c ẏ).
#include "constructed.hpp"
#include "frf/substructure.hpp"

#include <cmath>
#include <complex>
#include <numbers>
#include <string>
#include <vector>

namespace jointid::test {

struct OneMode {
  double f0 = 3.0, zeta = 0.01, phi = 0.25;
  double k = 400.0, c = 2.0;

  frf::Substructure substructure() const {
    frf::ModalModel modal;
    modal.dofs = {{7, fem::Dof::uy}};
    modal.frequencies_hz = Eigen::VectorXd::Constant(1, f0);
    modal.damping = Eigen::VectorXd::Constant(1, zeta);
    modal.shapes = Eigen::MatrixXd::Constant(1, 1, phi);
    return frf::Substructure(modal);
  }

  // The joint with values k and c (`fixed`: held, not identified).
  joints::Joint joint(double k_value, double c_value, bool fixed = false) const {
    return {
        "tip",          7, 0, fem::Dof::uy, {joints::Term::k, joints::Term::c}, {k_value, c_value},
        {fixed, fixed}, {}};
  }

  std::complex<double> receptance(double f_hz, double k_value, double c_value) const {
    const double w = 2.0 * std::numbers::pi * f_hz, w0 = 2.0 * std::numbers::pi * f0;
    const std::complex<double> H =
        phi * phi / std::complex<double>(w0 * w0 - w * w, 2.0 * zeta * w0 * w);
    return H / (1.0 + H * std::complex<double>(k_value, w * c_value));
  }

  // A sine test at f_hz driven by F0 sin ωt (F_1 = −i F0), measured as the model with the true
  // k and c gives it (harmonics 0 and 1, the mean unknown), each harmonic's noise variance
  // `variance`.
  identify::Measurement test(double f_hz, double F0, double variance = 1e-16) const {
    const std::complex<double> F1(0.0, -F0);
    return measurement(std::to_string(f_hz) + " Hz, " + std::to_string(F0) + " N", f_hz, F1,
                       {0.0, receptance(f_hz, k, c) * F1}, {variance, variance}, false);
  }

  // Tests at these frequencies and one level; `relative_noise` > 0: each harmonic's noise
  // standard deviation that share of the response's fundamental, else 1e-8 m.
  std::vector<identify::Measurement> tests(const std::vector<double>& frequencies, double F0,
                                           double relative_noise = 0.0) const {
    std::vector<identify::Measurement> out;
    for (double f : frequencies)
      out.push_back(test(f, F0,
                         relative_noise > 0.0
                             ? std::pow(relative_noise, 2) * std::norm(receptance(f, k, c) * F0)
                             : 1e-16));
    return out;
  }
};

// Options that compare the fundamental only, with a small harmonic balance.
inline discover::Options fundamental_only() {
  discover::Options o;
  o.harmonics = {1};
  o.balance.harmonics = 3;
  return o;
}

} // namespace jointid::test

#include "identify/one_mode_fit.hpp"

#include <Eigen/Dense>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace jointid::identify {

OneModeFit fit_one_mode(std::span<const double> freq_hz, const Eigen::VectorXcd& response,
                        const Eigen::VectorXcd& force, const std::complex<double>* residue) {
  const auto n = static_cast<Eigen::Index>(freq_hz.size());
  if (response.size() != n || force.size() != n)
    throw std::invalid_argument("one-mode fit: " + std::to_string(n) + " frequencies, " +
                                std::to_string(response.size()) + " responses and " +
                                std::to_string(force.size()) + " forces");
  OneModeFit out;
  if (n < 3) {
    out.status = fem::Status::failure(fem::Status::Code::not_separable,
                                      "one-mode fit: " + std::to_string(n) +
                                          " rows, expected at least 3 (4 unknowns)");
    return out;
  }
  // Columns ω_n², d, Re A, Im A, each scaled to unit norm (the solve's conditioning).
  Eigen::MatrixXd Q(2 * n, 4);
  Eigen::VectorXd p(2 * n);
  double force_sum = 0.0;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (std::abs(force(i)) == 0.0)
      throw std::invalid_argument("one-mode fit: the force of row " + std::to_string(i + 1) +
                                  " is 0");
    const double w = 2.0 * std::numbers::pi * freq_hz[static_cast<std::size_t>(i)];
    const std::complex<double> H = response(i) / force(i), iwH(0.0, w);
    const std::complex<double> rate = iwH * H, rhs = w * w * H;
    Q.row(2 * i) << H.real(), rate.real(), -1.0, 0.0;
    Q.row(2 * i + 1) << H.imag(), rate.imag(), 0.0, -1.0;
    p(2 * i) = rhs.real(), p(2 * i + 1) = rhs.imag();
    force_sum += std::abs(force(i));
  }
  const Eigen::VectorXd scale = Q.colwise().norm().cwiseMax(1e-300).cwiseInverse();
  const Eigen::MatrixXd Qs = Q * scale.asDiagonal();
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(Qs);
  const Eigen::VectorXd x = scale.cwiseProduct(qr.solve(p));
  const double wn2 = x(0), d = x(1);
  const std::complex<double> A(x(2), x(3));
  out.force_amplitude = force_sum / static_cast<double>(n);
  out.relative_residual = (Q * x - p).norm() / std::max(p.norm(), 1e-300);
  if (!(wn2 > 0.0) || !(d > 0.0)) {
    out.status = fem::Status::failure(
        fem::Status::Code::numerical_issue,
        "one-mode fit: no resonance in the rows (fitted ω_n² = " + std::to_string(wn2) +
            " rad²/s², d = " + std::to_string(d) + " 1/s; expected both > 0)");
    return out;
  }
  // Covariance σ² (QᵀQ)⁻¹ with σ² the residual's variance (2n − 4 degrees of freedom; 0 rows
  // to spare: no estimate, infinite deviations).
  const Eigen::Index dof = 2 * n - 4;
  const double s2 = dof > 0 ? (Q * x - p).squaredNorm() / static_cast<double>(dof)
                            : std::numeric_limits<double>::infinity();
  const Eigen::MatrixXd inverse = (Qs.transpose() * Qs).inverse();
  const Eigen::MatrixXd C = s2 * scale.asDiagonal() * inverse * scale.asDiagonal();
  const double wn = std::sqrt(wn2);
  out.frequency_hz = wn / (2.0 * std::numbers::pi);
  out.frequency_std_hz = std::sqrt(C(0, 0)) / (2.0 * wn) / (2.0 * std::numbers::pi);
  out.damping_ratio = d / (2.0 * wn);
  // D = d / (2 sqrt(ω_n²)): gradient (−d/(4 ω_n³), 1/(2 ω_n)) in (ω_n², d)
  const Eigen::Vector2d g(-d / (4.0 * wn2 * wn), 1.0 / (2.0 * wn));
  out.damping_ratio_std = std::sqrt(std::max(0.0, g.dot(C.topLeftCorner(2, 2) * g)));
  // The level's point at its row nearest resonance (largest |X/F|): the single mode with the
  // fitted residue A and that row's own ω_n² and d, ω_n² − ω² + iωd = A F / X, at |X|.
  Eigen::Index best = 0;
  for (Eigen::Index i = 1; i < n; ++i)
    if (std::abs(response(i) / force(i)) > std::abs(response(best) / force(best))) best = i;
  const double w = 2.0 * std::numbers::pi * freq_hz[static_cast<std::size_t>(best)];
  out.residue = A;
  const std::complex<double> per_row = (residue ? *residue : A) * force(best) / response(best);
  const double row_wn2 = w * w + per_row.real(), row_d = per_row.imag() / w;
  out.amplitude = std::abs(response(best));
  if (row_wn2 > 0.0 && row_d > 0.0) {
    const double row_wn = std::sqrt(row_wn2);
    out.frequency_hz = row_wn / (2.0 * std::numbers::pi);
    out.damping_ratio = row_d / (2.0 * row_wn);
  }
  return out;
}

OneModeFit fit_one_mode(const SteppedSineTable& table, const fem::NodeDof& dof,
                        const std::complex<double>* residue) {
  int force = -1, response = -1;
  char quantity = 0;
  std::string at = fem::to_string(dof);
  at.insert(at.begin(), '@'); // (GCC 12 warns falsely, -Wrestrict, about "@" + a temporary)
  for (std::size_t c = 0; c < table.channels.size(); ++c) {
    const std::string& name = table.channels[c];
    if (name.rfind("f@", 0) == 0) {
      if (force >= 0)
        throw std::invalid_argument("one-mode fit: two force channels, " +
                                    table.channels[static_cast<std::size_t>(force)] + " and " +
                                    name + "; expected one (one force level a table)");
      force = static_cast<int>(c);
    }
    // x before v before a: the displacement itself when the table has it.
    for (const char q : {'x', 'v', 'a'})
      if (name.size() == at.size() + 1 && name.front() == q &&
          name.compare(1, at.size(), at) == 0 &&
          (response < 0 || std::string("xva").find(q) < std::string("xva").find(quantity)))
        response = static_cast<int>(c), quantity = q;
  }
  if (force < 0)
    throw std::invalid_argument("one-mode fit: no force channel (f@NODE:DOF); expected one");
  if (response < 0)
    throw std::invalid_argument("one-mode fit: no response at " + fem::to_string(dof) + " (x" + at +
                                ", v" + at + " or a" + at + ")");
  const Eigen::Index n = table.values.rows();
  Eigen::VectorXcd X(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double w = 2.0 * std::numbers::pi * table.freq_hz[static_cast<std::size_t>(i)];
    const std::complex<double> v = table.values(i, response);
    X(i) = quantity == 'x' ? v : quantity == 'v' ? v / std::complex<double>(0.0, w) : -v / (w * w);
  }
  return fit_one_mode(table.freq_hz, X, table.values.col(force), residue);
}

void share_residue(std::vector<MeasuredBackbonePoint>& levels,
                   const std::vector<SteppedSineTable>& tables, const fem::NodeDof& dof) {
  const MeasuredBackbonePoint* lowest = nullptr;
  for (const MeasuredBackbonePoint& l : levels)
    if (l.fit.status.ok() && (!lowest || l.fit.amplitude < lowest->fit.amplitude)) lowest = &l;
  if (!lowest) return;
  const std::complex<double> A = lowest->fit.residue;
  for (std::size_t i = 0; i < levels.size(); ++i)
    if (levels[i].fit.status.ok()) levels[i].fit = fit_one_mode(tables.at(i), dof, &A);
}

} // namespace jointid::identify

#include "frf/receptance.hpp"

#include "fem/assert.hpp"

#include <Eigen/CholmodSupport>
#include <Eigen/UmfPackSupport>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace jointid::frf {

ModalSynthesis::ModalSynthesis(const fem::Assembled& system, const fem::Modes& modes,
                               const fem::Damping& damping, std::vector<int> dofs,
                               const ModalSynthesisOptions& options)
    : dofs_(std::move(dofs)) {
  const int n = system.dofs.num_equations(), m = modes.num_modes(),
            d = static_cast<int>(dofs_.size());
  for (int e : dofs_)
    if (e < 0 || e >= n)
      throw std::invalid_argument("modal synthesis: equation " + std::to_string(e) +
                                  " out of range");
  if (!modes.status.ok()) {
    status_ = modes.status.within("the modal analysis failed: ");
    return;
  }
  phi_.resize(d, m);
  for (int i = 0; i < d; ++i) {
    int row = dofs_[i];
    if (!modes.rows.empty()) { // the engine kept only some rows
      const auto at = std::find(modes.rows.begin(), modes.rows.end(), row);
      if (at == modes.rows.end())
        throw std::invalid_argument("modal synthesis: the modes lack the row of equation " +
                                    std::to_string(row));
      row = static_cast<int>(at - modes.rows.begin());
    }
    phi_.row(i) = modes.phi.row(row);
  }
  omega_ = modes.omega;
  // Rayleigh damping gives 2 ζ_r ω_r = α + β ω_r² directly; going through ζ_r = α/2ω_r + βω_r/2
  // would lose α for a rigid mode whose computed ω_r is exactly 0.
  modal_damping_.resize(m);
  for (int r = 0; r < m; ++r)
    modal_damping_(r) = damping.kind == fem::Damping::Kind::rayleigh
                            ? damping.alpha + damping.beta * omega_(r) * omega_(r)
                            : 2.0 * damping.ratio(omega_(r)) * omega_(r);
  residual_ = Eigen::MatrixXd::Zero(d, d);
  const bool rigid = m > 0 && omega_(0) < 1e-6 * std::max(1.0, omega_(m - 1));
  if (options.residual_flexibility && !rigid && d > 0) {
    Eigen::CholmodSupernodalLLT<fem::SparseMatrix, Eigen::Lower> llt(system.K);
    if (llt.info() == Eigen::Success) {
      Eigen::MatrixXd unit = Eigen::MatrixXd::Zero(n, d);
      for (int j = 0; j < d; ++j)
        unit(dofs_[j], j) = 1.0;
      const Eigen::MatrixXd flex = llt.solve(unit); // n × d columns of K⁻¹
      for (int i = 0; i < d; ++i)
        residual_.row(i) = flex.row(dofs_[i]);
      residual_ -=
          phi_ * omega_.array().square().inverse().matrix().asDiagonal() * phi_.transpose();
      residual_ = 0.5 * (residual_ + residual_.transpose()).eval();
      has_residual_ = true;
    }
  }
}

ModalSynthesis::ModalSynthesis(const ModalModel& modal, std::vector<int> dofs)
    : dofs_(std::move(dofs)) {
  modal.validate();
  const int n = modal.num_dofs(), m = modal.num_modes(), d = static_cast<int>(dofs_.size());
  for (int e : dofs_)
    if (e < 0 || e >= n)
      throw std::invalid_argument("modal synthesis: equation " + std::to_string(e) +
                                  " out of range (the modal model has " + std::to_string(n) +
                                  " DOFs)");
  phi_.resize(d, m);
  for (int i = 0; i < d; ++i)
    phi_.row(i) = modal.shapes.col(dofs_[i]).transpose();
  omega_ = 2.0 * std::numbers::pi * modal.frequencies_hz;
  modal_damping_ = 2.0 * modal.damping.cwiseProduct(omega_);
  residual_ = Eigen::MatrixXd::Zero(d, d);
  has_residual_ = modal.residual_flexibility.size() > 0;
  if (has_residual_)
    for (int i = 0; i < d; ++i)
      for (int j = 0; j < d; ++j)
        residual_(i, j) = modal.residual_flexibility(dofs_[i], dofs_[j]);
}

ModalSynthesis::ModalSynthesis(std::shared_ptr<const MeasuredReceptance> measured,
                               std::vector<int> dofs)
    : dofs_(std::move(dofs)) {
  const int n = static_cast<int>(measured->data().dofs.size());
  for (int e : dofs_)
    if (e < 0 || e >= n)
      throw std::invalid_argument("receptance: equation " + std::to_string(e) +
                                  " out of range (the measured FRFs have " + std::to_string(n) +
                                  " DOFs)");
  phi_.resize(static_cast<Eigen::Index>(dofs_.size()), 0);
  residual_ = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(dofs_.size()),
                                    static_cast<Eigen::Index>(dofs_.size()));
  measured_.push_back({std::move(measured), dofs_});
}

ModalSynthesis ModalSynthesis::block_diagonal(const std::vector<ModalSynthesis>& parts,
                                              const std::vector<std::vector<int>>& equations) {
  if (parts.size() != equations.size())
    throw std::invalid_argument("block_diagonal: one list of equations per part");
  ModalSynthesis out;
  Eigen::Index d = 0, m = 0;
  for (std::size_t p = 0; p < parts.size(); ++p) {
    if (!parts[p].status_.ok() && out.status_.ok()) out.status_ = parts[p].status_;
    if (equations[p].size() != parts[p].dofs_.size())
      throw std::invalid_argument("block_diagonal: part " + std::to_string(p + 1) + " serves " +
                                  std::to_string(parts[p].dofs_.size()) + " equations, given " +
                                  std::to_string(equations[p].size()));
    for (const int e : equations[p]) {
      if (std::find(out.dofs_.begin(), out.dofs_.end(), e) != out.dofs_.end())
        throw std::invalid_argument("block_diagonal: equation " + std::to_string(e) +
                                    " is served by two parts");
      out.dofs_.push_back(e);
    }
    m += parts[p].phi_.cols();
  }
  d = static_cast<Eigen::Index>(out.dofs_.size());
  if (!out.status_.ok()) return out;
  out.phi_ = Eigen::MatrixXd::Zero(d, m);
  out.omega_.resize(m);
  out.modal_damping_.resize(m);
  out.residual_ = Eigen::MatrixXd::Zero(d, d);
  Eigen::Index row = 0, col = 0;
  for (const ModalSynthesis& part : parts) {
    const Eigen::Index n = static_cast<Eigen::Index>(part.dofs_.size()), k = part.phi_.cols();
    out.phi_.block(row, col, n, k) = part.phi_;
    out.omega_.segment(col, k) = part.omega_;
    out.modal_damping_.segment(col, k) = part.modal_damping_;
    out.residual_.block(row, row, n, n) = part.residual_;
    out.has_residual_ = out.has_residual_ || part.has_residual_;
    for (const MeasuredBlock& b : part.measured_) {
      MeasuredBlock shifted{b.frf, std::vector<int>(static_cast<std::size_t>(d), -1)};
      for (Eigen::Index i = 0; i < n; ++i)
        shifted.local[static_cast<std::size_t>(row + i)] = b.local[static_cast<std::size_t>(i)];
      out.measured_.push_back(std::move(shifted));
    }
    row += n;
    col += k;
  }
  return out;
}

ModalSynthesis ModalSynthesis::failed(fem::Status status, std::vector<int> dofs) {
  JOINTID_ASSERT(!status.ok(), "a failed synthesis needs a status that is not ok");
  ModalSynthesis out;
  out.status_ = std::move(status);
  out.dofs_ = std::move(dofs);
  return out;
}

void ModalSynthesis::require_ok() const {
  if (!status_.ok())
    throw std::logic_error("modal synthesis used although it failed (check status() first): " +
                           status_.reason);
}

ModalSynthesis ModalSynthesis::with_damping_scale(double factor) const {
  require_ok();
  if (phi_.cols() == 0 && !measured_.empty())
    throw std::logic_error("receptance: measured FRFs have no modal damping to scale");
  if (!(factor > 0.0) || !std::isfinite(factor))
    throw std::invalid_argument(
        "modal synthesis: a damping scale factor must be finite and > 0, got " +
        std::to_string(factor));
  ModalSynthesis scaled = *this;
  scaled.modal_damping_ *= factor;
  return scaled;
}

ModalSynthesis ModalSynthesis::with_self_excitation(double xi) const {
  require_ok();
  if (!measured_.empty())
    throw std::logic_error("receptance: measured FRFs have no modal damping to shift");
  if (!std::isfinite(xi))
    throw std::invalid_argument("modal synthesis: the self-excitation must be finite, got " +
                                std::to_string(xi));
  ModalSynthesis shifted = *this;
  shifted.modal_damping_.array() -= xi;
  return shifted;
}

Eigen::MatrixXd ModalSynthesis::shapes(std::span<const int> equations) const {
  require_ok();
  Eigen::MatrixXd out(equations.size(), phi_.cols());
  for (std::size_t i = 0; i < equations.size(); ++i)
    out.row(static_cast<Eigen::Index>(i)) = phi_.row(position(equations[i]));
  return out;
}

Eigen::MatrixXd ModalSynthesis::residual_flexibility(std::span<const int> rows,
                                                     std::span<const int> cols) const {
  require_ok();
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(rows.size(), cols.size());
  if (!has_residual_) return out;
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (std::size_t j = 0; j < cols.size(); ++j)
      out(i, j) = residual_(position(rows[i]), position(cols[j]));
  return out;
}

int ModalSynthesis::position(int equation) const {
  const auto it = std::find(dofs_.begin(), dofs_.end(), equation);
  if (it == dofs_.end())
    throw std::invalid_argument("modal synthesis: equation " + std::to_string(equation) +
                                " was not among the DOFs it was built for");
  return static_cast<int>(it - dofs_.begin());
}

CMatrix ModalSynthesis::receptance(double omega, std::span<const int> rows,
                                   std::span<const int> cols) const {
  return receptances(std::span<const double>(&omega, 1), rows, cols);
}

CMatrix ModalSynthesis::receptances(std::span<const double> omegas, std::span<const int> rows,
                                    std::span<const int> cols) const {
  require_ok();
  const int m = static_cast<int>(omega_.size());
  JOINTID_ASSERT(phi_.rows() == static_cast<Eigen::Index>(dofs_.size()) && phi_.cols() == m &&
                     modal_damping_.size() == m,
                 "one shape row per DOF served, one frequency and damping per mode");
  JOINTID_ASSERT(residual_.rows() == phi_.rows() && residual_.cols() == phi_.rows(),
                 "the residual flexibility is |dofs| × |dofs|");
  const auto nr = static_cast<Eigen::Index>(rows.size()),
             nc = static_cast<Eigen::Index>(cols.size());
  const auto nw = static_cast<Eigen::Index>(omegas.size());
  CMatrix H(nr, nc * nw);
  // The rows' and columns' positions among the synthesis's DOFs, and for each the first row
  // (column) at the same position: a response at the force's DOF, or a joint DOF that is also
  // a force or response DOF, repeats entries, computed once (one allocation for all four).
  std::vector<int> index(2 * (rows.size() + cols.size()));
  int* const pr = index.data();
  int* const pc = pr + nr;
  int* const first_row = pc + nc;
  int* const first_col = first_row + nr;
  auto positions = [this](std::span<const int> equations, int* at, int* first) {
    for (std::size_t i = 0; i < equations.size(); ++i) {
      at[i] = position(equations[i]);
      first[i] = static_cast<int>(i);
      for (std::size_t e = 0; e < i; ++e)
        if (at[e] == at[i]) {
          first[i] = static_cast<int>(e);
          break;
        }
    }
  };
  positions(rows, pr, first_row);
  positions(cols, pc, first_col);
  // 1 / (ω_r² − ω² + i d_r ω) per mode and frequency (m × nw), without the library's checked
  // division; then per entry Σ_r φ_ir φ_jr / d_r (no conjugation: receptance is symmetric, not
  // Hermitian), the products φ_ir φ_jr once for all frequencies.
  CMatrix modal(m, nw);
  Eigen::VectorXd product(m);
  for (Eigen::Index k = 0; k < nw; ++k) {
    const double omega = omegas[static_cast<std::size_t>(k)];
    for (int r = 0; r < m; ++r) {
      const double a = omega_(r) * omega_(r) - omega * omega, b = modal_damping_(r) * omega;
      const double d = a * a + b * b;
      // A 0 Hz mode (rigid-body motion) has no static receptance: at 0 Hz (harmonic 0, the
      // mean) its term is infinite. Named here, rather than let it turn every result into NaN.
      if (!(d > 0.0) && omega == 0.0 && omega_(r) == 0.0)
        throw std::invalid_argument(
            "receptance: mode " + std::to_string(r + 1) +
            " is at 0 Hz (a rigid-body motion), so the receptance at 0 Hz (harmonic 0, the "
            "static mean) is infinite: support the substructure, or leave harmonic 0 out");
      modal(r, k) = d > 0.0 ? Complex(a / d, -b / d) : 1.0 / Complex(a, b);
    }
  }
  for (Eigen::Index i = 0; i < nr; ++i)
    for (Eigen::Index j = 0; j < nc; ++j) {
      if (const Eigen::Index fi = first_row[i], fj = first_col[j]; fi != i || fj != j) {
        for (Eigen::Index k = 0; k < nw; ++k) // computed already: fi ≤ i, fj ≤ j
          H(i, k * nc + j) = H(fi, k * nc + fj);
        continue;
      }
      const int pi = pr[i], pj = pc[j];
      for (int r = 0; r < m; ++r)
        product(r) = phi_(pi, r) * phi_(pj, r);
      for (Eigen::Index k = 0; k < nw; ++k) {
        Complex h = residual_(pi, pj);
        for (int r = 0; r < m; ++r)
          h += product(r) * modal(r, k);
        H(i, k * nc + j) = h;
      }
    }
  // Measured FRFs, in their block: the entries whose row and column are both theirs.
  for (const MeasuredBlock& b : measured_) {
    std::vector<int> r_at, c_at, r_local, c_local;
    for (std::size_t i = 0; i < rows.size(); ++i)
      if (const int l = b.local[static_cast<std::size_t>(pr[i])]; l >= 0)
        r_at.push_back(static_cast<int>(i)), r_local.push_back(l);
    for (std::size_t j = 0; j < cols.size(); ++j)
      if (const int l = b.local[static_cast<std::size_t>(pc[j])]; l >= 0)
        c_at.push_back(static_cast<int>(j)), c_local.push_back(l);
    if (r_at.empty() || c_at.empty()) continue;
    for (Eigen::Index k = 0; k < nw; ++k) {
      const CMatrix Hm = b.frf->receptance(omegas[static_cast<std::size_t>(k)], r_local, c_local);
      for (std::size_t i = 0; i < r_at.size(); ++i)
        for (std::size_t j = 0; j < c_at.size(); ++j)
          H(r_at[i], k * nc + c_at[j]) +=
              Hm(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j));
    }
  }
  return H;
}

Blocks ModalSynthesis::blocks(double omega, const Partition& p) const {
  return {receptance(omega, p.set1, p.set1), receptance(omega, p.set1, p.set2),
          receptance(omega, p.set2, p.set1), receptance(omega, p.set2, p.set2)};
}

fem::Outcome<CMatrix> direct_receptance(const fem::Assembled& system, const fem::SparseMatrix& C,
                                        double omega, std::span<const int> rows,
                                        std::span<const int> cols) {
  using CSparse = Eigen::SparseMatrix<Complex>;
  const int n = system.dofs.num_equations();
  CSparse D = (system.K - omega * omega * system.M).cast<Complex>();
  if (C.nonZeros() > 0) D += Complex(0.0, omega) * C.cast<Complex>();
  D.makeCompressed();
  Eigen::UmfPackLU<CSparse> lu(D);
  if (lu.info() != Eigen::Success)
    return {
        fem::Status::failure(
            fem::Status::Code::numerical_issue,
            "direct receptance: K - w^2 M + i w C is singular at w = " + std::to_string(omega) +
                " rad/s (" + std::to_string(omega / (2.0 * std::numbers::pi)) +
                " Hz): an undamped natural frequency, or a DOF with neither stiffness nor mass"),
        {}};
  Eigen::MatrixXcd unit = Eigen::MatrixXcd::Zero(n, static_cast<int>(cols.size()));
  for (std::size_t j = 0; j < cols.size(); ++j)
    unit(cols[j], j) = 1.0;
  const Eigen::MatrixXcd X = lu.solve(unit);
  CMatrix H(rows.size(), cols.size());
  for (std::size_t i = 0; i < rows.size(); ++i)
    H.row(i) = X.row(rows[i]);
  return {{}, std::move(H)};
}

} // namespace jointid::frf

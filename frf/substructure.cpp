#include "frf/substructure.hpp"

#include "fem/damping.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <stdexcept>

namespace jointid::frf {

namespace {

/// Up to this many equations every mode is computed by the dense eigensolver (fem's automatic
/// engine choice).
int dense_limit() {
  return fem::ModalOptions{}.dense_limit;
}

// The shortest text that reads back as `value`.
std::string number(double value) {
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, value).ptr;
  return std::string(buffer, end);
}

fem::Modes checked(fem::Modes modes) {
  if (modes.status != fem::ModalStatus::success)
    throw std::runtime_error("modal analysis failed: " + modes.reason);
  return modes;
}

} // namespace

Substructure::Substructure(fem::Model model)
    : model_(std::move(model)), system_(fem::assemble(*model_)), damping_(model_->damping) {}

Substructure::Substructure(fem::Assembled system, fem::Damping damping) : damping_(damping) {
  const int n = system.dofs.num_equations();
  if (n == 0) throw std::invalid_argument("K and M: no DOFs");
  for (const auto& [name, A] : {std::pair<const char*, const fem::SparseMatrix*>{"K", &system.K},
                                std::pair<const char*, const fem::SparseMatrix*>{"M", &system.M}}) {
    if (A->rows() != n || A->cols() != n)
      throw std::invalid_argument(std::string(name) + " is " + std::to_string(A->rows()) + " x " +
                                  std::to_string(A->cols()) + ", expected " + std::to_string(n) +
                                  " x " + std::to_string(n) + " (one row per DOF of the table)");
    double largest = 0.0;
    for (Eigen::Index c = 0; c < A->outerSize(); ++c)
      for (fem::SparseMatrix::InnerIterator it(*A, c); it; ++it) {
        if (!std::isfinite(it.value()))
          throw std::invalid_argument(std::string(name) + ": entry (" +
                                      std::to_string(it.row() + 1) + ", " +
                                      std::to_string(it.col() + 1) + ") is not finite");
        largest = std::max(largest, std::abs(it.value()));
      }
    const fem::SparseMatrix D = *A - fem::SparseMatrix(A->transpose());
    for (Eigen::Index c = 0; c < D.outerSize(); ++c)
      for (fem::SparseMatrix::InnerIterator it(D, c); it; ++it)
        if (std::abs(it.value()) > 1e-10 * largest)
          throw std::invalid_argument(
              std::string(name) + " is not symmetric: entries (" + std::to_string(it.row() + 1) +
              ", " + std::to_string(it.col() + 1) + ") and (" + std::to_string(it.col() + 1) +
              ", " + std::to_string(it.row() + 1) + ") differ by " + number(it.value()));
  }
  for (int i = 0; i < n; ++i)
    if (system.M.coeff(i, i) < 0.0)
      throw std::invalid_argument("M: diagonal entry " + std::to_string(i + 1) + " (" +
                                  fem::to_string(system.dofs.node_dof(i)) +
                                  ") is negative: " + number(system.M.coeff(i, i)));
  system_ = std::move(system);
}

Substructure::Substructure(ModalModel modal) {
  modal.validate();
  modal_dofs_ = fem::DofMap::from_dofs(modal.dofs);
  modal_ = std::move(modal);
}

Substructure::Substructure(MeasuredFrf frf) {
  measured_ = std::make_shared<const MeasuredReceptance>(std::move(frf));
  modal_dofs_ = fem::DofMap::from_dofs(measured_->data().dofs);
}

const char* Substructure::given_by() const {
  return measured_ ? "measured FRFs ([frf])"
         : modal_  ? "its modes ([modal])"
         : model_  ? "a finite element model"
                   : "its matrices ([matrices])";
}

const fem::DofMap& Substructure::dofs() const {
  return system_ ? system_->dofs : modal_dofs_;
}

const fem::Modes& Substructure::all_modes() const {
  if (!all_modes_) {
    fem::ModalOptions options;
    options.num_modes = 0;
    options.engine = fem::ModalEngine::dense;
    all_modes_ = checked(fem::modal_analysis(*system_, options));
  }
  return *all_modes_;
}

ModalSynthesis Substructure::synthesis(std::vector<int> dofs, double f_max_hz,
                                       std::vector<std::string>* notes) const {
  if (modal_) return ModalSynthesis(*modal_, std::move(dofs));
  if (measured_) {
    ModalSynthesis synthesis(measured_, dofs);
    std::string where;
    const double error = measured_->interpolation_error(dofs, &where);
    if (notes && error > 1e-3)
      notes->push_back("measured FRFs: between lines the receptance is interpolated, with an "
                       "estimated error up to " +
                       number(std::round(error * 1e4) / 1e4) + " of the FRF's peak (" + where +
                       "): measure with a finer frequency step, or at the tests' frequencies");
    return synthesis;
  }
  const int n = system_->dofs.num_equations();
  for (int e : dofs)
    if (e < 0 || e >= n)
      throw std::invalid_argument("receptance: equation " + std::to_string(e) +
                                  " is outside the model (" + std::to_string(n) + " equations)");
  std::optional<fem::Modes> band;
  if (n > dense_limit()) {
    if (!(f_max_hz > 0.0) || !std::isfinite(f_max_hz))
      throw std::invalid_argument(
          "receptance: a model of " + std::to_string(n) + " equations (more than " +
          std::to_string(dense_limit()) +
          ") uses the modes below the highest frequency of interest, which must be > 0 Hz, got " +
          number(f_max_hz));
    fem::ModalOptions options;
    options.max_frequency_hz = f_max_hz;
    options.engine = fem::ModalEngine::sparse;
    band = checked(band_solver_ ? band_solver_(*model_, *system_, options, dofs)
                                : fem::modal_analysis(*system_, options));
  }
  const fem::Modes& modes = band ? *band : all_modes();
  ModalSynthesis synthesis(*system_, modes, damping_, std::move(dofs));
  if (notes && modes.num_modes() < n && !synthesis.has_residual())
    notes->push_back("receptance from " + std::to_string(modes.num_modes()) + " of " +
                     std::to_string(n) +
                     " modes without residual flexibility (the model has rigid-body modes): the "
                     "modes left out are ignored");
  return synthesis;
}

fem::SparseMatrix Substructure::damping_matrix() const {
  if (!system_)
    throw std::logic_error(std::string("time integration needs a finite element model; this "
                                       "substructure is given by ") +
                           given_by());
  const fem::Damping& damping = damping_;
  if (damping.kind != fem::Damping::Kind::modal) return fem::damping_matrix(*system_, damping);
  const int n = system_->dofs.num_equations();
  if (n > dense_limit())
    throw std::invalid_argument(
        "modal damping in a time simulation needs every mode, and the model has " +
        std::to_string(n) + " equations (more than " + std::to_string(dense_limit()) +
        "); use [damping] rayleigh = [alpha, beta]");
  return fem::damping_matrix(*system_, damping, &all_modes());
}

} // namespace jointid::frf

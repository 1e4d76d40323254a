#include "frf/substructure.hpp"

#include "fem/damping.hpp"
#include "fem/text.hpp"

#include <Eigen/SparseCholesky>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <map>
#include <stdexcept>

namespace jointid::frf {

namespace {

/// Up to this many equations every mode is computed by the dense eigensolver (fem's automatic
/// engine choice).
int dense_limit() {
  return fem::ModalOptions{}.dense_limit;
}

// The shortest text that reads back as `value`.
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
              ", " + std::to_string(it.row() + 1) + ") differ by " + shortest(it.value()));
  }
  for (int i = 0; i < n; ++i)
    if (system.M.coeff(i, i) < 0.0)
      throw std::invalid_argument("M: diagonal entry " + std::to_string(i + 1) + " (" +
                                  fem::to_string(system.dofs.node_dof(i)) +
                                  ") is negative: " + shortest(system.M.coeff(i, i)));
  // K positive definite: a substructure given by its matrices is held (no rigid-body motion,
  // no mechanism) and has no negative stiffness; otherwise its first modes are at 0 Hz (or
  // imaginary) and every receptance near them meaningless. The LDLᵀ factorisation (fill-reducing
  // order) finds it: a pivot that is not above 1e-10 of its row's diagonal (rounding of a
  // positive definite K leaves it far above that) is where it breaks down.
  {
    const Eigen::SimplicialLDLT<fem::SparseMatrix> ldlt(system.K);
    const Eigen::VectorXd D = ldlt.vectorD();
    const auto& to_original = ldlt.permutationPinv().indices();
    for (Eigen::Index i = 0; i < D.size(); ++i) {
      const int e = to_original(i);
      const double diagonal = system.K.coeff(e, e);
      if (D(i) > 1e-10 * std::abs(diagonal)) continue;
      throw std::invalid_argument(
          "K is not positive definite: its factorisation breaks down at " +
          fem::to_string(system.dofs.node_dof(e)) + " (pivot " + shortest(D(i)) + ", diagonal " +
          shortest(diagonal) + "): " +
          (D(i) < -1e-10 * std::abs(diagonal)
               ? "a negative stiffness"
               : "a rigid-body motion or a mechanism (a 0 Hz mode)") +
          " there; K and M must describe a supported structure (add its supports to K)");
    }
    if (ldlt.info() != Eigen::Success)
      throw std::invalid_argument("K is not positive definite: its factorisation fails; K and M "
                                  "must describe a supported structure (add its supports to K)");
  }
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

Substructure::Substructure(std::vector<Substructure> parts, std::vector<int> node_offsets)
    : parts_(std::move(parts)), node_offsets_(std::move(node_offsets)) {
  if (parts_.empty()) throw std::invalid_argument("substructures: none given");
  if (parts_.size() != node_offsets_.size())
    throw std::invalid_argument("substructures: one node offset per part");
  std::vector<fem::NodeDof> dofs;
  std::map<int, std::size_t> node_part; // node (offset) → the part that has it
  for (std::size_t p = 0; p < parts_.size(); ++p) {
    const Substructure& part = parts_[p];
    if (!part.parts_.empty())
      throw std::invalid_argument("substructure " + std::to_string(p + 1) +
                                  " is itself made of substructures: list its parts instead");
    if (node_offsets_[p] < 0)
      throw std::invalid_argument("substructure " + std::to_string(p + 1) +
                                  ": the node offset must be >= 0, got " +
                                  std::to_string(node_offsets_[p]));
    const fem::DofMap& map = part.dofs();
    for (int e = 0; e < map.num_equations(); ++e) {
      fem::NodeDof nd = map.node_dof(e);
      nd.node += node_offsets_[p];
      const auto [at, fresh] = node_part.emplace(nd.node, p);
      if (!fresh && at->second != p)
        throw std::invalid_argument("node " + std::to_string(nd.node) + " is in substructure " +
                                    std::to_string(at->second + 1) + " and in substructure " +
                                    std::to_string(p + 1) + ": give one of them a node offset");
      dofs.push_back(nd);
      part_of_.push_back(static_cast<int>(p));
      local_of_.push_back(e);
    }
  }
  modal_dofs_ = fem::DofMap::from_dofs(dofs);
}

double Substructure::band_top_hz(const std::vector<int>& equations) const {
  if (measured_) return measured_->band_top_hz(equations);
  double top = std::numeric_limits<double>::infinity();
  if (parts_.empty()) return top;
  std::vector<std::vector<int>> local(parts_.size());
  for (const int e : equations)
    if (e >= 0 && e < static_cast<int>(part_of_.size()))
      local[static_cast<std::size_t>(part_of_[static_cast<std::size_t>(e)])].push_back(
          local_of_[static_cast<std::size_t>(e)]);
  for (std::size_t p = 0; p < parts_.size(); ++p)
    top = std::min(top, parts_[p].band_top_hz(local[p]));
  return top;
}

const char* Substructure::given_by() const {
  if (!parts_.empty()) return "several substructures ([[substructures]])";
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
    all_modes_ = fem::modal_analysis(*system_, options);
  }
  return *all_modes_;
}

ModalSynthesis Substructure::synthesis(std::vector<int> dofs, double f_max_hz,
                                       std::vector<std::string>* notes) const {
  if (modal_) return ModalSynthesis(*modal_, std::move(dofs));
  if (!parts_.empty()) { // each part's synthesis of its equations, side by side
    std::vector<std::vector<int>> local(parts_.size()), here(parts_.size());
    for (const int e : dofs) {
      if (e < 0 || e >= static_cast<int>(part_of_.size()))
        throw std::invalid_argument("receptance: equation " + std::to_string(e) +
                                    " is outside the substructures (" +
                                    std::to_string(part_of_.size()) + " equations)");
      const auto p = static_cast<std::size_t>(part_of_[static_cast<std::size_t>(e)]);
      local[p].push_back(local_of_[static_cast<std::size_t>(e)]);
      here[p].push_back(e);
    }
    std::vector<ModalSynthesis> syntheses;
    std::vector<std::vector<int>> served;
    for (std::size_t p = 0; p < parts_.size(); ++p) {
      if (local[p].empty()) continue;
      std::vector<std::string> part_notes;
      syntheses.push_back(parts_[p].synthesis(local[p], f_max_hz, &part_notes));
      if (const fem::Status& status = syntheses.back().status(); !status.ok())
        return ModalSynthesis::failed(status.within("substructure " + std::to_string(p + 1) + ": "),
                                      std::move(dofs));
      served.push_back(here[p]);
      if (notes)
        for (const std::string& note : part_notes)
          notes->push_back("substructure " + std::to_string(p + 1) + ": " + note);
    }
    return ModalSynthesis::block_diagonal(syntheses, served);
  }
  if (measured_) {
    ModalSynthesis synthesis(measured_, dofs);
    std::string where;
    const double error = measured_->interpolation_error(dofs, &where);
    if (notes && error > 1e-3)
      notes->push_back("measured FRFs: between lines the receptance is interpolated, with an "
                       "estimated error up to " +
                       shortest(std::round(error * 1e4) / 1e4) + " of the FRF's peak (" + where +
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
          shortest(f_max_hz));
    fem::ModalOptions options;
    options.max_frequency_hz = f_max_hz;
    options.engine = fem::ModalEngine::sparse;
    band = band_solver_ ? band_solver_(*model_, *system_, options, dofs)
                        : fem::modal_analysis(*system_, options);
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

fem::Outcome<fem::SparseMatrix> Substructure::damping_matrix() const {
  if (!system_)
    throw std::logic_error(std::string("time integration needs a finite element model; this "
                                       "substructure is given by ") +
                           given_by());
  const fem::Damping& damping = damping_;
  if (damping.kind != fem::Damping::Kind::modal)
    return {{}, fem::damping_matrix(*system_, damping)};
  const int n = system_->dofs.num_equations();
  if (n > dense_limit())
    throw std::invalid_argument(
        "modal damping in a time simulation needs every mode, and the model has " +
        std::to_string(n) + " equations (more than " + std::to_string(dense_limit()) +
        "); use [damping] rayleigh = [alpha, beta]");
  const fem::Modes& modes = all_modes();
  if (!modes.status.ok())
    return {modes.status.within("modal damping needs every mode, and the modal analysis failed: "),
            {}};
  return {{}, fem::damping_matrix(*system_, damping, &modes)};
}

} // namespace jointid::frf

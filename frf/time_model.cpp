#include "frf/time_model.hpp"

#include "fem/modal.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace jointid::frf {

namespace {

using Triplets = std::vector<Eigen::Triplet<double>>;

// One substructure's time model before the parts are put side by side.
struct Part {
  fem::Status status;
  fem::SparseMatrix K, M, C, T, R; // C, R may be empty
  int modes_kept = 0, static_columns = 0, residual_dofs = 0;
  bool every_mode = false;
  std::string description;
  std::vector<std::string> warnings;
};

// Appends the entries of A shifted by (row, col).
void append(Triplets& t, const fem::SparseMatrix& A, int row, int col) {
  for (Eigen::Index c = 0; c < A.outerSize(); ++c)
    for (fem::SparseMatrix::InnerIterator it(A, c); it; ++it)
      t.emplace_back(static_cast<int>(it.row()) + row, static_cast<int>(it.col()) + col,
                     it.value());
}

fem::SparseMatrix identity(int n) {
  fem::SparseMatrix I(n, n);
  I.setIdentity();
  return I;
}

// A [modal] model: q̈ + 2ζω q̇ + ω² q = Φᵀ F, x = Φ q + R F.
Part modal_part(const ModalModel& modal) {
  Part p;
  const int m = modal.num_modes(), n = modal.num_dofs();
  Triplets k, mass, c;
  for (int r = 0; r < m; ++r) {
    const double w = 2.0 * std::numbers::pi * modal.frequencies_hz(r);
    k.emplace_back(r, r, w * w);
    mass.emplace_back(r, r, 1.0);
    c.emplace_back(r, r, 2.0 * modal.damping(r) * w);
  }
  p.K.resize(m, m);
  p.M.resize(m, m);
  p.C.resize(m, m);
  p.K.setFromTriplets(k.begin(), k.end());
  p.M.setFromTriplets(mass.begin(), mass.end());
  p.C.setFromTriplets(c.begin(), c.end());
  p.T = Eigen::MatrixXd(modal.shapes.transpose()).sparseView(0.0, 0.0);
  p.modes_kept = m;
  const Eigen::MatrixXd& R = modal.residual_flexibility;
  if (R.size() > 0 && R.cwiseAbs().maxCoeff() > 0.0) {
    p.R = (0.5 * (R + R.transpose())).sparseView(0.0, 0.0);
    p.residual_dofs = n;
  }
  p.description =
      p.residual_dofs > 0
          ? fmt::format("{} modes of its [modal] model, its residual flexibility at {} DOFs as a "
                        "static correction",
                        m, n)
          : fmt::format("{} modes of its [modal] model (no residual flexibility)", m);
  return p;
}

// A finite element model or [matrices]: in full, or in modal coordinates (the modes below the
// cutoff and the static pseudo-modes at the loaded equations).
Part matrices_part(const Substructure& sub, const TimeModelOptions& o,
                   const std::vector<int>& loaded) {
  Part p;
  const fem::Assembled& system = *sub.system();
  const int n = system.dofs.num_equations();
  if (!o.modal_coordinates) {
    const fem::Outcome<fem::SparseMatrix> damping = sub.damping_matrix();
    if (!damping.status.ok()) {
      p.status = damping.status;
      return p;
    }
    p.K = system.K;
    p.M = system.M;
    p.C = damping.value;
    p.T = identity(n);
    p.description = fmt::format("full model, {} equations", n);
    return p;
  }
  // Small models: every mode (dense); others: only the band below the cutoff (shift-invert
  // Lanczos on a sparse factorisation) — a dense eigensolution of 1000 equations alone takes
  // longer than the whole simulation.
  constexpr int every_mode_limit = 200;
  fem::ModalOptions mo;
  mo.num_modes = 0;
  if (n <= every_mode_limit) {
    mo.engine = fem::ModalEngine::dense;
  } else {
    mo.engine = fem::ModalEngine::sparse;
    mo.max_frequency_hz = std::max(o.modal_cutoff_hz, o.force_band_hz);
  }
  fem::Modes modes = fem::modal_analysis(system, mo);
  if (!modes.status.ok()) {
    p.status = modes.status.within("the modal analysis failed: ");
    return p;
  }
  int kept = 0;
  while (kept < modes.num_modes() && modes.frequency_hz(kept) < o.modal_cutoff_hz)
    ++kept;
  p.every_mode = kept == n;
  int below_band = 0;
  for (int r = kept; r < modes.num_modes() && modes.frequency_hz(r) <= o.force_band_hz; ++r)
    ++below_band;
  if (below_band > 0)
    p.warnings.push_back(fmt::format(
        "modal route: {} mode{} between the modal cutoff, {:.4g} Hz, and {:.4g} Hz (below which "
        "99 % of the force's power lies) {} left out (the first at {:.4g} Hz): the force drives "
        "{} near resonance, which the static correction does not hold, so the response can be "
        "tens of per cent off; raise the modal cutoff above {:.4g} Hz (0: the Nyquist frequency)",
        below_band, below_band > 1 ? "s" : "", o.modal_cutoff_hz, o.force_band_hz,
        below_band > 1 ? "are" : "is", modes.frequency_hz(kept), below_band > 1 ? "them" : "it",
        o.force_band_hz));
  modes.omega.conservativeResize(kept);
  modes.phi.conservativeResize(Eigen::NoChange, kept);
  std::vector<int> at = loaded;
  if (!o.static_correction || p.every_mode) at.clear();
  const fem::ModalReduction reduction = fem::modal_reduction(system, modes, sub.damping(), at);
  p.K = reduction.system.K;
  p.M = reduction.system.M;
  p.C = reduction.C;
  p.T = reduction.basis.sparseView(0.0, 0.0);
  p.modes_kept = reduction.kept_modes;
  p.static_columns = reduction.static_columns;
  p.description =
      fmt::format("{} modes below {} Hz of {} equations{}", kept, o.modal_cutoff_hz, n,
                  reduction.static_columns > 0
                      ? fmt::format(", static correction at {} DOFs", reduction.static_columns)
                      : std::string(p.every_mode ? ", every mode" : ", no static correction"));
  return p;
}

Part part_model(const Substructure& sub, const TimeModelOptions& o, const std::vector<int>& loaded,
                const std::string& name) {
  if (sub.measured())
    throw std::invalid_argument(no_time_domain_model(name + " is given by measured FRFs ([frf])"));
  if (sub.modal()) return modal_part(*sub.modal());
  if (!sub.system())
    throw std::logic_error("time model: a substructure without matrices, modes or FRFs");
  return matrices_part(sub, o, loaded);
}

} // namespace

std::string no_time_domain_model(const std::string& what) {
  return what +
         ", which have no time-domain model: a measured FRF is known only at its lines, with no "
         "modes or matrices to integrate. Fit a modal model to them first (jointid modal-fit) "
         "and use the [modal] model it writes";
}

TimeDomainModel time_domain_model(const Substructure& sub, const TimeModelOptions& o) {
  if (o.modal_coordinates && !(std::isfinite(o.modal_cutoff_hz) && o.modal_cutoff_hz > 0.0))
    throw std::invalid_argument(fmt::format(
        "time model: modal coordinates need a cutoff > 0 Hz, got {}", o.modal_cutoff_hz));
  const int n_x = sub.dofs().num_equations();
  for (const int e : o.loaded)
    if (e < 0 || e >= n_x)
      throw std::invalid_argument(fmt::format(
          "time model: equation {} is outside the substructure ({} equations)", e, n_x));

  // 1. Each substructure's model, with its share of the loaded equations.
  std::vector<Part> parts;
  std::vector<int> first; // each part's first equation here (parts' equations in order)
  if (sub.parts().empty()) {
    parts.push_back(part_model(sub, o, o.loaded, "the substructure"));
    first.push_back(0);
  } else {
    // Refuse measured FRFs before any modal analysis runs.
    for (std::size_t p = 0; p < sub.parts().size(); ++p)
      if (sub.parts()[p].measured())
        throw std::invalid_argument(no_time_domain_model(
            fmt::format("substructure {} is given by measured FRFs ([frf])", p + 1)));
    int offset = 0;
    for (std::size_t p = 0; p < sub.parts().size(); ++p) {
      const Substructure& part = sub.parts()[p];
      const int n = part.dofs().num_equations();
      std::vector<int> local;
      for (const int e : o.loaded)
        if (e >= offset && e < offset + n) local.push_back(e - offset);
      parts.push_back(part_model(part, o, local, fmt::format("substructure {}", p + 1)));
      first.push_back(offset);
      offset += n;
    }
  }

  // 2. Side by side.
  TimeDomainModel out;
  const bool composite = !sub.parts().empty();
  for (std::size_t p = 0; p < parts.size(); ++p) {
    if (!parts[p].status.ok()) {
      out.status = composite ? parts[p].status.within(fmt::format("substructure {}: ", p + 1))
                             : parts[p].status;
      return out;
    }
  }
  fem::TimeModel& m = out.model;
  for (const Part& part : parts) {
    out.modes_kept += part.modes_kept;
    out.static_columns += part.static_columns;
    out.residual_dofs += part.residual_dofs;
    out.parts.push_back(part.description);
    for (const std::string& w : part.warnings)
      out.warnings.push_back(
          composite ? fmt::format("substructure {}: {}", &part - parts.data() + 1, w) : w);
  }
  out.every_mode = parts.size() == 1 && parts.front().every_mode;
  int n_w = 0;
  for (const Part& p : parts)
    n_w += static_cast<int>(p.K.rows());
  if (!composite && sub.system() && !o.modal_coordinates) {
    m.system.dofs = sub.system()->dofs; // a finite element model in full: its own equations
  } else {
    std::vector<fem::NodeDof> coordinates;
    for (int i = 0; i < n_w; ++i)
      coordinates.push_back({i + 1, fem::Dof::ux});
    m.system.dofs = fem::DofMap::from_dofs(coordinates);
  }
  if (!composite) {
    Part& part = parts.front();
    m.system.K = std::move(part.K);
    m.system.M = std::move(part.M);
    m.C = std::move(part.C);
    m.T = std::move(part.T);
    m.R = std::move(part.R);
    return out;
  }
  Triplets K, M, C, T, R;
  int w0 = 0;
  for (std::size_t p = 0; p < parts.size(); ++p) {
    const Part& part = parts[p];
    append(K, part.K, w0, w0);
    append(M, part.M, w0, w0);
    if (part.C.size() > 0) append(C, part.C, w0, w0);
    append(T, part.T, first[p], w0);
    if (part.R.size() > 0) append(R, part.R, first[p], first[p]);
    w0 += static_cast<int>(part.K.rows());
  }
  m.system.K.resize(n_w, n_w);
  m.system.M.resize(n_w, n_w);
  m.C.resize(n_w, n_w);
  m.T.resize(n_x, n_w);
  m.system.K.setFromTriplets(K.begin(), K.end());
  m.system.M.setFromTriplets(M.begin(), M.end());
  m.C.setFromTriplets(C.begin(), C.end());
  m.T.setFromTriplets(T.begin(), T.end());
  if (!R.empty()) {
    m.R.resize(n_x, n_x);
    m.R.setFromTriplets(R.begin(), R.end());
  }
  return out;
}

} // namespace jointid::frf

#include "identify/modal_fit.hpp"

#include "fem/constants.hpp"

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <numbers>
#include <stdexcept>

namespace jointid::identify {

namespace {

using cd = std::complex<double>;

// ---------------------------------------------------------------------------------------------
// LSCF: the normal equations' Toeplitz blocks and the poles at one order.

/// Sums over the lines that every order's normal equations are made of (see the file comment of
/// modal_fit.hpp): with θ_j = ω_j T,
///   r_m = Σ_j cos(m θ_j),   t_om = Σ_j |H_oj|² cos(m θ_j),   s_om = −Σ_j Re(H_oj e^{i m θ_j}),
/// R_kl = r_|l−k|, S_kl = s_(l−k), T_kl = t_|l−k| for the coefficients k, l = 0 … n, each
/// response weighted by w_o² = 1 / mean|H_o|².
struct NormalSums {
  Eigen::VectorXd r;              ///< m = 0 … n_max
  std::vector<Eigen::VectorXd> t; ///< per response, m = 0 … n_max
  std::vector<Eigen::VectorXd> s; ///< per response, m = −n_max … n_max at index m + n_max
  Eigen::VectorXd weight2;        ///< w_o²
  int n_max = 0;
};

NormalSums normal_sums(const Eigen::VectorXd& theta, const Eigen::MatrixXcd& H, int n_max) {
  NormalSums ns;
  ns.n_max = n_max;
  const Eigen::Index L = theta.size(), O = H.cols();
  ns.r = Eigen::VectorXd::Zero(n_max + 1);
  ns.weight2.resize(O);
  for (Eigen::Index o = 0; o < O; ++o) {
    ns.t.push_back(Eigen::VectorXd::Zero(n_max + 1));
    ns.s.push_back(Eigen::VectorXd::Zero(2 * n_max + 1));
    const double mean2 = H.col(o).squaredNorm() / static_cast<double>(L);
    ns.weight2(o) = mean2 > 0.0 ? 1.0 / mean2 : 0.0;
  }
  for (Eigen::Index j = 0; j < L; ++j) {
    const cd step = std::polar(1.0, theta(j));
    cd e(1.0, 0.0); // e^{i m θ_j}
    for (int m = 0; m <= n_max; ++m) {
      ns.r(m) += e.real();
      for (Eigen::Index o = 0; o < O; ++o) {
        const cd h = H(j, o);
        ns.t[static_cast<std::size_t>(o)](m) += std::norm(h) * e.real();
        ns.s[static_cast<std::size_t>(o)](n_max + m) -= (h * e).real();
        if (m > 0) ns.s[static_cast<std::size_t>(o)](n_max - m) -= (h * std::conj(e)).real();
      }
      e *= step;
    }
  }
  return ns;
}

/// The roots z of the denominator A(z) at order n (n + 1 coefficients, the last one 1).
Eigen::VectorXcd denominator_roots(const NormalSums& ns, int n) {
  const int size = n + 1;
  Eigen::MatrixXd R(size, size);
  for (int k = 0; k < size; ++k)
    for (int l = 0; l < size; ++l)
      R(k, l) = ns.r(std::abs(l - k));
  // R⁺ by its eigenvalues: a narrow band far above 0 Hz makes R nearly singular.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(R);
  const Eigen::VectorXd& e = eig.eigenvalues();
  const double cut = 1e-13 * e.cwiseAbs().maxCoeff();
  Eigen::VectorXd inv_sqrt(size);
  for (int k = 0; k < size; ++k)
    inv_sqrt(k) = e(k) > cut ? 1.0 / std::sqrt(e(k)) : 0.0;
  const Eigen::MatrixXd P = inv_sqrt.asDiagonal() * eig.eigenvectors().transpose();
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(size, size), S(size, size);
  for (std::size_t o = 0; o < ns.t.size(); ++o) {
    const double w2 = ns.weight2(static_cast<Eigen::Index>(o));
    if (w2 == 0.0) continue;
    for (int k = 0; k < size; ++k)
      for (int l = 0; l < size; ++l) {
        S(k, l) = ns.s[o](ns.n_max + l - k);
        M(k, l) += w2 * ns.t[o](std::abs(l - k));
      }
    const Eigen::MatrixXd PS = P * S;
    M.noalias() -= w2 * PS.transpose() * PS;
  }
  // A's last coefficient is 1: M_aa α_a = −M_a,n.
  const Eigen::VectorXd alpha =
      M.topLeftCorner(n, n).colPivHouseholderQr().solve(-M.col(n).head(n));
  // The companion matrix of z^n + α_{n−1} z^{n−1} + … + α_0.
  Eigen::MatrixXd C = Eigen::MatrixXd::Zero(n, n);
  for (int k = 0; k < n; ++k)
    C(0, k) = -alpha(n - 1 - k);
  for (int k = 1; k < n; ++k)
    C(k, k - 1) = 1.0;
  if (!C.allFinite()) return {};
  const Eigen::EigenSolver<Eigen::MatrixXd> roots(C, false);
  if (roots.info() != Eigen::Success) return {};
  return roots.eigenvalues();
}

// ---------------------------------------------------------------------------------------------
// The stabilisation diagram and the modes chosen from it.

struct Pole {
  int order = 0;
  double f = 0.0, zeta = 0.0;
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

std::vector<DiagramPole> stabilisation_diagram(const Eigen::VectorXd& theta,
                                               const Eigen::MatrixXcd& H, double T, int max_order,
                                               double f_lo, double f_hi, const ModalFitOptions& o) {
  const NormalSums ns = normal_sums(theta, H, max_order);
  std::vector<DiagramPole> diagram;
  std::vector<Pole> previous;
  for (int n = 2; n <= max_order; n += 2) {
    const Eigen::VectorXcd z = denominator_roots(ns, n);
    std::vector<Pole> current;
    for (Eigen::Index k = 0; k < z.size(); ++k) {
      if (!(std::abs(z(k)) > 0.0) || !(std::arg(z(k)) > 0.0)) continue; // one of each pair
      const cd lambda = std::log(z(k)) / T;
      const double f = std::abs(lambda) / two_pi, zeta = -lambda.real() / std::abs(lambda);
      if (!(f >= f_lo && f <= f_hi && zeta > 0.0 && zeta < 1.0)) continue;
      current.push_back({n, f, zeta});
    }
    for (const Pole& p : current) {
      DiagramPole d{n, p.f, p.zeta, PoleStability::new_pole};
      const Pole* nearest = nullptr;
      for (const Pole& q : previous)
        if (!nearest || std::abs(q.f - p.f) < std::abs(nearest->f - p.f)) nearest = &q;
      if (nearest && std::abs(nearest->f - p.f) <= o.frequency_tolerance * p.f)
        d.stability = std::abs(nearest->zeta - p.zeta) <= o.damping_tolerance * p.zeta
                          ? PoleStability::stable
                          : PoleStability::frequency;
      diagram.push_back(d);
    }
    previous = std::move(current);
  }
  return diagram;
}

/// The modes: groups of stable poles, best supported first (see the file comment of
/// modal_fit.hpp, step 3). `wanted` 0: every group supported at `threshold` orders or more.
std::vector<FittedMode> select_modes(const std::vector<DiagramPole>& diagram, int max_order,
                                     int wanted, int threshold, const ModalFitOptions& o) {
  // The candidates, by order.
  const int orders = max_order / 2;
  std::vector<std::vector<Pole>> by_order(static_cast<std::size_t>(orders));
  for (const DiagramPole& d : diagram)
    if (d.stability == PoleStability::stable && d.damping <= o.max_damping)
      by_order[static_cast<std::size_t>(d.order / 2 - 1)].push_back(
          {d.order, d.frequency_hz, d.damping});
  std::vector<FittedMode> modes;
  const double tol = o.frequency_tolerance;
  while (wanted == 0 || static_cast<int>(modes.size()) < wanted) {
    // The best-supported candidate: poles at the most orders within tol of it, then the least
    // spread.
    const Pole* best = nullptr;
    int best_support = 0;
    double best_spread = 0.0;
    for (const auto& poles : by_order)
      for (const Pole& p : poles) {
        int support = 0;
        double spread = 0.0;
        for (const auto& other : by_order) {
          double nearest = std::numeric_limits<double>::infinity();
          for (const Pole& q : other)
            nearest = std::min(nearest, std::abs(q.f - p.f));
          if (nearest <= tol * p.f) ++support, spread += nearest;
        }
        if (support > best_support || (support == best_support && spread < best_spread))
          best = &p, best_support = support, best_spread = spread;
      }
    if (!best || best_support < threshold) break;
    // Its group: at each order the pole nearest to it, taken out of the candidates.
    const Pole centre = *best;
    std::vector<double> f, zeta;
    for (auto& poles : by_order) {
      auto nearest = poles.end();
      for (auto it = poles.begin(); it != poles.end(); ++it)
        if (std::abs(it->f - centre.f) <= tol * centre.f &&
            (nearest == poles.end() ||
             std::abs(it->f - centre.f) < std::abs(nearest->f - centre.f)))
          nearest = it;
      if (nearest == poles.end()) continue;
      f.push_back(nearest->f);
      zeta.push_back(nearest->zeta);
      poles.erase(nearest);
    }
    FittedMode m;
    m.frequency_hz = median(f);
    m.damping = median(zeta);
    m.stable_orders = static_cast<int>(f.size());
    modes.push_back(std::move(m));
  }
  std::sort(modes.begin(), modes.end(), [](const FittedMode& a, const FittedMode& b) {
    return a.frequency_hz < b.frequency_hz;
  });
  return modes;
}

// ---------------------------------------------------------------------------------------------
// Residues: least squares with the poles fixed.

cd modal_term(const FittedMode& m, double omega) {
  const double w = two_pi * m.frequency_hz;
  return 1.0 / cd(w * w - omega * omega, 2.0 * m.damping * w * omega);
}

double relative_misfit(const Eigen::VectorXcd& measured, const Eigen::VectorXcd& fitted) {
  const double norm = measured.squaredNorm();
  return norm > 0.0 ? std::sqrt((measured - fitted).squaredNorm() / norm)
                    : std::numeric_limits<double>::quiet_NaN();
}

void fit_residues(const MeasuredFrfs& data, const ModalFitOptions& o, ModalFit& fit) {
  const Eigen::Index L = data.num_lines(), O = data.num_responses();
  const auto m = static_cast<Eigen::Index>(fit.modes.size());
  const Eigen::Index lower = o.lower_residual ? m : -1;
  const Eigen::Index upper = o.upper_residual ? m + (o.lower_residual ? 1 : 0) : -1;
  const Eigen::Index unknowns = m + (o.lower_residual ? 1 : 0) + (o.upper_residual ? 1 : 0);
  // Columns: Re and Im of each term over the lines.
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(2 * L, unknowns);
  for (Eigen::Index j = 0; j < L; ++j) {
    const double omega = two_pi * data.frequency_hz(j);
    for (Eigen::Index r = 0; r < m; ++r) {
      const cd b = modal_term(fit.modes[static_cast<std::size_t>(r)], omega);
      A(j, r) = b.real();
      A(L + j, r) = b.imag();
    }
    if (lower >= 0) A(j, lower) = -1.0 / (omega * omega);
    if (upper >= 0) A(j, upper) = 1.0;
  }
  const Eigen::VectorXd scale = A.colwise().norm().cwiseMax(1e-300).cwiseInverse();
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A * scale.asDiagonal());
  for (FittedMode& mode : fit.modes)
    mode.residues.resize(O);
  fit.lower_residual = Eigen::VectorXd::Zero(O);
  fit.upper_residual = Eigen::VectorXd::Zero(O);
  fit.fitted.resize(L, O);
  fit.fit_error.resize(O);
  for (Eigen::Index c = 0; c < O; ++c) {
    Eigen::VectorXd b(2 * L);
    b << data.H.col(c).real(), data.H.col(c).imag();
    const Eigen::VectorXd x = scale.cwiseProduct(qr.solve(b));
    for (Eigen::Index r = 0; r < m; ++r)
      fit.modes[static_cast<std::size_t>(r)].residues(c) = x(r);
    if (lower >= 0) fit.lower_residual(c) = x(lower);
    if (upper >= 0) fit.upper_residual(c) = x(upper);
    const Eigen::VectorXd y = A * x;
    fit.fitted.col(c) = y.head(L).cast<cd>() + cd(0.0, 1.0) * y.tail(L).cast<cd>();
    fit.fit_error(c) = relative_misfit(data.H.col(c), fit.fitted.col(c));
  }
}

// The [modal] model: the modes whose driving-point residue is > 0, mass-normalised there, and
// the upper residual as a flexibility of rank one.
void build_model(const MeasuredFrfs& data, const ModalFitOptions& o, ModalFit& fit) {
  const int d = data.drive_column();
  const Eigen::Index O = data.num_responses();
  frf::ModalModel& model = fit.substructure;
  model.dofs = data.responses;
  std::vector<const FittedMode*> kept;
  for (std::size_t r = 0; r < fit.modes.size(); ++r) {
    FittedMode& mode = fit.modes[r];
    const double a = mode.residues(d);
    if (a > 0.0) {
      mode.shape = mode.residues / std::sqrt(a);
      kept.push_back(&mode);
    } else {
      fit.warnings.push_back(fmt::format(
          "mode {} ({:.6g} Hz): its residue at the driving point {} is {:.3g}, not > 0, so it "
          "cannot be mass-normalised and is left out of the model (the driving point may be "
          "near a node of this mode: drive elsewhere to scale it)",
          r + 1, mode.frequency_hz, data.drive_name, a));
    }
  }
  const auto m = static_cast<Eigen::Index>(kept.size());
  model.frequencies_hz.resize(m);
  model.damping.resize(m);
  model.shapes.resize(m, O);
  for (Eigen::Index r = 0; r < m; ++r) {
    model.frequencies_hz(r) = kept[static_cast<std::size_t>(r)]->frequency_hz;
    model.damping(r) = kept[static_cast<std::size_t>(r)]->damping;
    model.shapes.row(r) = kept[static_cast<std::size_t>(r)]->shape.transpose();
  }
  const double Ud = fit.upper_residual(d);
  if (o.upper_residual && Ud > 0.0) {
    model.residual_flexibility = fit.upper_residual * fit.upper_residual.transpose() / Ud;
  } else if (o.upper_residual) {
    model.residual_flexibility.resize(0, 0);
    fit.warnings.push_back(fmt::format(
        "the upper residual at the driving point {} is {:.3g} m/N, not > 0 as the modes above the "
        "band would make it: the residual terms took up what the modes fitted leave unexplained "
        "(often a mode just below the band), so no residual flexibility is in the model; a band "
        "that starts below every mode gives one",
        data.drive_name, Ud));
  }
  // The model's FRFs from the drive, as a `[modal]` model gives them.
  const Eigen::Index L = data.num_lines();
  fit.model_frf.resize(L, O);
  fit.model_error.resize(O);
  for (Eigen::Index c = 0; c < O; ++c) {
    for (Eigen::Index j = 0; j < L; ++j) {
      const double omega = two_pi * data.frequency_hz(j);
      cd h = model.residual_flexibility.size() ? model.residual_flexibility(c, d) : 0.0;
      for (Eigen::Index r = 0; r < m; ++r) {
        const double w = two_pi * model.frequencies_hz(r);
        h += model.shapes(r, c) * model.shapes(r, d) /
             cd(w * w - omega * omega, 2.0 * model.damping(r) * w * omega);
      }
      fit.model_frf(j, c) = h;
    }
    fit.model_error(c) = relative_misfit(data.H.col(c), fit.model_frf.col(c));
  }
}

std::string response_list(const MeasuredFrfs& data) {
  std::string out;
  for (const auto& name : data.response_names)
    out += (out.empty() ? "" : ", ") + name;
  return out;
}

} // namespace

double modal_assurance(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  const double ab = a.dot(b), aa = a.squaredNorm(), bb = b.squaredNorm();
  return aa > 0.0 && bb > 0.0 ? ab * ab / (aa * bb) : 0.0;
}

ModalFit modal_fit(const MeasuredFrfs& data, const ModalFitOptions& o) {
  // 1. The input.
  const Eigen::Index L = data.num_lines(), O = data.num_responses();
  if (O == 0) throw std::invalid_argument("no responses to fit");
  if (data.H.rows() != L || data.H.cols() != O)
    throw std::invalid_argument(fmt::format("the FRFs are {} × {}, expected {} lines × {} "
                                            "responses",
                                            data.H.rows(), data.H.cols(), L, O));
  if (!data.H.allFinite()) throw std::invalid_argument("the FRFs hold a value that is not finite");
  for (Eigen::Index j = 1; j < L; ++j)
    if (!(data.frequency_hz(j) > data.frequency_hz(j - 1)))
      throw std::invalid_argument("the FRFs' frequencies do not increase");
  if (L > 0 && !(data.frequency_hz(0) > 0.0))
    throw std::invalid_argument("the FRFs' lines must lie above 0 Hz");
  if (data.drive_column() < 0)
    throw std::invalid_argument(fmt::format(
        "the driving point {} is not among the responses ({}): mass-normalised shapes need the "
        "response at the driving point (measure x, v or a at {} too)",
        data.drive_name, response_list(data), fem::to_string(data.drive)));
  if (o.modes < 0)
    throw std::invalid_argument(fmt::format("expected a number of modes >= 0, got {}", o.modes));
  if (!(o.frequency_tolerance > 0.0 && o.damping_tolerance > 0.0 && o.max_damping > 0.0))
    throw std::invalid_argument("the stabilisation tolerances and the largest damping ratio must "
                                "be > 0");
  const Eigen::Index needed = o.modes > 0 ? 2 * o.modes + 6 : 10;
  const std::string lines_text = L > 0
                                     ? fmt::format("{} line{} ({} to {} Hz)", L, L == 1 ? "" : "s",
                                                   data.frequency_hz(0), data.frequency_hz(L - 1))
                                     : std::string("no line");
  if (L < needed)
    throw std::invalid_argument(
        o.modes > 0
            ? fmt::format("the band holds {}: fitting {} mode{} needs at least {} (2 N + 6): "
                          "widen the band, refine the resolution or ask fewer modes",
                          lines_text, o.modes, o.modes == 1 ? "" : "s", needed)
            : fmt::format("the band holds {}: a stabilisation diagram needs at least {}: widen "
                          "the band or refine the resolution",
                          lines_text, needed));
  int max_order = o.max_order;
  if (max_order != 0 && max_order < 4)
    throw std::invalid_argument(
        fmt::format("expected a highest model order of at least 4, got {}", max_order));
  const int cap = static_cast<int>((L - 2) / 2 * 2);
  ModalFit fit;
  if (max_order == 0) {
    max_order = std::min(cap, std::max(40, 4 * o.modes + 20));
  } else if (max_order > cap) {
    fit.warnings.push_back(fmt::format("highest model order {} lowered to {}: the band holds {}",
                                       max_order, cap, lines_text));
    max_order = cap;
  }
  max_order = max_order / 2 * 2;
  fit.max_order = max_order;
  fit.options = o;
  fit.options.max_order = max_order;

  // 2. Poles and the stabilisation diagram.
  const double f_top = data.frequency_hz(L - 1);
  fit.sampling_time_s = 1.0 / (2.0 * f_top);
  const Eigen::VectorXd theta = two_pi * fit.sampling_time_s * data.frequency_hz;
  fit.diagram = stabilisation_diagram(theta, data.H, fit.sampling_time_s, max_order,
                                      data.frequency_hz(0), f_top, o);

  // 3. The modes.
  const int stable_orders = max_order / 2 - 1; // the first order has nothing to be stable against
  const int threshold =
      o.modes > 0
          ? 3
          : std::max(3, static_cast<int>(std::ceil(0.4 * static_cast<double>(stable_orders))));
  fit.modes = select_modes(fit.diagram, max_order, o.modes, threshold, o);
  if (o.modes > 0 && static_cast<int>(fit.modes.size()) < o.modes) {
    fit.status = fem::Status::failure(
        fem::Status::Code::not_separable,
        fmt::format(
            "the stabilisation diagram (orders up to {}) shows {} mode{} in the band {} to {} Hz, "
            "not the {} asked: ask fewer modes, widen the band or raise the highest order",
            max_order, fit.modes.size(), fit.modes.size() == 1 ? "" : "s", data.frequency_hz(0),
            f_top, o.modes));
  } else if (fit.modes.empty()) {
    fit.status = fem::Status::failure(
        fem::Status::Code::not_separable,
        fmt::format("the stabilisation diagram (orders up to {}) shows no mode in the band "
                    "{} to {} Hz stable at {} orders or more",
                    max_order, data.frequency_hz(0), f_top, threshold));
  }

  // 4. Residues, shapes and the model. Chosen by the diagram alone (no number of modes asked), a
  //    pole whose driving-point residue is not > 0 is no mode of a passive structure (φ_d² > 0):
  //    it is dropped and the residues fitted again without it.
  fit_residues(data, o, fit);
  if (o.modes == 0) {
    const int d = data.drive_column();
    std::vector<FittedMode> kept;
    for (const FittedMode& m : fit.modes) {
      if (m.residues(d) > 0.0) {
        kept.push_back(m);
        continue;
      }
      fit.warnings.push_back(fmt::format(
          "a pole at {:.6g} Hz (ζ = {:.3g}), stable at {} orders of the diagram, has a residue "
          "{:.3g} at the driving point {}, not > 0: not taken as a mode (a computational pole, "
          "or a mode with a node at the driving point: give the number of modes to keep it)",
          m.frequency_hz, m.damping, m.stable_orders, m.residues(d), data.drive_name));
    }
    if (kept.size() < fit.modes.size()) {
      fit.modes = std::move(kept);
      fit_residues(data, o, fit);
    }
  }
  build_model(data, o, fit);
  if (fit.status.ok() && fit.substructure.num_modes() == 0)
    fit.status = fem::Status::failure(fem::Status::Code::not_separable,
                                      "no mode could be mass-normalised at the driving point " +
                                          data.drive_name);

  // 5. What the user should know.
  for (std::size_t r = 0; r < fit.modes.size(); ++r) {
    const FittedMode& mode = fit.modes[r];
    const double bandwidth = 2.0 * mode.damping * mode.frequency_hz;
    if (data.method == SpectraMethod::welch && bandwidth < 4.0 * data.resolution_hz)
      fit.warnings.push_back(fmt::format(
          "mode {} ({:.6g} Hz): its half-power bandwidth, {:.3g} Hz, spans fewer than 4 lines of "
          "the Hann-windowed spectra ({:.3g} Hz apart): the window's leakage makes its damping "
          "come out too high; use longer segments or a periodic excitation",
          r + 1, mode.frequency_hz, bandwidth, data.resolution_hz));
  }
  if (o.lower_residual && L > 0) {
    const double omega = two_pi * data.frequency_hz(0);
    for (Eigen::Index c = 0; c < O; ++c) {
      const double share = std::abs(fit.lower_residual(c)) / (omega * omega) /
                           std::max(std::abs(data.H(0, c)), 1e-300);
      if (share > 0.05) {
        fit.warnings.push_back(fmt::format(
            "the lower residual (the modes below the band, or what the modes fitted leave "
            "unexplained at its bottom) makes {:.0f} % of {} at {:.6g} Hz; a [modal] model has no "
            "lower residual, so the model leaves it out: start the band below those modes to fit "
            "them as modes",
            100.0 * share, data.response_names[static_cast<std::size_t>(c)], data.frequency_hz(0)));
        break;
      }
    }
  }
  for (Eigen::Index c = 0; c < O; ++c) {
    const Eigen::VectorXd g = data.coherence.col(c);
    if (g.size() == 0 || !g.allFinite()) continue;
    const double mean = g.mean();
    if (mean < 0.9)
      fit.warnings.push_back(fmt::format(
          "{}: mean coherence {:.3f} in the band (noise, non-linearity or an unmeasured input)",
          data.response_names[static_cast<std::size_t>(c)], mean));
  }
  return fit;
}

} // namespace jointid::identify

#include "frf/continuation.hpp"

#include "fem/text.hpp"
#include "frf/hb_equations.hpp"
#include "joints/basis.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace jointid::frf {

using detail::two_pi;

namespace {

bool has_exact_friction(const std::vector<joints::Joint>& joints, const HarmonicBalanceOptions& o) {
  if (!o.exact_friction) return false;
  for (const joints::Joint& j : joints) {
    const int t = j.term_index(joints::Term::fc);
    if (t >= 0 && j.values[t] != 0.0) return true;
  }
  return false;
}

// A residual or a step as %g would print it: 7.05e-06, not 0.000007 (or 0.000000).
std::string hz(double f) {
  std::ostringstream s;
  s.precision(6);
  s << f << " Hz";
  return s.str();
}

// The harmonic-balance problem at one frequency: its receptances and its equations.
struct Frame {
  double omega;
  std::unique_ptr<HarmonicBalance> hb;
  std::unique_ptr<detail::Equations> eq;
};

class Tracer {
public:
  Tracer(const ModalSynthesis& H, const std::vector<joints::Joint>& joints, const fem::DofMap& dofs,
         std::vector<int> force_equations, const Eigen::MatrixXcd& F, std::vector<int> outputs,
         const ContinuationOptions& o)
      : H_(H), joints_(joints), dofs_(dofs), forces_(std::move(force_equations)), F_(F),
        outputs_(std::move(outputs)), o_(o) {}

  // `hz`, if given, is ω / 2π exactly as the user wrote it (the ends of the band).
  Frame frame(double omega, double hz = 0.0) const {
    Frame fr{omega,
             std::make_unique<HarmonicBalance>(H_, joints_, dofs_, forces_, outputs_,
                                               hz > 0.0 ? hz : omega / two_pi, o_.hb),
             nullptr};
    fr.eq = fr.hb->equations(joints_, F_);
    return fr;
  }

  // ∂R/∂ω at (z, ω) by a central difference.
  Eigen::VectorXd dR_domega(const Eigen::VectorXd& z, double omega) const {
    const double d = 1e-5 * omega;
    const Frame up = frame(omega + d), down = frame(omega - d);
    return (up.eq->residual(z, 1.0, nullptr) - down.eq->residual(z, 1.0, nullptr)) / (2.0 * d);
  }

  const HarmonicBalanceOptions& hb_options() const { return o_.hb; }

private:
  const ModalSynthesis& H_;
  const std::vector<joints::Joint>& joints_;
  const fem::DofMap& dofs_;
  std::vector<int> forces_;
  Eigen::MatrixXcd F_;
  std::vector<int> outputs_;
  ContinuationOptions o_;
};

// A point of the branch in physical units, with its unit tangent in the scaled coordinates of
// the time it was computed (`t`: n + 1 entries, the last one ω's).
struct State {
  Eigen::VectorXd z;
  double omega = 0.0;
  Eigen::VectorXd t;
  int iterations = 0;
  double residual = 0.0;
};

Eigen::VectorXd solve_bordered(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) {
  const Eigen::FullPivLU<Eigen::MatrixXd> lu(A);
  if (lu.isInvertible()) return lu.solve(b);
  Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd> cod(A);
  cod.setThreshold(1e-13);
  return cod.solve(b);
}

// The Floquet multipliers with hysteretic joints (sliders). A slider that sticks from the
// instant t_a of its last slide on has the force k (y − y(t_a) ± φ): its perturbation is
// k (δy(t) − δy(t_a)), and 0 while it slides (±f). So the joint's hysteretic force perturbation
// at t is K_st(t) δy(t) − Σ_a K_a(t) s_a, K_st the stiffness of the elements stuck at t, K_a
// that of those stuck since anchor a, and s_a = δy(t_a) a state of the variational equations
// (ṡ_a = 0, reset to δy at t_a). This is the exact linearisation of the sliders (the memory of
// the stick phase kept), not the tangent stiffness alone, which would forget where the stick
// phase began. The loop is taken on the step grid (t_n = n h, two passes from rest, as the
// harmonic balance does on its samples): the stuck set and anchors of a step are those of its
// end, an O(h) error at the few steps where a slider switches. With the flexibility R of the
// modes left out in series: δy = (I + R G_y')⁻¹ (P δq − R G_ẏ P δq̇ − R h0),
// δg = G_y' δy + G_ẏ P δq̇ + h0, G_y' = G_y + K_st, h0 = −Σ_a K_a s_a.
template <class Sample>
Eigen::VectorXcd hysteretic_monodromy(const std::vector<joints::Joint>& joints,
                                      const std::vector<joints::Sliders>& sliders,
                                      const HarmonicBalanceResult& r, const Eigen::VectorXd& om,
                                      const Eigen::VectorXd& d, const Eigen::MatrixXd& P,
                                      const Eigen::MatrixXd& R, long steps, Sample& sample,
                                      Eigen::VectorXd& gy, Eigen::VectorXd& gv) {
  const int nj = static_cast<int>(joints.size()), n = static_cast<int>(om.size());
  const int K = static_cast<int>(r.Y.rows()) - 1;
  const double omega = two_pi * r.frequency_hz, h = two_pi / omega / static_cast<double>(steps);
  const auto N = static_cast<std::size_t>(steps);
  // Per hysteretic joint: the stuck stiffness per sample, and the anchors' weights (−K_a) in
  // rows by sample (start[i] … start[i + 1]), each naming its state (slot).
  struct Loop {
    std::vector<double> stuck;
    std::vector<std::size_t> start;
    std::vector<std::pair<int, double>> weights;     // (state index, −K_a)
    std::vector<std::pair<std::size_t, int>> resets; // (sample, state index), sorted by sample
  };
  std::vector<Loop> loops(static_cast<std::size_t>(nj));
  int states = 0;
  for (int j = 0; j < nj; ++j) {
    const joints::Sliders& sl = sliders[static_cast<std::size_t>(j)];
    if (sl.empty()) continue;
    std::vector<double> y(N), g(N);
    for (std::size_t i = 0; i < N; ++i) {
      const double t = h * static_cast<double>(i);
      double v = r.Y(0, j).real();
      for (int k = 1; k <= K; ++k)
        v += (r.Y(k, j) * std::polar(1.0, k * omega * t)).real();
      y[i] = v;
    }
    std::vector<joints::LoopEntry> entries;
    joints::LoopWork work;
    joints::steady_loop(sl, y, false, g, &entries, work);
    std::sort(entries.begin(), entries.end(),
              [](const joints::LoopEntry& a, const joints::LoopEntry& b) { return a.n < b.n; });
    Loop& L = loops[static_cast<std::size_t>(j)];
    L.stuck.assign(N, 0.0);
    L.start.assign(N + 1, 0);
    std::map<int, int> slot; // anchor sample → state index
    for (const joints::LoopEntry& e : entries) {
      if (e.m == e.n) {
        L.stuck[static_cast<std::size_t>(e.n)] += e.value;
        continue;
      }
      auto [it, added] = slot.emplace(e.m, states);
      if (added) ++states;
      L.weights.emplace_back(it->second, e.value);
      ++L.start[static_cast<std::size_t>(e.n) + 1];
    }
    for (std::size_t i = 0; i < N; ++i)
      L.start[i + 1] += L.start[i];
    for (const auto& [sample, state] : slot)
      L.resets.emplace_back(static_cast<std::size_t>(sample), state);
  }
  const int dim = 2 * n + states;
  // The joints' force perturbation δg (nj × columns) at time t, grid sample i, for states X.
  // (Work arrays sized once: nothing is allocated inside the steps.)
  Eigen::VectorXd gyt(nj);
  Eigen::MatrixXd H0(nj, dim), dy(nj, dim), dg(nj, dim), Pv(nj, dim), rhs(nj, dim), A(nj, nj);
  Eigen::PartialPivLU<Eigen::MatrixXd> lu(nj);
  auto perturbation = [&](double t, std::size_t i, const Eigen::MatrixXd& X, bool want_force) {
    sample(t);
    gyt = gy;
    H0.setZero();
    for (int j = 0; j < nj; ++j) {
      const Loop& L = loops[static_cast<std::size_t>(j)];
      if (L.stuck.empty()) continue;
      gyt(j) += L.stuck[i];
      for (std::size_t e = L.start[i]; e < L.start[i + 1]; ++e)
        H0.row(j) += L.weights[e].second * X.row(2 * n + L.weights[e].first);
    }
    Pv.noalias() = P * X.middleRows(n, n);
    A.noalias() = R * gyt.asDiagonal(); // I + R G_y'
    A.diagonal().array() += 1.0;
    lu.compute(A);
    rhs.noalias() = P * X.topRows(n);
    H0 += gv.asDiagonal() * Pv; // (G_ẏ P δq̇ + h0, reused below)
    rhs.noalias() -= R * H0;
    dy.noalias() = lu.solve(rhs);
    if (want_force) dg.noalias() = gyt.asDiagonal() * dy + H0;
  };
  auto rate = [&](double t, std::size_t i, const Eigen::MatrixXd& X, Eigen::MatrixXd& Y) {
    perturbation(t, i, X, true);
    Y.setZero();
    const auto q = X.topRows(n), v = X.middleRows(n, n);
    Y.topRows(n) = v;
    Y.middleRows(n, n) = -(om.array().square().matrix().asDiagonal() * q) - d.asDiagonal() * v;
    Y.middleRows(n, n).noalias() -= P.transpose() * dg;
  };
  Eigen::MatrixXd W = Eigen::MatrixXd::Identity(dim, dim);
  Eigen::MatrixXd k1(dim, dim), k2 = k1, k3 = k1, k4 = k1, Wt = k1;
  for (long s = 0; s < steps; ++s) {
    const double t = static_cast<double>(s) * h;
    const auto i0 = static_cast<std::size_t>(s), i1 = static_cast<std::size_t>(s + 1) % N;
    rate(t, i0, W, k1);
    Wt = W + 0.5 * h * k1;
    rate(t + 0.5 * h, i1, Wt, k2);
    Wt = W + 0.5 * h * k2;
    rate(t + 0.5 * h, i1, Wt, k3);
    Wt = W + h * k3;
    rate(t + h, i1, Wt, k4);
    W += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    // the anchors at the step's end take δy there
    bool any = false;
    for (const Loop& L : loops)
      for (const auto& reset : L.resets)
        any = any || reset.first == i1;
    if (!any) continue;
    perturbation(t + h, i1, W, false);
    for (int j = 0; j < nj; ++j)
      for (const auto& [sample, state] : loops[static_cast<std::size_t>(j)].resets)
        if (sample == i1) W.row(2 * n + state) = dy.row(j);
  }
  if (!W.allFinite()) return Eigen::VectorXcd::Constant(1, std::nan(""));
  return Eigen::EigenSolver<Eigen::MatrixXd>(W, false).eigenvalues();
}

} // namespace

Stability floquet_stability(const ModalSynthesis& H, const std::vector<joints::Joint>& joints,
                            const fem::DofMap& dofs, const HarmonicBalanceResult& r,
                            const HarmonicBalanceOptions& o) {
  Stability out;
  if (has_exact_friction(joints, o)) {
    out.note = "not determined: exact dry friction has no derivative while a joint sticks";
    return out;
  }
  if (H.measured()) {
    out.note = "not determined: measured FRFs have no modes for Floquet's method";
    return out;
  }
  const int nj = static_cast<int>(joints.size());
  if (r.Y.cols() != nj || r.Y.rows() < 2 || !(r.frequency_hz > 0.0))
    throw std::invalid_argument("floquet_stability: the steady state does not fit the joints");
  const int K = static_cast<int>(r.Y.rows()) - 1;
  const double omega = two_pi * r.frequency_hz, T = two_pi / omega;
  const std::vector<int> jdofs = joints::joint_dof_set(joints, dofs);
  const Eigen::MatrixXd B = joints::joint_coordinates_on(joints, dofs, jdofs);
  const Eigen::VectorXd& Om = H.natural_frequencies();
  const Eigen::VectorXd& D = H.modal_damping();
  // The modes kept: below the cut-off, lowest first, at most 60.
  std::vector<int> keep;
  const double cutoff = 2.0 * (K + 1) * omega;
  std::vector<int> order(Om.size());
  for (int m = 0; m < Om.size(); ++m)
    order[m] = m;
  std::sort(order.begin(), order.end(), [&](int a, int b) { return Om(a) < Om(b); });
  for (int m : order)
    if (keep.size() < 3 || (Om(m) <= cutoff && keep.size() < 60)) keep.push_back(m);
  if (keep.empty()) {
    out.note = "not determined: the substructure has no modes";
    return out;
  }
  const int n = static_cast<int>(keep.size());
  out.modes = n;
  const Eigen::MatrixXd phi_all = H.shapes(jdofs);
  Eigen::MatrixXd phi(jdofs.size(), n);
  Eigen::VectorXd om(n), d(n);
  std::vector<bool> kept(Om.size(), false);
  for (int i = 0; i < n; ++i)
    phi.col(i) = phi_all.col(keep[i]), om(i) = Om(keep[i]), d(i) = D(keep[i]), kept[keep[i]] = true;
  const Eigen::MatrixXd P = B.transpose() * phi; // nj × n
  // The modes left out respond quasi-statically: the joints see their flexibility R (and the
  // synthesis' residual flexibility), in series with the kept modes.
  Eigen::MatrixXd R = B.transpose() * H.residual_flexibility(jdofs, jdofs) * B;
  for (int m = 0; m < Om.size(); ++m)
    if (!kept[m] && Om(m) > 0.0) {
      const Eigen::VectorXd p = B.transpose() * phi_all.col(m);
      R += p * p.transpose() / (Om(m) * Om(m));
    }

  // The joints' stiffness and damping along the orbit, seen through the flexibility of the
  // modes left out: δg = Gy δy + Gv δẏ with δy = P δq − R δg (and δẏ ≈ P δq̇ — the left-out
  // modes' share of the rate is neglected), so δg = S_y P δq + S_v P δq̇ with
  // S = (I + Gy R)⁻¹ [Gy, Gv].
  const double width = o.exact_friction ? 0.0 : o.friction_width;
  Eigen::VectorXd gy(nj), gv(nj);
  auto sample = [&](double t) {
    const Complex e1 = std::polar(1.0, omega * t);
    for (int j = 0; j < nj; ++j) {
      double y = r.Y(0, j).real(), v = 0.0;
      Complex e = 1.0;
      for (int k = 1; k <= K; ++k) {
        e *= e1; // e^{ikωt}
        y += (r.Y(k, j) * e).real();
        v += (Complex(0.0, k * omega) * r.Y(k, j) * e).real();
      }
      double g;
      detail::joint_force(joints[j], y, v, width, g, gy(j), gv(j));
    }
  };
  Eigen::MatrixXd Sy(nj, nj), Sv(nj, nj), A(nj, nj), Ainv(nj, nj);
  Eigen::PartialPivLU<Eigen::MatrixXd> lu(nj);
  auto derivatives = [&](double t) {
    sample(t);
    A = gy.asDiagonal() * R; // I + Gy R
    A.diagonal().array() += 1.0;
    lu.compute(A);
    Ainv = lu.inverse();
    Sy.noalias() = Ainv * gy.asDiagonal();
    Sv.noalias() = Ainv * gv.asDiagonal();
  };
  // Step: h ω_est ≤ 0.5 with ω_est² ≥ the largest stiffness over the period (Gershgorin-like
  // bound), and at least 16 steps per period of the highest harmonic.
  const int probe = 16 * (K + 1);
  double gy_max = 0.0, gv_max = 0.0;
  for (int i = 0; i < probe && nj > 0; ++i) { // no joints (a linear substructure): no bound
    sample(T * i / probe);
    gy_max = std::max(gy_max, gy.cwiseAbs().maxCoeff());
    gv_max = std::max(gv_max, gv.cwiseAbs().maxCoeff());
  }
  // Hysteretic joints: their elements, and the largest stiffness they add (all stuck).
  std::vector<joints::Sliders> sliders(static_cast<std::size_t>(nj));
  bool hysteretic = false;
  double slider_stiffness = 0.0;
  for (int j = 0; j < nj; ++j)
    if (joints[j].has_hysteretic_terms()) {
      sliders[static_cast<std::size_t>(j)] = joints::JointLaw(joints[j]).sliders();
      slider_stiffness =
          std::max(slider_stiffness, sliders[static_cast<std::size_t>(j)].stiffness_sum());
      hysteretic = true;
    }
  gy_max += slider_stiffness;
  const double p2 = P.squaredNorm();
  const double w_est = std::max(
      {std::sqrt(om.array().square().maxCoeff() + gy_max * p2), d.maxCoeff() + gv_max * p2, omega});
  const long steps = std::max<long>(probe, static_cast<long>(std::ceil(T * w_est / 0.5)));
  if (steps > 400000) {
    out.note = "not determined: the joints are too stiff for the explicit check (" +
               std::to_string(steps) + " steps a period)";
    return out;
  }
  if (hysteretic) {
    out.multipliers = hysteretic_monodromy(joints, sliders, r, om, d, P, R, steps, sample, gy, gv);
    if (!out.multipliers.allFinite()) {
      out.note = "not determined: the check diverged";
      out.multipliers.resize(0);
      return out;
    }
    out.stable = out.multipliers.cwiseAbs().maxCoeff() < 1.0 + 1e-6;
    return out;
  }
  // W = [δq; δq̇] for the 2n unit initial conditions; Ẇ = A(t) W. The joints' S_y, S_v are
  // formed once per time — at the start, the middle and the end of each step, the end being the
  // next step's start — and nothing is allocated inside the loop.
  Eigen::MatrixXd W = Eigen::MatrixXd::Identity(2 * n, 2 * n);
  struct Joints {
    Eigen::MatrixXd Sy, Sv;
  };
  auto joints_at = [&](double t, Joints& j) {
    derivatives(t);
    j.Sy = Sy, j.Sv = Sv;
  };
  const Eigen::VectorXd om2 = om.array().square();
  Eigen::MatrixXd Pq(nj, 2 * n), Pv(nj, 2 * n), G(nj, 2 * n);
  // (lazy products for a few modes: there the blocked product's packing costs more than its
  // arithmetic)
  const bool small = n <= 16;
  auto rate = [&](const Joints& j, const Eigen::MatrixXd& X, Eigen::MatrixXd& Y) {
    const auto q = X.topRows(n), v = X.bottomRows(n);
    if (small) {
      Pq.noalias() = P.lazyProduct(q), Pv.noalias() = P.lazyProduct(v);
      G.noalias() = j.Sy.lazyProduct(Pq), G.noalias() += j.Sv.lazyProduct(Pv);
    } else {
      Pq.noalias() = P * q, Pv.noalias() = P * v;
      G.noalias() = j.Sy * Pq, G.noalias() += j.Sv * Pv;
    }
    Y.topRows(n) = v;
    Y.bottomRows(n) = -(om2.asDiagonal() * q) - d.asDiagonal() * v;
    if (small)
      Y.bottomRows(n).noalias() -= P.transpose().lazyProduct(G);
    else
      Y.bottomRows(n).noalias() -= P.transpose() * G;
  };
  // A half-wave symmetric orbit, y(t + T/2) = −y(t), of odd joint forces: their derivatives,
  // even in (y, ẏ), repeat every half period, so the monodromy is the half period's squared
  // (Φ(T) = Φ(T/2)²) and half the period is integrated.
  bool half = true;
  for (Eigen::Index k = 0; k <= K && half; k += 2)
    half = r.Y.row(k).isZero(0.0);
  for (const joints::Joint& j : joints)
    for (std::size_t t = 0; t < j.terms.size() && half; ++t)
      half = !joints::term_info(j.terms[t]).even || j.values[t] == 0.0;
  const long span = half ? (steps + 1) / 2 : steps;
  const double hs = (half ? 0.5 * T : T) / static_cast<double>(span);
  Joints start{Sy, Sv}, middle = start, end = start;
  Eigen::MatrixXd k1(2 * n, 2 * n), k2 = k1, k3 = k1, k4 = k1, Wt = k1;
  joints_at(0.0, start);
  for (long s = 0; s < span; ++s) {
    const double h = hs, t = static_cast<double>(s) * h;
    joints_at(t + 0.5 * h, middle);
    joints_at(t + h, end);
    rate(start, W, k1);
    Wt = W + 0.5 * h * k1;
    rate(middle, Wt, k2);
    Wt = W + 0.5 * h * k2;
    rate(middle, Wt, k3);
    Wt = W + h * k3;
    rate(end, Wt, k4);
    W += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
    std::swap(start, end);
  }
  if (!W.allFinite()) {
    out.note = "not determined: the check diverged";
    return out;
  }
  out.multipliers = Eigen::EigenSolver<Eigen::MatrixXd>(W, false).eigenvalues();
  if (half) out.multipliers = out.multipliers.array().square();
  out.stable = out.multipliers.cwiseAbs().maxCoeff() < 1.0 + 1e-6;
  return out;
}

namespace {

// The sign of the determinant of the even harmonics' block of the Jacobian of the equations
// over all harmonics, at a half-wave symmetric solution z of the symmetric equations `eq`.
// There the Jacobian is block-diagonal (odd, even): an even perturbation of a symmetric orbit
// stays even. The even block is singular where a Floquet multiplier crosses +1 with an
// asymmetric perturbation (a symmetry-breaking bifurcation), so its sign changes there.
int even_block_sign(const HarmonicBalance& hb, const detail::Equations& eq,
                    const Eigen::VectorXd& z, const std::vector<joints::Joint>& joints,
                    const Eigen::MatrixXcd& F) {
  const int blocks = eq.size() / eq.m();
  // A start with even harmonics: the equations over all harmonics.
  const Eigen::MatrixXcd asymmetric = Eigen::MatrixXcd::Ones(eq.K + 1, blocks);
  const std::unique_ptr<detail::Equations> all = hb.equations(joints, F, &asymmetric);
  Eigen::VectorXd za = Eigen::VectorXd::Zero(all->size());
  all->pack(eq.unpack(z, blocks), za);
  Eigen::MatrixXd J(all->size(), all->size());
  all->residual(za, 1.0, &J);
  std::vector<int> rows; // the even harmonics' unknowns, block by block
  for (int b = 0; b < blocks; ++b) {
    const int o = b * all->m();
    rows.push_back(o); // the mean
    for (int i = 1; i < all->count(); ++i)
      if (all->harmonics[i] % 2 == 0)
        rows.push_back(o + all->at(i)), rows.push_back(o + all->at(i) + 1);
  }
  const auto n = static_cast<Eigen::Index>(rows.size());
  Eigen::MatrixXd E(n, n);
  for (Eigen::Index r = 0; r < n; ++r)
    for (Eigen::Index c = 0; c < n; ++c)
      E(r, c) = J(rows[r], rows[c]);
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(E);
  int sign = static_cast<int>(lu.permutationP().determinant());
  for (Eigen::Index i = 0; i < n; ++i)
    sign *= lu.matrixLU()(i, i) < 0.0 ? -1 : 1;
  return sign;
}

// The branch's points without their stability, and per point the sign of the determinant of
// the even harmonics' block of the all-harmonics Jacobian (`even`; empty unless the equations
// are half-wave symmetric and stability is asked for).
ResponseBranch trace_points(const ModalSynthesis& H, const std::vector<joints::Joint>& joints,
                            const fem::DofMap& dofs, std::vector<int> force_equations,
                            const Eigen::MatrixXcd& F, std::vector<int> outputs, double start_hz,
                            double end_hz, const ContinuationOptions& o,
                            const std::function<void(double)>& progress, std::vector<int>& even) {
  if (!(start_hz > 0.0) || !(end_hz > 0.0) || start_hz == end_hz)
    throw std::invalid_argument("response curve: the band needs two different frequencies > 0 "
                                "Hz, got " +
                                hz(start_hz) + " and " + hz(end_hz));
  if (!(o.min_step > 0.0) || !(o.initial_step >= o.min_step) || !(o.max_step >= o.initial_step))
    throw std::invalid_argument(
        "response curve: steps must satisfy 0 < min_step <= initial_step <= max_step");
  if (o.max_points < 2)
    throw std::invalid_argument("response curve: max_points must be at least 2");
  const Tracer tracer(H, joints, dofs, std::move(force_equations), F, std::move(outputs), o);
  const double w0 = two_pi * start_hz, w1 = two_pi * end_hz, dir = w1 > w0 ? 1.0 : -1.0;
  const double band = std::abs(w1 - w0);
  const double tol = std::max(o.hb.tolerance, 1e-10);
  ResponseBranch branch;
  const bool exact_friction = has_exact_friction(joints, o.hb);
  if (o.stability && exact_friction)
    branch.notes.push_back("stability not determined: exact dry friction has no derivative "
                           "while a joint sticks");

  // The start: a fixed-frequency solve (from the linear guess, then by load steps).
  Frame fr = tracer.frame(w0, start_hz);
  const int n = fr.eq->size(), nY = fr.eq->nj * fr.eq->m();
  // Scales: joint amplitudes by `amp` (the largest met so far); friction force unknowns through
  // their compliance c; ω by the band.
  Eigen::VectorXd unit = Eigen::VectorXd::Ones(n);
  for (std::size_t f = 0; f < fr.eq->friction.size(); ++f)
    unit.segment((fr.eq->nj + static_cast<int>(f)) * fr.eq->m(), fr.eq->m())
        .setConstant(1.0 / fr.eq->friction[f].c);
  State s;
  s.omega = w0;
  {
    s.z = fr.hb->first_guess(*fr.eq, nullptr);
    const Eigen::VectorXd guess = s.z;
    bool ok = detail::newton(*fr.eq, s.z, 1.0, o.hb, s.iterations, s.residual);
    const int steps = std::max(1, o.hb.continuation_steps);
    if (!ok) {
      s.z = guess / steps;
      ok = true;
      for (int i = 1; i <= steps && ok; ++i)
        ok = detail::newton(*fr.eq, s.z, static_cast<double>(i) / steps, o.hb, s.iterations,
                            s.residual);
    }
    if (!ok) {
      branch.notes.push_back("no steady state found at the start, " + hz(start_hz) + " (residual " +
                             significant(s.residual, 3) + ")");
      return branch;
    }
  }
  double amp = std::max(s.z.head(nY).norm(), 1e-300);
  auto scale = [&](const Eigen::VectorXd& z, double w) {
    Eigen::VectorXd u(n + 1);
    u.head(n) = z.cwiseQuotient(unit) / amp;
    u(n) = w / band;
    return u;
  };
  auto unscale = [&](const Eigen::VectorXd& u, Eigen::VectorXd& z, double& w) {
    z = u.head(n).cwiseProduct(unit) * amp;
    w = u(n) * band;
  };
  // The bordered Jacobian [J_z S_z, R_ω Δω; tᵀ] at (z, ω) and the residual R.
  auto bordered = [&](const Eigen::VectorXd& z, double w, const Eigen::VectorXd& t,
                      Eigen::VectorXd& R, double* znorm) {
    const Frame f = tracer.frame(w);
    if (znorm) *znorm = f.eq->norm(z);
    Eigen::MatrixXd Jz(n, n);
    R = f.eq->residual(z, 1.0, &Jz);
    Eigen::MatrixXd A(n + 1, n + 1);
    A.topLeftCorner(n, n) = Jz * (unit * amp).asDiagonal();
    A.topRightCorner(n, 1) = tracer.dR_domega(z, w) * band;
    A.bottomRows(1) = t.transpose();
    return A;
  };
  auto tangent = [&](const Eigen::VectorXd& z, double w, const Eigen::VectorXd& previous) {
    Eigen::VectorXd R;
    const Eigen::MatrixXd A = bordered(z, w, previous, R, nullptr);
    Eigen::VectorXd e = Eigen::VectorXd::Zero(n + 1);
    e(n) = 1.0;
    Eigen::VectorXd t = solve_bordered(A, e);
    return Eigen::VectorXd(t / t.norm());
  };
  // Corrector from the prediction u_p along t: Newton on [R; tᵀ(u − u_p)] = 0.
  auto correct = [&](const Eigen::VectorXd& u_p, const Eigen::VectorXd& t, State& out) {
    Eigen::VectorXd u = u_p;
    for (int it = 0; it < 12; ++it) {
      unscale(u, out.z, out.omega);
      if (!(out.omega > 0.0) || !out.z.allFinite()) return false;
      Eigen::VectorXd R;
      double znorm = 0.0;
      const Eigen::MatrixXd A = bordered(out.z, out.omega, t, R, &znorm);
      out.residual = R.norm() / std::max(znorm, 1e-300);
      out.iterations = it;
      const double arc = t.dot(u - u_p);
      if (out.residual < tol && std::abs(arc) < 1e-10) return true;
      Eigen::VectorXd b(n + 1);
      b.head(n) = -R;
      b(n) = -arc;
      const Eigen::VectorXd du = solve_bordered(A, b);
      if (!du.allFinite()) return false;
      u += du;
    }
    unscale(u, out.z, out.omega);
    const Frame f = tracer.frame(out.omega);
    out.residual = f.eq->residual(out.z, 1.0, nullptr).norm() / std::max(f.eq->norm(out.z), 1e-300);
    return out.residual < tol;
  };
  auto record = [&](const State& st) {
    const Frame f = tracer.frame(st.omega, st.omega == w0   ? start_hz
                                           : st.omega == w1 ? end_hz
                                                            : 0.0);
    ResponsePoint p;
    p.hb = f.hb->result(*f.eq, st.z);
    p.hb.status = {};
    p.hb.iterations = st.iterations;
    p.hb.residual = st.residual;
    if (o.stability && !exact_friction && f.eq->symmetric())
      even.push_back(even_block_sign(*f.hb, *f.eq, st.z, joints, F));
    branch.points.push_back(std::move(p));
  };
  // A fixed-frequency solve at ω from a guess (the last point at the band's end).
  auto solve_at = [&](double w, Eigen::VectorXd z, State& out) {
    const Frame f = tracer.frame(w);
    out.iterations = 0;
    if (!detail::newton(*f.eq, z, 1.0, o.hb, out.iterations, out.residual)) return false;
    out.z = std::move(z);
    out.omega = w;
    return true;
  };

  Eigen::VectorXd e_w = Eigen::VectorXd::Zero(n + 1);
  e_w(n) = dir;
  s.t = tangent(s.z, s.omega, e_w);
  record(s);
  double ds = o.initial_step, covered = 0.0;
  const double corner_step = std::max(o.min_step, 1e-3 * o.max_step);
  while (true) {
    if (static_cast<int>(branch.points.size()) >= o.max_points) {
      branch.notes.push_back("stopped after " + std::to_string(o.max_points) + " points at " +
                             hz(s.omega / two_pi) + " (max_points)");
      return branch;
    }
    if (ds < o.min_step) {
      branch.notes.push_back("continuation stalled at " + hz(s.omega / two_pi) +
                             ": no step down to " + significant(o.min_step, 3) + " converged");
      return branch;
    }
    const Eigen::VectorXd u = scale(s.z, s.omega);
    State next;
    if (!correct(u + ds * s.t, s.t, next)) {
      ds *= 0.5;
      continue;
    }
    next.t = tangent(next.z, next.omega, s.t);
    // A sharp turn: retried shorter, unless the step is already short — then it is a corner of
    // the branch (exact friction: a sample's stick state changes), which no step removes.
    if (next.t.dot(s.t) < std::cos(25.0 * std::numbers::pi / 180.0) && ds > corner_step) {
      ds *= 0.5;
      continue;
    }
    // A fold between s and next: locate it (secant on the arclength, tangent's ω component).
    if (s.t(n) * next.t(n) < 0.0) {
      double a = 0.0, b = ds, ta = s.t(n), tb = next.t(n);
      State fold = next;
      bool found = false;
      for (int it = 0; it < 8; ++it) {
        const double c = a - ta * (b - a) / (tb - ta);
        State trial;
        if (!correct(u + c * s.t, s.t, trial)) break;
        trial.t = tangent(trial.z, trial.omega, s.t);
        fold = trial, found = true;
        if (std::abs(trial.t(n)) < 1e-8) break;
        if (trial.t(n) * ta > 0.0)
          a = c, ta = trial.t(n);
        else
          b = c, tb = trial.t(n);
      }
      if (found) {
        record(fold);
        branch.folds.push_back(static_cast<int>(branch.points.size()) - 1);
      }
    }
    // Past the band's end: finish exactly there.
    if ((next.omega - w1) * dir >= 0.0) {
      const double x = (w1 - s.omega) / (next.omega - s.omega);
      State last;
      if (!solve_at(w1, s.z + x * (next.z - s.z), last)) {
        branch.notes.push_back("no steady state found at the end, " + hz(end_hz));
        return branch;
      }
      record(last);
      branch.complete = true;
      if (progress) progress(1.0);
      return branch;
    }
    if ((next.omega - w0) * dir < 0.0) {
      branch.notes.push_back("the branch turned back out of the band at its start, " +
                             hz(start_hz) + ", after " + std::to_string(branch.folds.size()) +
                             " folds");
      return branch;
    }
    record(next);
    ds = next.iterations <= 3   ? std::min(1.5 * ds, o.max_step)
         : next.iterations >= 7 ? 0.7 * ds
                                : ds;
    s = std::move(next);
    // Rescale to the largest amplitude met; the tangent, in the new scale, renormalised.
    const double a_new = std::max(amp, s.z.head(nY).norm());
    if (a_new > amp) {
      s.t.head(n) *= amp / a_new;
      s.t /= s.t.norm();
      amp = a_new;
    }
    covered = std::max(covered, std::abs(s.omega - w0) / band);
    if (progress) progress(covered);
  }
}

// Each point's stability from Floquet multipliers computed at some of them (see
// continuation.hpp): the first and last points, every `stride`-th, each fold and its
// neighbours, both sides of each sign change of the even block's determinant; then every point
// between two computed ones whose verdicts differ, until neighbouring computed points agree or
// are adjacent. A point between two that agree takes their verdict.
void assign_stability(ResponseBranch& branch, const std::vector<int>& even, int stride,
                      const std::function<Stability(const HarmonicBalanceResult&)>& check,
                      const std::function<void(double)>& progress) {
  std::vector<ResponsePoint>& p = branch.points;
  const std::size_t N = p.size();
  if (N == 0) return;
  std::vector<char> wanted(N, 0);
  const auto want = [&](std::ptrdiff_t i) {
    if (i >= 0 && static_cast<std::size_t>(i) < N) wanted[static_cast<std::size_t>(i)] = 1;
  };
  for (std::size_t i = 0; i < N; i += static_cast<std::size_t>(std::max(1, stride)))
    want(static_cast<std::ptrdiff_t>(i));
  want(static_cast<std::ptrdiff_t>(N) - 1);
  for (int f : branch.folds)
    want(f - 1), want(f), want(f + 1);
  for (std::size_t i = 1; i < even.size() && i < N; ++i)
    if (even[i] != even[i - 1])
      want(static_cast<std::ptrdiff_t>(i) - 1), want(static_cast<std::ptrdiff_t>(i));
  // Progress: the points computed of those wanted so far (more may be wanted later), never
  // going back.
  double reported = 0.0;
  std::size_t done = 0, undetermined = 0;
  std::string first_note; // of the first point whose stability could not be determined
  for (bool more = true; more;) {
    for (std::size_t i = 0; i < N; ++i)
      if (wanted[i] && !p[i].stability_checked) {
        const Stability s = check(p[i].hb);
        p[i].stable = s.stable;
        if (s.stable) p[i].max_multiplier = s.multipliers.cwiseAbs().maxCoeff();
        p[i].stability_checked = true;
        if (!s.stable && undetermined++ == 0)
          first_note =
              hz(p[i].hb.frequency_hz) + ": " + (s.note.empty() ? "no reason given" : s.note);
        ++done;
        if (progress) {
          const auto total = static_cast<double>(std::count(wanted.begin(), wanted.end(), 1));
          reported = std::max(reported, static_cast<double>(done) / total);
          progress(reported);
        }
      }
    more = false;
    for (std::size_t a = 0, b = 1; b < N; ++b) {
      if (!p[b].stability_checked) continue;
      if (p[a].stable != p[b].stable && b > a + 1) {
        for (std::size_t i = a + 1; i < b; ++i)
          wanted[i] = 1;
        more = true;
      }
      a = b;
    }
  }
  for (std::size_t a = 0, b = 1; b < N; ++b) {
    if (!p[b].stability_checked) continue;
    for (std::size_t i = a + 1; i < b; ++i)
      p[i].stable = p[a].stable;
    a = b;
  }
  if (undetermined > 0)
    branch.notes.push_back("the stability of " + std::to_string(undetermined) + " of the " +
                           std::to_string(done) +
                           " points whose Floquet multipliers were computed could not be "
                           "determined (the first at " +
                           first_note + ")");
}

} // namespace

ResponseBranch trace_response(const ModalSynthesis& H, const std::vector<joints::Joint>& joints,
                              const fem::DofMap& dofs, std::vector<int> force_equations,
                              const Eigen::MatrixXcd& F, std::vector<int> outputs, double start_hz,
                              double end_hz, const ContinuationOptions& o,
                              const std::function<void(double)>& progress) {
  if (o.stability_stride < 1)
    throw std::invalid_argument("response curve: stability_stride must be at least 1");
  std::vector<int> even;
  const bool stability = o.stability && !has_exact_friction(joints, o.hb);
  // Tracing reports the first half of the fraction, the stability the second (if checked).
  const auto half = [&](double offset) -> std::function<void(double)> {
    if (!progress) return {};
    if (!stability) return progress;
    return [&progress, offset](double fraction) { progress(offset + 0.5 * fraction); };
  };
  ResponseBranch branch = trace_points(H, joints, dofs, std::move(force_equations), F,
                                       std::move(outputs), start_hz, end_hz, o, half(0.0), even);
  if (stability)
    assign_stability(
        branch, even, o.stability_stride,
        [&](const HarmonicBalanceResult& r) { return floquet_stability(H, joints, dofs, r, o.hb); },
        half(0.5));
  if (progress) progress(1.0);
  return branch;
}

ResponseCurves response_curves(const Substructure& sub, const std::vector<joints::Joint>& joints,
                               const fem::NodeDof& force, const std::vector<double>& amplitudes,
                               double start_hz, double end_hz, const ContinuationOptions& o,
                               const std::function<void(std::size_t, double)>& progress) {
  if (amplitudes.empty())
    throw std::invalid_argument("response curves: expected at least one force amplitude");
  for (double a : amplitudes)
    if (!(std::isfinite(a) && a > 0.0))
      throw std::invalid_argument("response curves: force amplitudes must be finite and > 0, got " +
                                  std::to_string(a));
  if (!(start_hz > 0.0) || !(end_hz > 0.0) || !std::isfinite(start_hz) || !std::isfinite(end_hz) ||
      start_hz == end_hz)
    throw std::invalid_argument("response curves: the band needs two different finite "
                                "frequencies > 0 Hz, got " +
                                hz(start_hz) + " and " + hz(end_hz));
  const fem::DofMap& dofs = sub.dofs();
  const int force_eq = dofs.equation(force); // throws for a DOF not in the model
  ResponseCurves out;
  out.harmonics = o.hb.harmonics;
  out.amplitudes = amplitudes;
  std::vector<int> outputs = joints::joint_dof_set(joints, dofs);
  if (std::find(outputs.begin(), outputs.end(), force_eq) == outputs.end())
    outputs.push_back(force_eq);
  for (int e : outputs)
    out.dofs.push_back(dofs.node_dof(e));
  const ModalSynthesis synthesis = sub.synthesis(
      outputs, synthesis_band_hz(std::max(start_hz, end_hz), o.hb.harmonics), &out.notes);
  if (!synthesis.status().ok()) {
    out.status = synthesis.status();
    return out;
  }
  // An undamped mode where the harmonics reach (fundamental to harmonic K): only the joints can
  // bound its resonance; without a dissipative joint term it is unbounded there, and the points
  // near it are the arithmetic's limits (|X| of 1e14 m), not a response. Said, with the cure.
  {
    bool dissipates = false;
    for (const auto& j : joints)
      for (std::size_t t = 0; t < j.terms.size(); ++t)
        if (joints::term_info(j.terms[t]).nature == joints::Nature::dissipative &&
            j.values[t] != 0.0)
          dissipates = true;
    const double lo = std::min(start_hz, end_hz),
                 hi = std::max(start_hz, end_hz) * std::max(1, o.hb.harmonics);
    const Eigen::VectorXd& w = synthesis.natural_frequencies();
    const Eigen::VectorXd& d = synthesis.modal_damping();
    for (Eigen::Index r = 0; r < w.size(); ++r) {
      const double f = w(r) / two_pi;
      if (d(r) == 0.0 && f >= lo && f <= hi)
        out.notes.push_back(
            "mode " + std::to_string(r + 1) + " (" + hz(f) +
            ") has no damping (modal damping 0) and lies where the harmonics reach (" + hz(lo) +
            " to " + hz(hi) + "): " +
            (dissipates ? "only the joints' damping bounds its resonance"
                        : "no joint term dissipates either, so its resonance is unbounded and "
                          "the points near it are the arithmetic's limits, not a response") +
            "; give the model damping ([damping])");
    }
  }
  for (std::size_t i = 0; i < amplitudes.size(); ++i) {
    std::function<void(double)> each;
    if (progress) each = [&progress, i](double fraction) { progress(i, fraction); };
    Eigen::MatrixXcd F = Eigen::MatrixXcd::Zero(2, 1);
    F(1, 0) = Complex(0.0, -amplitudes[i]);
    out.curves.push_back(
        trace_response(synthesis, joints, dofs, {force_eq}, F, outputs, start_hz, end_hz, o, each));
  }
  return out;
}

} // namespace jointid::frf

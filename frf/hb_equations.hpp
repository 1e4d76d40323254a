#pragma once
/// Internal to jointid_frf (not part of the API): the harmonic-balance equations at one
/// frequency, shared by HarmonicBalance::solve() and the frequency continuation.
#include "frf/harmonic_balance.hpp"

#include "fem/fft.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <memory>
#include <new>
#include <numbers>
#include <span>
#include <vector>

namespace jointid::frf::detail {

constexpr double two_pi = 2.0 * std::numbers::pi;

// A joint's smooth force g and its derivatives at one time (the stability check's), but for
// its hysteretic terms (sliders: they need a history). Coulomb friction is left out when it is
// handled exactly (`width` = 0), else regularised as fc·tanh(ẏ/width), as in add_joint_forces()
// below.
inline void joint_force(const joints::Joint& j, double y, double v, double width, double& g,
                        double& gy, double& gv) {
  g = gy = gv = 0.0;
  for (std::size_t t = 0; t < j.terms.size(); ++t) {
    const double b = j.values[t];
    if (joints::has_parameters(j.terms[t])) {
      if (j.terms[t] != joints::Term::gap) continue;
      double slope;
      g += joints::gap_force(j.parameter(t, "delta"), j.parameter(t, "kg"), y, &slope);
      gy += slope;
    } else if (joints::is_dry_friction(j.terms[t])) {
      if (width == 0.0) continue;
      const double th = std::tanh(v / width);
      g += b * th;
      gv += b * (1.0 - th * th) / width;
    } else {
      g += b * joints::basis(j.terms[t], y, v);
      gy += b * joints::basis_dy(j.terms[t], y, v);
      gv += b * joints::basis_dydot(j.terms[t], y, v);
    }
  }
}

// A joint at small amplitude: its linear stiffness (k, a hysteretic term's kt, a gap's kg
// when it has no clearance) and its linear viscous damping (c); the other terms vanish there.
// The harmonic balance's linear start and the backbone's linear mode.
struct LinearJoint {
  double stiffness = 0.0, damping = 0.0;
};
inline LinearJoint linear_joint(const joints::Joint& j) {
  LinearJoint out;
  for (std::size_t t = 0; t < j.terms.size(); ++t) {
    const joints::TermInfo& info = joints::term_info(j.terms[t]);
    if (info.parameters.size() > 0) {
      if (j.terms[t] == joints::Term::jenkins || j.terms[t] == joints::Term::iwan)
        out.stiffness += j.parameter(t, "kt");
      else if (j.terms[t] == joints::Term::gap && j.parameter(t, "delta") == 0.0)
        out.stiffness += j.parameter(t, "kg");
      continue;
    }
    if (info.degree != 1) continue;
    (info.nature == joints::Nature::conservative ? out.stiffness : out.damping) += j.values[t];
  }
  return out;
}

// A joint's memoryless force g and its derivatives at the n time samples y, ẏ, added to the
// columns of g (n × 3: g, ∂g/∂y, ∂g/∂ẏ): its coefficient terms and gaps; the hysteretic terms
// are the equations' (Equations::sliders). Coulomb friction is left out when it is handled
// exactly (`width` = 0), else regularised as fc·tanh(ẏ/width).
inline void add_joint_forces(const joints::Joint& j, const double* y, const double* v, int n,
                             double width, Eigen::Map<Eigen::MatrixXd>& g) {
  const auto size = static_cast<std::size_t>(n);
  const std::span<const double> ys(y, size), vs(v, size);
  const std::span<double> gs(g.col(0).data(), size), gys(g.col(1).data(), size),
      gvs(g.col(2).data(), size);
  for (std::size_t t = 0; t < j.terms.size(); ++t) {
    const double b = j.values[t];
    if (joints::has_parameters(j.terms[t])) {
      if (j.terms[t] != joints::Term::gap) continue;
      const double delta = j.parameter(t, "delta"), kg = j.parameter(t, "kg");
      for (std::size_t i = 0; i < size; ++i) {
        double slope;
        gs[i] += joints::gap_force(delta, kg, ys[i], &slope);
        gys[i] += slope;
      }
      continue;
    }
    if (!joints::is_dry_friction(j.terms[t])) {
      joints::add_samples(j.terms[t], b, ys, vs, gs, gys, gvs);
      continue;
    }
    if (width == 0.0) continue;
    for (std::size_t i = 0; i < size; ++i) {
      const double th = std::tanh(vs[i] / width);
      gs[i] += b * th;
      gvs[i] += b * (1.0 - th * th) / width;
    }
  }
}

// y = A x and y = Aᵀ x for the small dense tables of one point (A column-major, x and y
// contiguous, y not aliasing x). Written as inline column updates and dot products: at these
// sizes (a few hundred entries) Eigen's general matrix-vector kernel costs more in dispatch
// and blocking than the arithmetic (about 700 instructions a call for a 48 × 11 table).
inline void multiply(const Eigen::MatrixXd& A, const double* x, double* y) {
  const Eigen::Index rows = A.rows();
  Eigen::Map<Eigen::VectorXd> out(y, rows);
  out.setZero();
  for (Eigen::Index j = 0; j < A.cols(); ++j)
    if (x[j] != 0.0) out += x[j] * A.col(j);
}
inline void multiply_transposed(const Eigen::MatrixXd& A, const double* x, double* y) {
  const Eigen::Map<const Eigen::VectorXd> in(x, A.rows());
  for (Eigen::Index j = 0; j < A.cols(); ++j)
    y[j] = A.col(j).dot(in);
}

// A joint with exact dry friction: its limit, its augmentation r (N s/m) and a compliance c
// (m/N) that puts its residual rows in metres like the others.
struct Friction {
  int joint;
  double limit, r, c;
};

// The equations of one solve. The harmonics solved for are `harmonics` (ascending): 0 … K, or,
// for a half-wave symmetric problem, the odd ones 1, 3, … ≤ K (the even ones are then exactly
// zero and are not unknowns). Unknowns z: per joint j, at offset j m(), Re Y_0 if the mean is
// solved for, then Re Y_k, Im Y_k for each other harmonic k; then per friction joint f, at
// offset (nj + f) m(), its force harmonics Λ packed the same way (N). The time samples are
// θ_n = 2πn / Nt over the period, or over its first half (n < Nt, Nt the half period's count)
// for a symmetric problem: y(θ + π) = −y(θ), and the sums over half the period are the period's
// for the harmonics that occur. residual() works in scratch arrays of its own (sized once): a
// Newton iteration allocates nothing, and one Equations serves one thread.
struct Equations {
  int K, nj, Nt; // K: the results' harmonics 0 … K; Nt: the samples kept
  const std::vector<int>& harmonics;
  const HarmonicBlocks& Hyy; // per harmonic 0 … K
  CMatrix HyF_F;             // (K+1) × nj: H_yf(kω) F_k, the joints' response to the force alone
  CMatrix Fk;                // (K+1) × n_forces: the force harmonics
  const std::vector<joints::Joint>& joints;
  double width; // 0: friction exact
  std::vector<Friction> friction;
  // Per sample n: ∂y_n/∂z and ∂ẏ_n/∂z / ω of one joint (Nt × m()), both stacked (2Nt × m(),
  // one product gives y and ẏ / ω), and the forward transform from samples to packed
  // harmonics, transposed (Nt × m(): its rows as contiguous columns).
  const Eigen::MatrixXd &dy, &dv_unit, &dyv_unit, &forward_t;
  // cos(pθ_n) beside sin(pθ_n) for the p = 0, s, 2s, … 2 max(harmonics) that products of two
  // harmonics make (s = 1, or 2 when symmetric): the harmonics of sample weights.
  const Eigen::MatrixXd& trig;
  double omega;
  // Per joint, the elements of its hysteretic terms (jenkins, iwan), all in parallel; empty for
  // a joint without. Their force at the samples is the steady loop (joints::steady_loop): the
  // elements start at rest at zero deformation and run over the period (both halves when
  // symmetric) until it closes; its exact derivative with respect to the samples is kept for
  // jacobian().
  std::vector<joints::Sliders> sliders{};

  // From this many unknowns per block (a periodic test's hundreds of lines) the transforms
  // between samples and harmonics run by FFT (below: forward, trig_sums, samples), and so does
  // the hysteretic loop's derivative, O(m Nt log Nt) instead of the forward table's O(m² Nt).
  // A variable so that the tests can compare the two routes.
  static inline int fft_from = 96;
  // From this many unknowns per block (and by FFT) nothing is tabulated and the Jacobian is
  // never formed: at a ground-vibration test's thousands of lines its tables and the dense
  // matrix would take O(m Nt) and O(m²) memory (over 100 GB and 2.7 GB at 9 000 lines) and its
  // factorisation O(m³). Newton's steps are solved by GMRES instead, with products J v
  // (jacobian_times(), by FFT, O(Nt log Nt) a product) and a preconditioner of each line's own
  // coupling (precondition()). Faster from the FFT's threshold on (bench_periodic_balance: 1.4
  // against 5.1 ms a steady state at 129 unknowns, 19 against 1 280 ms at 1 025). A variable so
  // that the tests can compare the two routes.
  static inline int matrix_free_from = 96;

  bool symmetric() const { return harmonics.front() != 0; }
  int count() const { return static_cast<int>(harmonics.size()); }
  int m() const { return 2 * count() - (symmetric() ? 0 : 1); }
  int size() const { return (nj + static_cast<int>(friction.size())) * m(); }
  // Offset in a block of the real part of harmonics[i] (its imaginary part follows); i ≥ 1
  // when the mean is solved for (the mean, at 0, has no imaginary part).
  int at(int i) const { return symmetric() ? 2 * i : 2 * i - 1; }
  int first() const { return symmetric() ? 0 : 1; } // the first index i with an imaginary part

  // Work arrays of residual() and jacobian(), views into one buffer (one allocation per
  // Equations: at a harmonic-balance point of a few µs the allocator was a fifth of the time).
  // A copy starts empty: the views must not point into another object's buffer.
  struct Scratch {
    using Vector = Eigen::Map<Eigen::VectorXd>;
    using Matrix = Eigen::Map<Eigen::MatrixXd>;
    std::vector<double> buffer;
    Vector yv{nullptr, 0}, harmonics{nullptr, 0}, lambda{nullptr, 0}, clamped{nullptr, 0};
    // At the point of the last residual(): per joint, g, ∂g/∂y, ∂g/∂ẏ at the samples (Nt × 3);
    // per friction joint, 1 where a sample sticks (Nt). jacobian() reads them.
    std::vector<Matrix> g;
    std::vector<Vector> stick;
    Matrix weights{nullptr, 0, 0}; // trig.cols() × 2: cos and sin sums of ∂g/∂y, ∂g/∂ẏ
    Matrix E{nullptr, 0, 0}, D{nullptr, 0, 0};
    Vector w{nullptr, 0};    // the weight's harmonics −2K … 2K, real parts then imaginary
    Eigen::MatrixXcd G;      // (K+1) × nj: the joint forces' harmonics at `last`
    Vector last{nullptr, 0}; // the unknowns of the last residual(), if `has_last`
    bool has_last = false;
    // The hysteretic forces: per joint, ∂g_n/∂y_m of its loop at the last residual(); the
    // loop's work arrays, its force at the samples and (jacobian()) the derivative times dy.
    std::vector<std::vector<joints::LoopEntry>> loop;
    joints::LoopWork loop_work;
    std::vector<double> loop_force;
    Eigen::MatrixXd loop_dy;
    // Per joint, ∂pack(G_j)/∂z_j of its smooth force at the last jacobian(), when keep_dG is
    // set (force_change() reads them).
    bool keep_dG = false;
    std::vector<Eigen::MatrixXd> dG;
    // jacobian_times()'s work arrays (samples of a direction: y, ẏ, the weighted sum; its force
    // change, packed), and precondition()'s matrices: per line of `harmonics`, the inverse of
    // that line's own coupling ((nj + friction) square, side by side).
    Vector product{nullptr, 0}, change{nullptr, 0}, lambda_change{nullptr, 0};
    Eigen::MatrixXcd line_inverse;

    Scratch() = default;
    Scratch(const Scratch&) : Scratch() {}
    Scratch& operator=(const Scratch&) { return *this; }
  };
  mutable Scratch work{};

  Scratch& scratch() const {
    Scratch& w = work;
    if (w.yv.size() == 2 * Nt) return w;
    const Eigen::Index n = Nt, M = m(), nf = static_cast<Eigen::Index>(friction.size());
    const Eigen::Index nw = 4 * K + 1, nt = trig.cols();
    const Eigen::Index dense = matrix_free() ? 0 : M; // E and D: not when matrix-free
    w.buffer.assign(static_cast<std::size_t>(2 * n + M + 2 * n + nj * 3 * n + nf * n + 2 * nt +
                                             2 * dense * dense + 2 * nw + size() + 3 * n + 2 * M),
                    0.0);
    double* at = w.buffer.data();
    auto take = [&at](Eigen::Index size) {
      double* p = at;
      at += size;
      return p;
    };
    new (&w.yv) Scratch::Vector(take(2 * n), 2 * n);
    new (&w.harmonics) Scratch::Vector(take(M), M);
    new (&w.lambda) Scratch::Vector(take(n), n);
    new (&w.clamped) Scratch::Vector(take(n), n);
    w.g.clear(), w.stick.clear();
    for (int j = 0; j < nj; ++j)
      w.g.emplace_back(take(3 * n), n, 3);
    for (Eigen::Index f = 0; f < nf; ++f)
      w.stick.emplace_back(take(n), n);
    new (&w.weights) Scratch::Matrix(take(2 * nt), nt, 2);
    new (&w.E) Scratch::Matrix(take(dense * dense), dense, dense);
    new (&w.D) Scratch::Matrix(take(dense * dense), dense, dense);
    new (&w.w) Scratch::Vector(take(2 * nw), 2 * nw);
    new (&w.last) Scratch::Vector(take(size()), size());
    new (&w.product) Scratch::Vector(take(3 * n), 3 * n);
    new (&w.change) Scratch::Vector(take(M), M);
    new (&w.lambda_change) Scratch::Vector(take(M), M);
    w.has_last = false;
    w.G.setZero(K + 1, nj);
    w.loop.assign(static_cast<std::size_t>(nj), {});
    w.loop_force.assign(static_cast<std::size_t>(n), 0.0);
    if (!matrix_free()) w.loop_dy.setZero(n, M);
    return w;
  }

  // D += forward · diag(w) · dy (rate = false) or forward · diag(w) · dv (rate = true): the
  // derivative of the harmonics of a signal w(t) y(t) or w(t) ẏ(t) with respect to the packed
  // harmonics of y, from the harmonics W_p = (1/Nt) Σ w(θ_n) e^{−ipθ_n} of the weights
  // (product-to-sum: a product of harmonics j and k has harmonics k ± j). O(Nt K + K²) instead
  // of O(Nt K²). `sums` = trigᵀ w, the column of the weight's cosine and sine sums.
  template <class Sums, class Out> void add_product(const Sums& sums, bool rate, Out& D) const {
    const auto& E = product_matrix(sums);
    if (rate)
      add_rate(E, 1.0, D);
    else
      D += E;
  }
  // E: the derivative for w(t) y(t) alone (the scratch's E), from the weight's sums. When
  // symmetric, the weight (∂g/∂y, ∂g/∂ẏ of an odd force, a stick mask) has even harmonics
  // only, and so k ± j is for odd k and j.
  template <class Sums> const Scratch::Matrix& product_matrix(const Sums& sums) const {
    Scratch& s = scratch();
    const Eigen::Index np = trig.cols() / 2; // the p tabulated
    const int step = symmetric() ? 2 : 1;
    const double* cs = sums.data();
    const double* sn = cs + np;
    const double scale = 1.0 / Nt;
    // W_p = Re + i Im for p = −2K … 2K (the multiples of step), tabulated (re[p + 2K], im[…]).
    double* re = s.w.data();
    double* im = re + (4 * K + 1);
    for (Eigen::Index q = 0; q < np; ++q) {
      const Eigen::Index p = step * q;
      re[2 * K + p] = re[2 * K - p] = scale * cs[q];
      im[2 * K + p] = -scale * sn[q], im[2 * K - p] = scale * sn[q];
    }
    auto Re = [&](int p) { return re[2 * K + p]; };
    auto Im = [&](int p) { return im[2 * K + p]; };
    // The columns of y's own harmonics: 0, cos jθ, −sin jθ.
    Scratch::Matrix& E = s.E;
    const int i0 = first(), n = count();
    if (i0 == 1) { // the mean's row and column
      E(0, 0) = Re(0);
      for (int b = 1; b < n; ++b) {
        const int j = harmonics[b];
        E(0, at(b)) = Re(j), E(0, at(b) + 1) = Im(j);
        E(at(b), 0) = 2.0 * Re(j), E(at(b) + 1, 0) = 2.0 * Im(j);
      }
    }
    for (int a = i0; a < n; ++a) {
      const int k = harmonics[a], r = at(a);
      for (int b = i0; b < n; ++b) {
        const int j = harmonics[b], c = at(b);
        E(r, c) = Re(k - j) + Re(k + j);
        E(r, c + 1) = Im(k + j) - Im(k - j);
        E(r + 1, c) = Im(k + j) + Im(k - j);
        E(r + 1, c + 1) = Re(k - j) - Re(k + j);
      }
    }
    return E;
  }
  // D += factor · (E for w(t) ẏ(t)): ẏ's columns from y's, d/dt cos jθ = jω (−sin jθ),
  // d/dt (−sin jθ) = −jω cos jθ; the mean has no rate.
  template <class Out> void add_rate(const Scratch::Matrix& E, double factor, Out&& D) const {
    for (int b = first(); b < count(); ++b) {
      const double f = factor * harmonics[b] * omega;
      const int c = at(b);
      D.col(c) += f * E.col(c + 1);
      D.col(c + 1) -= f * E.col(c);
    }
  }

  Eigen::MatrixXcd unpack(const Eigen::VectorXd& z, int blocks, int offset = 0) const {
    Eigen::MatrixXcd Y = Eigen::MatrixXcd::Zero(K + 1, blocks);
    for (int j = 0; j < blocks; ++j) {
      const int o = (offset + j) * m();
      if (!symmetric()) Y(0, j) = z(o);
      for (int i = first(); i < count(); ++i)
        Y(harmonics[i], j) = Complex(z(o + at(i)), z(o + at(i) + 1));
    }
    return Y;
  }
  void pack(const Eigen::MatrixXcd& Y, Eigen::VectorXd& z, int offset = 0) const {
    for (int j = 0; j < Y.cols(); ++j) {
      const int o = (offset + j) * m();
      if (!symmetric()) z(o) = Y(0, j).real();
      for (int i = first(); i < count(); ++i) {
        const Complex y = Y(harmonics[i], j);
        z(o + at(i)) = y.real(), z(o + at(i) + 1) = y.imag();
      }
    }
  }

  // The transforms between samples and harmonics: by the tables (O(Nt m) a transform), or from
  // fft_from unknowns a block by FFT of the whole period (O(Nt log Nt)): a symmetric problem's
  // kept samples are the first half, the second half the first negated (odd harmonics) or
  // repeated (a weight of even harmonics).
  bool by_fft() const { return m() >= fft_from; }
  // (Decided when the tables were chosen, HarmonicBalance's construction: they are left out.)
  bool matrix_free() const { return dy.size() == 0; }
  int period_samples() const { return symmetric() ? 2 * Nt : Nt; }
  static fem::RealFft& fft(int n) {
    thread_local std::map<int, std::unique_ptr<fem::RealFft>> plans;
    auto& plan = plans[n];
    if (!plan) plan = std::make_unique<fem::RealFft>(n);
    return *plan;
  }
  // Packed harmonics (m) of the signal sampled at the kept samples `x` (Nt): forward · x.
  void forward(const double* x, double* out) const {
    if (!by_fft()) {
      multiply_transposed(forward_t, x, out);
      return;
    }
    const int N = period_samples();
    Eigen::VectorXd full(N);
    const Eigen::Map<const Eigen::VectorXd> kept(x, Nt);
    full.head(Nt) = kept;
    if (symmetric()) full.tail(Nt) = -kept;
    const Eigen::VectorXcd S = fft(N).forward(full);
    if (!symmetric()) out[0] = S(0).real() / N;
    for (int i = first(); i < count(); ++i) {
      const Complex v = 2.0 * S(harmonics[i]) / static_cast<double>(N);
      out[at(i)] = v.real(), out[at(i) + 1] = v.imag();
    }
  }
  // trigᵀ w: the cosine and sine sums of the weight w at the kept samples (Nt), Σ w cos pθ_n
  // then Σ w sin pθ_n for the p tabulated (0, s, 2s, … 2 max(harmonics)).
  void trig_sums(const double* w, double* out) const {
    if (!by_fft()) {
      multiply_transposed(trig, w, out);
      return;
    }
    // Over the kept samples θ_n = 2πn / period_samples(): when symmetric, p = 2q and the sums
    // are bin q of the FFT of the Nt samples.
    const Eigen::Index np = trig.cols() / 2;
    const Eigen::VectorXcd S = fft(Nt).forward(Eigen::Map<const Eigen::VectorXd>(w, Nt));
    for (Eigen::Index q = 0; q < np; ++q) { // (past Nyquist, a real signal's bins fold back)
      const Eigen::Index b = q % Nt;
      const Complex Sq = b <= Nt / 2 ? S(b) : std::conj(S(Nt - b));
      out[q] = Sq.real(), out[np + q] = -Sq.imag();
    }
  }

  // y and ẏ at the samples (2 Nt: y, then ẏ) from the packed harmonics `x` of one block.
  void samples(const double* x, double* yv) const {
    if (!by_fft()) {
      multiply(dyv_unit, x, yv);
    } else {
      const int N = period_samples();
      Eigen::VectorXcd Y = Eigen::VectorXcd::Zero(N / 2 + 1), V = Y;
      if (!symmetric()) Y(0) = x[0];
      for (int i = first(); i < count(); ++i) {
        const int k = harmonics[i];
        const Complex h(x[at(i)], x[at(i) + 1]);
        Y(k) = 0.5 * h, V(k) = Complex(0.0, 0.5 * k) * h;
      }
      fem::RealFft& plan = fft(N);
      Eigen::Map<Eigen::VectorXd>(yv, Nt) = plan.inverse(Y).head(Nt);
      Eigen::Map<Eigen::VectorXd>(yv + Nt, Nt) = plan.inverse(V).head(Nt);
    }
    for (int n = Nt; n < 2 * Nt; ++n)
      yv[n] *= omega;
  }

  // Packed harmonics of joint j's smooth force (m) at z; its samples are kept for jacobian().
  void smooth_force(const Eigen::VectorXd& z, int j, double* harmonics_out) const {
    Scratch& s = scratch();
    Scratch::Matrix& g = s.g[static_cast<std::size_t>(j)];
    samples(z.data() + j * m(), s.yv.data());
    g.setZero();
    add_joint_forces(joints[j], s.yv.data(), s.yv.data() + Nt, Nt, width, g);
    const auto u = static_cast<std::size_t>(j);
    if (u < sliders.size() && !sliders[u].empty()) {
      // (A loop that does not close within the passes keeps its last pass: it differs from the
      // next one only by elements that slide once more, a case met with a drifting mean only.)
      joints::steady_loop(sliders[u], {s.yv.data(), static_cast<std::size_t>(Nt)}, symmetric(),
                          s.loop_force, &s.loop[u], s.loop_work);
      g.col(0) += Eigen::Map<const Eigen::VectorXd>(s.loop_force.data(), Nt);
    }
    forward(g.data(), harmonics_out);
  }

  // Harmonics of the joints' forces (K+1) × nj at z, into G: the smooth forces (their samples
  // kept for jacobian()) and the exact friction forces (unknowns).
  void force_harmonics(const Eigen::VectorXd& z, Eigen::MatrixXcd& G) const {
    Scratch& s = scratch();
    G.setZero(K + 1, nj);
    for (int j = 0; j < nj; ++j) {
      smooth_force(z, j, s.harmonics.data());
      if (!symmetric()) G(0, j) = s.harmonics(0);
      for (int i = first(); i < count(); ++i)
        G(harmonics[i], j) = Complex(s.harmonics(at(i)), s.harmonics(at(i) + 1));
    }
    for (std::size_t f = 0; f < friction.size(); ++f) {
      const int o = (nj + static_cast<int>(f)) * m(), j = friction[f].joint;
      if (!symmetric()) G(0, j) += z(o);
      for (int i = first(); i < count(); ++i)
        G(harmonics[i], j) += Complex(z(o + at(i)), z(o + at(i) + 1));
    }
  }
  // The same, returned; the last residual's own when z is its point (the result of a solve).
  Eigen::MatrixXcd forces(const Eigen::VectorXd& z) const {
    const Scratch& s = scratch();
    if (s.has_last && z.size() == s.last.size() && (z.array() == s.last.array()).all()) return s.G;
    Eigen::MatrixXcd G;
    force_harmonics(z, G);
    return G;
  }

  // Adds ∂pack(H_yy(kω) G_k)/∂(unknowns of joint b's force) = `d` (packed rows) to the rows of
  // joint a, columns `col`.
  template <class Block>
  void add_coupling(Eigen::MatrixXd& J, int a, int b, int col, const Block& d) const {
    const int o = a * m();
    if (!symmetric()) // the mean is real
      J.block(o, col, 1, m()) += Hyy[0](a, b).real() * d.row(0);
    for (int i = first(); i < count(); ++i) {
      const Complex h = Hyy[harmonics[i]](a, b);
      const auto re = d.row(at(i)), im = d.row(at(i) + 1);
      J.block(o + at(i), col, 1, m()) += h.real() * re - h.imag() * im;
      J.block(o + at(i) + 1, col, 1, m()) += h.imag() * re + h.real() * im;
    }
  }

  // The same for d = I (a friction joint's force unknowns enter its harmonics as they are).
  void add_coupling_identity(Eigen::MatrixXd& J, int a, int b, int col) const {
    const int r = a * m();
    if (!symmetric()) J(r, col) += Hyy[0](a, b).real();
    for (int i = first(); i < count(); ++i) {
      const Complex h = Hyy[harmonics[i]](a, b);
      const int p = at(i);
      J(r + p, col + p) += h.real(), J(r + p, col + p + 1) -= h.imag();
      J(r + p + 1, col + p) += h.imag(), J(r + p + 1, col + p + 1) += h.real();
    }
  }

  // r = [z_Y − pack(H_yf F) + pack(H_yy G(z)); c (Λ − AFT[proj(λ + r ẏ)])], sized by the caller
  // (size()), and, if asked, its (generalised) Jacobian there (as jacobian()).
  void residual(const Eigen::VectorXd& z, double load, Eigen::VectorXd& r,
                Eigen::MatrixXd* J) const {
    JOINTID_ASSERT(z.size() == size(), "the packed unknowns have the equations' size");
    Scratch& s = scratch();
    r = z;
    // Per joint a: its rows get Σ_b H_yy(kω)_ab G_b,k, with G_b the smooth force of joint b
    // plus its friction unknowns.
    Eigen::MatrixXcd& G = s.G;
    force_harmonics(z, G);
    s.last = z, s.has_last = true;
    for (int a = 0; a < nj; ++a) {
      const int o = a * m();
      for (int i = 0; i < count(); ++i) {
        const int k = harmonics[i];
        Complex v = -load * HyF_F(k, a);
        for (int b = 0; b < nj; ++b)
          v += Hyy[k](a, b) * G(k, b);
        if (k == 0) {
          r(o) += v.real();
        } else {
          r(o + at(i)) += v.real();
          r(o + at(i) + 1) += v.imag();
        }
      }
    }
    for (std::size_t f = 0; f < friction.size(); ++f) {
      const Friction& fr = friction[f];
      const int o = (nj + static_cast<int>(f)) * m(), oy = fr.joint * m();
      double rw = fr.r * omega; // r ẏ = r ω (ẏ / ω) from the tables; r ẏ by FFT
      if (by_fft()) {
        double* work = s.product.data(); // λ and its (unused) rate, then ẏ
        samples(z.data() + o, work);
        s.lambda = Eigen::Map<const Eigen::VectorXd>(work, Nt);
        samples(z.data() + oy, work);
        s.yv.tail(Nt) = Eigen::Map<const Eigen::VectorXd>(work + Nt, Nt);
        rw = fr.r;
      } else {
        multiply(dy, z.data() + o, s.lambda.data());
        multiply(dv_unit, z.data() + oy, s.yv.data() + Nt);
      }
      Scratch::Vector& stick = s.stick[f];
      for (int n = 0; n < Nt; ++n) {
        const double trial = s.lambda(n) + rw * s.yv(Nt + n);
        stick(n) = std::abs(trial) < fr.limit ? 1.0 : 0.0;
        s.clamped(n) = std::clamp(trial, -fr.limit, fr.limit);
      }
      forward(s.clamped.data(), s.harmonics.data());
      r.segment(o, m()) = fr.c * (z.segment(o, m()) - s.harmonics);
    }
    if (J) jacobian(*J);
  }

  // The (generalised) Jacobian of the residual at the point of the last residual() call, from
  // the samples it kept: Newton needs it only where it takes a step from.
  void jacobian(Eigen::MatrixXd& J) const {
    Scratch& s = scratch();
    if (matrix_free()) { // (the continuation's and the backbone's: column by column)
      J.resize(size(), size());
      Eigen::VectorXd unit = Eigen::VectorXd::Zero(size()), column;
      for (int c = 0; c < size(); ++c) {
        unit(c) = 1.0;
        jacobian_times(unit, column);
        J.col(c) = column;
        unit(c) = 0.0;
      }
      return;
    }
    J.setIdentity(size(), size());
    for (int b = 0; b < nj; ++b) {
      const Scratch::Matrix& g = s.g[static_cast<std::size_t>(b)];
      trig_sums(g.col(1).data(), s.weights.col(0).data());
      trig_sums(g.col(2).data(), s.weights.col(1).data());
      s.D.setZero();
      add_product(s.weights.col(0), false, s.D);
      add_product(s.weights.col(1), true, s.D);
      const auto u = static_cast<std::size_t>(b);
      if (u < sliders.size() && !sliders[u].empty()) {
        // The loop's ∂g_n/∂y_m (a few entries a sample), through y_m = dy_m · z, then forward.
        s.loop_dy.setZero();
        for (const joints::LoopEntry& e : s.loop[u])
          s.loop_dy.row(e.n) += e.value * dy.row(e.m);
        if (by_fft()) {
          Eigen::VectorXd column(m());
          for (Eigen::Index c = 0; c < s.loop_dy.cols(); ++c) {
            forward(s.loop_dy.col(c).data(), column.data());
            s.D.col(c) += column;
          }
        } else {
          s.D.noalias() += forward_t.transpose() * s.loop_dy;
        }
      }
      for (int a = 0; a < nj; ++a)
        add_coupling(J, a, b, b * m(), s.D);
      if (s.keep_dG) {
        s.dG.resize(static_cast<std::size_t>(nj));
        s.dG[u] = s.D;
      }
    }
    for (std::size_t f = 0; f < friction.size(); ++f) {
      const Friction& fr = friction[f];
      const int o = (nj + static_cast<int>(f)) * m(), oy = fr.joint * m();
      for (int a = 0; a < nj; ++a)
        add_coupling_identity(J, a, fr.joint, o);
      // c (I − P_stick) and −c r P'_stick, both from the one product matrix of the stick mask
      multiply_transposed(trig, s.stick[f].data(), s.weights.col(0).data());
      const Scratch::Matrix& E = product_matrix(s.weights.col(0));
      J.block(o, o, m(), m()) = -fr.c * E; // the identity is J's own
      J.block(o, o, m(), m()).diagonal().array() += fr.c;
      J.block(o, oy, m(), m()).setZero();
      add_rate(E, -fr.c * fr.r, J.block(o, oy, m(), m()));
    }
  }

  // The change of the joints' force harmonics ((K+1) × nj) for a change dz of the unknowns, to
  // first order at the point of the last jacobian() (made with scratch().keep_dG set): per
  // joint its smooth force's ∂pack(G)/∂z times its block of dz, plus the change of its friction
  // unknowns (which enter G as they are).
  Eigen::MatrixXcd force_change(const Eigen::VectorXd& dz) const {
    const Scratch& s = scratch();
    if (matrix_free()) { // from the samples of the last residual(), as jacobian_times()
      JOINTID_ASSERT(dz.size() == size(), "a change of every unknown");
      Eigen::VectorXd packed(nj * m());
      for (int j = 0; j < nj; ++j)
        smooth_force_change(j, dz.data() + j * m(), packed.data() + j * m());
      for (std::size_t f = 0; f < friction.size(); ++f)
        packed.segment(friction[f].joint * m(), m()) +=
            dz.segment((nj + static_cast<int>(f)) * m(), m());
      return unpack(packed, nj);
    }
    JOINTID_ASSERT(s.keep_dG && s.dG.size() == static_cast<std::size_t>(nj) && dz.size() == size(),
                   "force_change() follows a jacobian() that kept the force's derivative");
    Eigen::VectorXd packed = Eigen::VectorXd::Zero(nj * m());
    for (int j = 0; j < nj; ++j)
      packed.segment(j * m(), m()) = s.dG[static_cast<std::size_t>(j)] * dz.segment(j * m(), m());
    for (std::size_t f = 0; f < friction.size(); ++f)
      packed.segment(friction[f].joint * m(), m()) +=
          dz.segment((nj + static_cast<int>(f)) * m(), m());
    return unpack(packed, nj);
  }

  // The matrix-free Jacobian (matrix_free(); any size, for the tests). All at the point of the
  // last residual(), from the samples it kept; none of them changes those.
  //
  // Packed harmonics (m) of the change of joint b's smooth force for a change v (packed, m) of
  // its deformation's harmonics: the transform of ∂g/∂y δy + ∂g/∂ẏ δẏ at the samples, plus its
  // hysteretic loop's ∂g_n/∂y_m δy_m. O(Nt log Nt) by FFT.
  void smooth_force_change(int b, const double* v, double* out) const {
    Scratch& s = scratch();
    double* yv = s.product.data(); // δy, δẏ (2 Nt), then the force's change (Nt)
    double* w = yv + 2 * Nt;
    samples(v, yv);
    const Scratch::Matrix& g = s.g[static_cast<std::size_t>(b)];
    for (int n = 0; n < Nt; ++n)
      w[n] = g(n, 1) * yv[n] + g(n, 2) * yv[Nt + n];
    const auto u = static_cast<std::size_t>(b);
    if (u < sliders.size() && !sliders[u].empty())
      for (const joints::LoopEntry& e : s.loop[u])
        w[e.n] += e.value * yv[e.m];
    forward(w, out);
  }
  // out[rows of joint a] += pack(H_yy(kω)_ab D_k) for the packed harmonics d (m).
  void add_receptance_times(int a, int b, const double* d, double* out) const {
    double* o = out + a * m();
    if (!symmetric()) o[0] += Hyy[0](a, b).real() * d[0];
    for (int i = first(); i < count(); ++i) {
      const Complex v = Hyy[harmonics[i]](a, b) * Complex(d[at(i)], d[at(i) + 1]);
      o[at(i)] += v.real(), o[at(i) + 1] += v.imag();
    }
  }
  // out = J v, J the (generalised) Jacobian jacobian() would form.
  void jacobian_times(const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::VectorXd& out) const {
    JOINTID_ASSERT(v.size() == size(), "a direction of every unknown");
    Scratch& s = scratch();
    out = v;
    double* dG = s.change.data();
    for (int b = 0; b < nj; ++b) {
      smooth_force_change(b, v.data() + b * m(), dG);
      for (std::size_t f = 0; f < friction.size(); ++f)
        if (friction[f].joint == b) s.change += v.segment((nj + static_cast<int>(f)) * m(), m());
      for (int a = 0; a < nj; ++a)
        add_receptance_times(a, b, dG, out.data());
    }
    for (std::size_t f = 0; f < friction.size(); ++f) {
      // c (δΛ − transform of stick · (δλ + r δẏ))
      const Friction& fr = friction[f];
      const int o = (nj + static_cast<int>(f)) * m();
      double* work = s.product.data();
      samples(v.data() + fr.joint * m(), work);
      Eigen::Map<Eigen::VectorXd> rate(work + 2 * Nt, Nt);
      rate = Eigen::Map<const Eigen::VectorXd>(work + Nt, Nt) * fr.r; // (samples: ẏ itself)
      samples(v.data() + o, work);                                    // δλ (its rate unused)
      for (int n = 0; n < Nt; ++n)
        work[n] = s.stick[f](n) * (work[n] + rate(n));
      forward(work, s.lambda_change.data());
      out.segment(o, m()) = fr.c * (v.segment(o, m()) - s.lambda_change);
    }
  }
  // The preconditioner of jacobian_times(): each line's own coupling, with the joints' tangents
  // and the friction joints' stick fractions averaged over the period (the couplings between
  // lines that their variation makes are left out). Per line k (complex, δY then δΛ):
  //     δY_a + Σ_b H_ab (ḡ_y,b + ikω ḡ_ẏ,b) δY_b + Σ_f H_a,j(f) δΛ_f,
  //     c_f ((1 − s̄_f) δΛ_f − s̄_f r_f ikω δY_j(f)),
  // with ḡ_y a hysteretic loop's mean diagonal ∂g_n/∂y_n too. Exact for linear joints.
  void prepare_preconditioner() const {
    Scratch& s = scratch();
    const int nf = static_cast<int>(friction.size()), q = nj + nf;
    std::vector<double> gy(static_cast<std::size_t>(nj)), gv(gy.size()),
        stuck(static_cast<std::size_t>(nf));
    for (int b = 0; b < nj; ++b) {
      const auto u = static_cast<std::size_t>(b);
      const Scratch::Matrix& g = s.g[u];
      gy[u] = g.col(1).mean(), gv[u] = g.col(2).mean();
      if (u < sliders.size() && !sliders[u].empty())
        for (const joints::LoopEntry& e : s.loop[u])
          if (e.n == e.m) gy[u] += e.value / Nt;
    }
    for (int f = 0; f < nf; ++f)
      stuck[static_cast<std::size_t>(f)] = s.stick[static_cast<std::size_t>(f)].mean();
    s.line_inverse.resize(q, q * count());
    Eigen::MatrixXcd A(q, q);
    for (int i = 0; i < count(); ++i) {
      const int k = harmonics[i];
      const Complex ikw(0.0, k * omega);
      A.setIdentity();
      for (int a = 0; a < nj; ++a) {
        for (int b = 0; b < nj; ++b)
          A(a, b) += Hyy[k](a, b) *
                     (gy[static_cast<std::size_t>(b)] + ikw * gv[static_cast<std::size_t>(b)]);
        for (int f = 0; f < nf; ++f)
          A(a, nj + f) += Hyy[k](a, friction[static_cast<std::size_t>(f)].joint);
      }
      for (int f = 0; f < nf; ++f) {
        const Friction& fr = friction[static_cast<std::size_t>(f)];
        const double st = stuck[static_cast<std::size_t>(f)];
        A.row(nj + f).setZero();
        A(nj + f, nj + f) = fr.c * (1.0 - st);
        A(nj + f, fr.joint) -= fr.c * st * fr.r * ikw;
      }
      // A friction joint stuck throughout leaves its mean singular: a least-squares inverse.
      s.line_inverse.middleCols(i * q, q) = A.completeOrthogonalDecomposition().pseudoInverse();
    }
  }
  // out = (the preconditioner)⁻¹ v, line by line.
  void precondition(const Eigen::Ref<const Eigen::VectorXd>& v, Eigen::VectorXd& out) const {
    const Scratch& s = scratch();
    const int nf = static_cast<int>(friction.size()), q = nj + nf;
    out.resize(size());
    Eigen::VectorXcd x(q), y(q);
    for (int i = 0; i < count(); ++i) {
      const bool mean = harmonics[i] == 0;
      for (int u = 0; u < q; ++u) {
        const int o = u * m() + (mean ? 0 : at(i));
        x(u) = mean ? Complex(v(o)) : Complex(v(o), v(o + 1));
      }
      y.noalias() = s.line_inverse.middleCols(i * q, q) * x;
      for (int u = 0; u < q; ++u) {
        const int o = u * m() + (mean ? 0 : at(i));
        out(o) = y(u).real();
        if (!mean) out(o + 1) = y(u).imag();
      }
    }
  }

  // Coefficient `term` of joint j grown by `step` (a term without parameters and not dry
  // friction: its force is linear in its coefficient): the harmonics of the added force at z
  // ((K+1) × nj, joint j's column) and the residual's change, pack(H_yy ΔG) in every joint's
  // rows (0 in the friction rows), exactly — without the joint's other forces (an iwan's loop).
  void coefficient_change(const Eigen::VectorXd& z, int j, joints::Term term, double step,
                          Eigen::MatrixXcd& dG, Eigen::VectorXd& dr) const {
    std::vector<double> yv(static_cast<std::size_t>(2 * Nt));
    samples(z.data() + j * m(), yv.data());
    Eigen::MatrixXd g = Eigen::MatrixXd::Zero(Nt, 3);
    const auto n = static_cast<std::size_t>(Nt);
    joints::add_samples(term, step, {yv.data(), n}, {yv.data() + Nt, n}, {g.col(0).data(), n},
                        {g.col(1).data(), n}, {g.col(2).data(), n});
    Eigen::VectorXd packed(m());
    forward(g.col(0).data(), packed.data());
    dG = Eigen::MatrixXcd::Zero(K + 1, nj);
    dG.col(j) = unpack(packed, 1).col(0);
    dr = Eigen::VectorXd::Zero(size());
    for (int a = 0; a < nj; ++a) {
      const int o = a * m();
      for (int i = 0; i < count(); ++i) {
        const int k = harmonics[i];
        const Complex v = Hyy[k](a, j) * dG(k, j);
        if (k == 0) {
          dr(o) = v.real();
        } else {
          dr(o + at(i)) = v.real();
          dr(o + at(i) + 1) = v.imag();
        }
      }
    }
  }

  Eigen::VectorXd residual(const Eigen::VectorXd& z, double load, Eigen::MatrixXd* J) const {
    Eigen::VectorXd r(size());
    if (J) J->resize(size(), size());
    residual(z, load, r, J);
    return r;
  }

  // The smooth forces' part of the residual's joint rows at z, split by the terms' degree d
  // (g(s y, s ẏ) = s^d g(y, ẏ) for s > 0, joints::TermInfo::degree): column d of h (size() × 4)
  // is pack(H_yy G_d(z)),
  // so that without friction unknowns the residual at s z is
  //     r(s z) = s z − pack(H_yf F) + Σ_d s^d h_d      (d = 0 … 3, s > 0).
  // False (h unset) where a force is not of that form (friction unknowns, regularised friction,
  // a term of another degree) or there are no joints.
  bool homogeneous_parts(const Eigen::VectorXd& z, Eigen::MatrixXd& h) const {
    if (!friction.empty() || nj == 0) return false;
    for (const joints::Joint& j : joints)
      for (std::size_t t = 0; t < j.terms.size(); ++t) {
        const int d = joints::term_info(j.terms[t]).degree;
        if (d < 0 || d > 3 || (width > 0.0 && joints::is_dry_friction(j.terms[t]))) return false;
      }
    Scratch& s = scratch();
    h.setZero(nj * m(), 4);
    Scratch::Matrix& g = s.g[0];
    const auto size = static_cast<std::size_t>(Nt);
    const std::span<const double> ys(s.yv.data(), size), vs(s.yv.data() + Nt, size);
    const std::span<double> gs(g.col(0).data(), size), gys(g.col(1).data(), size),
        gvs(g.col(2).data(), size);
    for (int b = 0; b < nj; ++b) {
      samples(z.data() + b * m(), s.yv.data());
      for (int d = 0; d <= 3; ++d) {
        g.setZero();
        bool any = false;
        for (std::size_t t = 0; t < joints[b].terms.size(); ++t)
          if (joints::term_info(joints[b].terms[t]).degree == d && joints[b].values[t] != 0.0 &&
              !joints::is_dry_friction(joints[b].terms[t]))
            joints::add_samples(joints[b].terms[t], joints[b].values[t], ys, vs, gs, gys, gvs),
                any = true;
        if (!any) continue;
        forward(g.data(), s.harmonics.data());
        for (int a = 0; a < nj; ++a) // joint a's rows: Σ_b H_yy(kω)_ab G_b,k
          for (int i = 0; i < count(); ++i) {
            const int k = harmonics[i];
            if (k == 0) {
              h(a * m(), d) += Hyy[0](a, b).real() * s.harmonics(0);
              continue;
            }
            const Complex v = Hyy[k](a, b) * Complex(s.harmonics(at(i)), s.harmonics(at(i) + 1));
            h(a * m() + at(i), d) += v.real(), h(a * m() + at(i) + 1, d) += v.imag();
          }
      }
    }
    return true;
  }

  // |z| with the force unknowns in metres (through each friction joint's compliance).
  double norm(const Eigen::VectorXd& z) const {
    double s = z.head(nj * m()).squaredNorm();
    for (std::size_t f = 0; f < friction.size(); ++f)
      s += std::pow(friction[f].c, 2) *
           z.segment((nj + static_cast<int>(f)) * m(), m()).squaredNorm();
    return std::sqrt(s);
  }
};

/// LU factorisation with partial pivoting of a small dense matrix, in place and without
/// allocating once sized. At the 10–60 unknowns of a harmonic-balance point Eigen's
/// PartialPivLU spends most of its time in blocking and dispatch (6 500 instructions for an
/// 11 × 11 matrix, 45 000 for 30 × 30, against n³/3 multiply-adds); this is the textbook
/// right-looking elimination, column-major, the trailing update a column at a time. Above
/// `blocked_from` unknowns (a periodic test's hundreds of lines) that elimination streams the
/// whole trailing matrix through memory at every column, and Eigen's blocked PartialPivLU
/// (matrix-matrix kernels) takes over, with the same pivoting and the same least pivot.
template <class Scalar> struct SmallLU {
  using Matrix = Eigen::Matrix<Scalar, Eigen::Dynamic, Eigen::Dynamic>;
  using Vector = Eigen::Matrix<Scalar, Eigen::Dynamic, 1>;
  static constexpr Eigen::Index blocked_from = 160;
  Matrix lu;
  std::vector<int> pivots; // row k was swapped with row pivots[k]
  double min_pivot = 0.0;  // least |U_kk|: 0 (or rounding level) where the matrix is singular
  Eigen::PartialPivLU<Matrix> blocked; // used when n >= blocked_from
  bool is_blocked = false;

  template <class Source> void compute(const Source& A) {
    is_blocked = A.rows() >= blocked_from;
    if (is_blocked) {
      blocked.compute(A);
      min_pivot = blocked.matrixLU().diagonal().cwiseAbs().minCoeff();
      return;
    }
    lu = A;
    const Eigen::Index n = lu.rows();
    pivots.resize(static_cast<std::size_t>(n));
    min_pivot = n > 0 ? std::numeric_limits<double>::infinity() : 0.0;
    Scalar* a = lu.data();
    for (Eigen::Index k = 0; k < n; ++k) {
      Scalar* ck = a + k * n; // column k
      Eigen::Index p = k;
      for (Eigen::Index i = k + 1; i < n; ++i)
        if (std::abs(ck[i]) > std::abs(ck[p])) p = i;
      pivots[static_cast<std::size_t>(k)] = static_cast<int>(p);
      if (p != k)
        for (Eigen::Index j = 0; j < n; ++j)
          std::swap(a[j * n + k], a[j * n + p]);
      const Scalar pivot = ck[k];
      min_pivot = std::min(min_pivot, static_cast<double>(std::abs(pivot)));
      if (pivot == Scalar(0)) continue; // singular: the column below is already zero
      const Scalar inverse = Scalar(1) / pivot;
      for (Eigen::Index i = k + 1; i < n; ++i)
        ck[i] *= inverse;
      for (Eigen::Index j = k + 1; j < n; ++j) {
        Scalar* cj = a + j * n;
        const Scalar ukj = cj[k];
        if (ukj == Scalar(0)) continue;
        for (Eigen::Index i = k + 1; i < n; ++i)
          cj[i] -= ck[i] * ukj;
      }
    }
  }

  /// b ← A⁻¹ b; only meaningful where min_pivot > 0.
  template <class Rhs> void solve_in_place(Rhs& b) const {
    if (is_blocked) {
      b = blocked.solve(b).eval();
      return;
    }
    const Eigen::Index n = lu.rows();
    const Scalar* a = lu.data();
    for (Eigen::Index k = 0; k < n; ++k) // P b: the swaps in order (L's rows were swapped too)
      std::swap(b(k), b(pivots[static_cast<std::size_t>(k)]));
    for (Eigen::Index k = 0; k < n; ++k) { // L y = P b (unit lower triangle), by columns
      const Scalar bk = b(k);
      if (bk == Scalar(0)) continue;
      for (Eigen::Index i = k + 1; i < n; ++i)
        b(i) -= a[k * n + i] * bk;
    }
    for (Eigen::Index k = n - 1; k >= 0; --k) { // U x = y
      b(k) /= a[k * n + k];
      const Scalar bk = b(k);
      for (Eigen::Index i = 0; i < k; ++i)
        b(i) -= a[k * n + i] * bk;
    }
  }
};

/// Newton's method (least-norm steps where J is singular, backtracking) on R(z) = 0 at the
/// given load factor; true when |R| / |z| < options.tolerance. Counts into `iterations`.
bool newton(const Equations& equations, Eigen::VectorXd& z, double load,
            const HarmonicBalanceOptions& options, int& iterations, double& residual);

} // namespace jointid::frf::detail

#pragma once
/// The forces of the parametric terms (joints/basis.hpp): sliders (jenkins, iwan) and the
/// clearance (gap). y is the joint's deformation (m, or rad for a rotational joint), forces in
/// N (N m), stiffnesses in N/m (N m/rad).
///
/// Sliders. A Jenkins element is a spring k in series with a Coulomb slider of slip force f.
/// With x the slider's position its force is k (y − x): while |y − x| ≤ φ = f / k the slider
/// sticks (x stays), beyond it slides with the deformation, x = y ∓ φ, and the force is ±f.
/// The element is rate-independent: its state after a deformation that is monotonic between
/// two instants (linear over a time step, or between two AFT samples) is the *return map*
/// x ← clamp(x, y − φ, y + φ) at the second one — exact, no regularisation, no time step.
/// Elements in parallel share y: one is the jenkins term, N of them the discrete iwan.
///
/// Iwan (D. J. Segalman, J. Appl. Mech. 72 (2005) 752–760). A continuum of Jenkins elements
/// of unit stiffness whose slip displacements φ are distributed with the density
///     ρ(φ) = R φ^χ  on 0 < φ < φ_max,   plus  S δ(φ − φ_max),
/// so that the force is F(t) = ∫ ρ(φ) (y − x(t, φ)) dφ. The four parameters fix R, S, φ_max:
/// the stiffness before any slip K_T = ∫ρ = R φ_max^{χ+1}/(χ+1) + S (kt), the macroslip force
/// F_S = ∫φρ = R φ_max^{χ+2}/(χ+2) + S φ_max (fs), the exponent χ (chi, −1 < χ ≤ 0) and
/// β = S / (R φ_max^{χ+1}/(χ+1)) (beta ≥ 0), whence
///     φ_max = F_S (1 + β) / (K_T (β + (χ+1)/(χ+2))),
///     R = F_S (χ+1) / (φ_max^{χ+2} (β + (χ+1)/(χ+2))),   S = β F_S / (φ_max (β + (χ+1)/(χ+2))).
/// Under a deformation cycle ±a with a < φ_max (microslip) it dissipates
///     D(a) = ∫₀^a ρ(φ) 4φ (a − φ) dφ = 4 R a^{χ+3} / ((χ+2)(χ+3))     per cycle,
/// a power χ + 3 of the amplitude. Quadrature: (0, φ_max] is cut at φ_i = φ_max r^{i−M}
/// (i = 1 … M, a geometric grid whose smallest cut is φ_max·1e-4: the power law is followed
/// over four decades of amplitude), and each interval (φ_{i−1}, φ_i] becomes one element that
/// carries its share of the density exactly: stiffness w_i = ∫ρ over it and slip displacement
/// its centroid ∫φρ / w_i. K_T and F_S are then exact, the loops exact in macroslip, and the
/// dissipation in microslip within the quadrature error: an interval wholly below a gives
/// −4 w_i var_i(φ) (the variance of φ over it, ≤ w_i Δφ_i² in size), the one holding a at most
/// 4 w_i φ_i Δφ_i; relative to D both are of order (r − 1)². The Dirac is one more
/// element (stiffness S, slip displacement φ_max) when β > 0. M + 1 = `sliders` (default 100).
#include <span>
#include <vector>

namespace jointid::joints {

/// Jenkins elements in parallel.
struct Sliders {
  std::vector<double> stiffness; ///< k_i, N/m
  std::vector<double> reach;     ///< φ_i = f_i / k_i: the stretch at which element i slips, m

  int size() const { return static_cast<int>(stiffness.size()); }
  bool empty() const { return stiffness.empty(); }
  /// Σ k_i: the stiffness before any slip.
  double stiffness_sum() const;
  /// Σ k_i φ_i: the force when every element slides.
  double slip_force_sum() const;
  /// Appends the elements of `other` (terms of one joint act in parallel).
  void append(const Sliders& other);
};

/// Segalman's density for the four parameters (see above).
struct IwanDensity {
  double R = 0.0;       ///< N/m^{χ+2}
  double S = 0.0;       ///< N/m: the Dirac's weight (a stiffness)
  double phi_max = 0.0; ///< m: the largest slip displacement
  double chi = 0.0;
};
/// Throws std::invalid_argument for parameters out of range (fs, kt > 0; −1 < chi ≤ 0; beta ≥ 0).
IwanDensity iwan_density(double fs, double kt, double chi, double beta);

inline constexpr int default_iwan_sliders = 100;

/// One Jenkins element: stiffness kt, slip force fs (both > 0).
Sliders jenkins_sliders(double kt, double fs);
/// The iwan's quadrature with `sliders` elements (at least 2; one of them the Dirac's when
/// beta > 0).
Sliders iwan_sliders(double fs, double kt, double chi, double beta,
                     int sliders = default_iwan_sliders);

/// Segalman's closed-form dissipation per cycle of the continuous iwan under a deformation
/// cycle of amplitude a ≤ φ_max (microslip), J.
double iwan_dissipation(const IwanDensity& density, double amplitude);

/// The return map: moves the positions x to the state at y (from the state at the last
/// instant) and returns the force Σ k_i (y − x_i); `tangent`, if given, receives Σ k_i over
/// the elements that stick there (∂F/∂y for a further small step).
double slide(const Sliders& sliders, std::span<double> x, double y, double* tangent = nullptr);
/// The same without moving x (a trial state, e.g. a Newton iterate within a time step).
double slide_trial(const Sliders& sliders, std::span<const double> x, double y,
                   double* tangent = nullptr);

/// ∂g_n/∂y_m of a steady loop (summed over entries with the same n and m).
struct LoopEntry {
  int n, m;
  double value;
};

/// Work arrays of steady_loop(), kept by the caller to reuse their memory.
struct LoopWork {
  /// A run of elements (in order of φ) that share their state: at rest since the start
  /// (virgin, x = 0), or last dragged to the extreme e at sample `anchor` in direction s,
  /// x_i = e − s φ_i.
  struct Group {
    int lo = 0, hi = 0; ///< elements [lo, hi) in order of φ
    bool virgin = true;
    int anchor = -1;
    double e = 0.0, s = 0.0;
  };
  std::vector<double> k, phi, K, P; ///< in order of φ; K, P: prefix sums of k and k φ
  /// The sliders k, phi, K and P were made from (a loop of the same sliders reuses them: a
  /// harmonic balance's every residual).
  std::vector<double> from_stiffness, from_reach;
  std::vector<Group> groups; ///< largest φ first
  std::vector<double> x, x_start;
};

/// The sliders' steady hysteresis loop under the periodic deformation sampled at y over one
/// period (or, `antisymmetric`, over its first half, with y(t + T/2) = −y(t)): the elements
/// start at rest at zero deformation (x = 0, the state of a joint assembled unloaded) and run
/// over the period until their state at its end repeats — two passes when the first one sees
/// every element slip (or none), at most `max_passes` after a first that only moves the
/// elements (one in all when max_passes is 1). Writes the force of the last pass at the
/// samples to g (y's size) and, if `derivative` is given, the exact ∂g_n/∂y_m of that pass:
/// an element stuck at sample n contributes k_i at (n, n) and, if it slid before, −k_i at the
/// sample m where it last slid (its position there was y_m ∓ φ_i; for the antisymmetric form
/// a sample of the second half is −y of the first: the sign turns). An element sliding at n
/// contributes nothing (its force is ±f_i). False if the loop did not close.
/// Cost: per sample, the runs of elements that share a state (the memory of the deformation's
/// extremes, a few for a smooth loop) rather than every element: with elements ordered by φ,
/// those that slide at a sample are the ones of smallest φ (|x_φ − x_ψ| ≤ |φ − ψ| for elements
/// started alike), so each sample drags a prefix of them to a new extreme.
bool steady_loop(const Sliders& sliders, std::span<const double> y, bool antisymmetric,
                 std::span<double> g, std::vector<LoopEntry>* derivative, LoopWork& work,
                 int max_passes = 8);

/// The clearance: 0 for |y| ≤ δ, kg (y − δ) beyond +δ and kg (y + δ) beyond −δ; `slope` gets
/// kg outside and 0 inside (the one-sided derivative at |y| = δ taken as 0).
double gap_force(double delta, double kg, double y, double* slope = nullptr);

} // namespace jointid::joints

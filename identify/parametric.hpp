#pragma once
/// The parametric terms' parameters (jenkins, iwan, gap: joints/basis.hpp) enter the joint's
/// force non-linearly, so the equation-error route Q b = p cannot estimate them. They are
/// identified by output error (identify/output_error.hpp), started here from a
/// describing-function fit:
///  1. each test alone, the joint with the parametric term replaced by a linear spring and
///     damper (k, c, its fixed terms kept) is fitted by equation error: its equivalent dynamic
///     stiffness Z = k_eq + iω c_eq at the amplitude a of its deformation's fundamental;
///  2. the term's describing function N(a) = G₁(a)/a (the first harmonic of its force under
///     y = a cos ωt: its steady loop for a slider) plus the joint's non-fixed k and iω c is
///     fitted to those Z(a) by Levenberg–Marquardt in the parameters' natural coordinates
///     (logarithms of the positive ones), from a few starts read off the data (the stiffness
///     lost between the smallest and largest amplitude, the dissipation's size).
/// Amplitude-independent information only enters through Z(a): the start is as good as the
/// amplitudes the tests span.
#include "fem/status.hpp"
#include "frf/substructure.hpp"
#include "identify/fit.hpp"
#include "identify/measurement.hpp"

#include <complex>
#include <span>
#include <string>
#include <vector>

namespace jointid::identify {

/// N(a) of term t of the joint (its parameters checked): G₁/a under y = a cos θ, the steady
/// loop's first harmonic, in closed form (each slider of a jenkins or an iwan stuck, k, or
/// slipping, (k/π)(β − ½ sin 2β + i sin²β) with cos β = 1 − 2φ/a; the gap's kg (1 − (2/π)(asin r
/// + r √(1 − r²))), r = δ/a) — the continuous loop, which joints::steady_loop samples.
std::complex<double> describing_function(const joints::Joint& joint, std::size_t term,
                                         double amplitude);
/// The same at every amplitude of `amplitudes` (m, > 0), the term's sliders built once. With
/// `per_efold` > 0 and more amplitudes than that grid needs, N is computed on a grid evenly
/// spaced in ln a (`per_efold` points per factor e, spanning the amplitudes, with the onsets of
/// the term's kinks added: where a slider of 5 % of its stiffness or more starts to slip, where
/// the gap closes) and interpolated linearly in ln a. Between kinks N is smooth in ln a and the
/// error falls as the square of the spacing h; just past a slider's onset its in-phase part
/// falls as x^{3/2} (x = ln a/φ), which costs 0.25 k h^{3/2}, and a smaller slider's kink a
/// quarter of h times its slope's jump: about 2e-3 of the stiffness at 24 points per e-fold.
/// For a fit's start, not for a result.
std::vector<std::complex<double>> describing_functions(const joints::Joint& joint, std::size_t term,
                                                       std::span<const double> amplitudes,
                                                       int per_efold = 0);

/// The sine that stands for joint j's deformation in a test: a sine test's fundamental (|Y₁|
/// in m, ω = 2π f); a periodic test's lines (Measurement::lines) as one sine of the same RMS,
/// amplitude sqrt(Σ|Y_l|²), at the frequency of the same RMS rate, ω = sqrt(Σ ω_l² |Y_l|² /
/// Σ |Y_l|²) — the amplitude and frequency a describing function of the joint is evaluated at
/// for a broadband test (an approximation: a multisine's peaks exceed its RMS sine's). NaN
/// amplitude when a DOF of the joint is not measured.
struct EquivalentSine {
  double amplitude = 0.0, omega = 0.0;
};
EquivalentSine joint_equivalent_sine(const Measurement& m, const joints::Joint& joint);
/// Its amplitude (m).
double joint_amplitude(const Measurement& m, const joints::Joint& joint);

/// Coordinates the fits move a parameter in: u = log p for a positive parameter (> 0 or >= 0
/// unbounded above), chi = −1/(1 + e^{−u}) for an exponent in (−1, 0]; else p itself.
double parameter_to_u(const joints::ParameterInfo& info, double p);
double parameter_from_u(const joints::ParameterInfo& info, double u);
/// Whether a 95 % interval [lo, hi] of a parameter is a result: finite, of non-zero width, and
/// narrow enough to fix the parameter's scale — within a factor of 100 (hi / lo ≤ 100) for a
/// positive parameter, within half its range for an exponent in (−1, 0], within its value's
/// size either side for any other. Wider, the tests do not determine it (an interval such as
/// kt ∈ [1e-10, 2.5e27] N/m says nothing about kt).
bool interval_determines(const joints::ParameterInfo& info, double value, double lo, double hi);

/// One test's equivalent dynamic stiffness of a joint: Z = k_eq + iω c_eq of the linear spring
/// and damper that reproduce its force's fundamental at the amplitude of its deformation's (m),
/// ω in rad/s. π a² Im Z is the joint's dissipation per cycle there (J).
struct EquivalentStiffness {
  double amplitude = 0.0, omega = 0.0;
  std::complex<double> Z;
};

/// The describing-function fit alone (step 2, as describing_function_start() does it): term
/// `term` of `joint` (its fixed parameters held) fitted to the points, with the joint's own k and
/// c (`k_open`, `c_open`) taken by least squares. Returns the joint with the term's parameters
/// set (given, not fixed); `note` gets the line describing_function_start() adds. Throws
/// std::invalid_argument naming the joint when there are no points, no start fits, or the fit
/// leaves a parameter's range (the tests may not reach the term's regime).
joints::Joint fit_describing_function(const joints::Joint& joint, std::size_t term,
                                      std::vector<EquivalentStiffness> points, bool k_open,
                                      bool c_open, std::string& note);

/// The same for several parametric terms of the joint at once (`terms`, indices into its terms),
/// their describing functions summed: a friction and a clearance whose stiffness first falls and
/// then rises with the amplitude. Every combination of each term's starts is tried; a gap beside
/// another term starts closing where the points' stiffness is least, its stop at twice the
/// stiffness regained from there. The parameters of all of them are set.
joints::Joint fit_describing_functions(const joints::Joint& joint,
                                       const std::vector<std::size_t>& terms,
                                       std::vector<EquivalentStiffness> points, bool k_open,
                                       bool c_open, std::string& note);

/// Output error identifies one parametric term a joint at a time: throws std::invalid_argument
/// naming the joint and its terms when a joint has two or more whose parameters are not all
/// fixed.
void check_one_parametric_term(const std::vector<joints::Joint>& joints);

/// The describing-function start of the parametric terms (its numerical outcome a status).
struct DescribingFunctionStart {
  /// ok, or why a joint's fit found no start (the reason names the joint and the term; the
  /// per-test fits' own status passed up within it). `joints` are then as given.
  fem::Status status;
  /// The joints with every non-fixed parameter of a parametric term set (given, not fixed) to
  /// its describing-function estimate.
  std::vector<joints::Joint> joints;
  /// One line per term: the amplitudes used, the relative misfit, the values.
  std::vector<std::string> notes;
};

/// The start of every non-fixed parametric term (at most one a joint: check_one_parametric_term).
/// Throws std::invalid_argument naming the joint when no test measures its deformation (bad
/// input: the joint's DOFs need a response channel).
DescribingFunctionStart describing_function_start(const frf::Substructure& substructure,
                                                  const std::vector<joints::Joint>& joints,
                                                  const std::vector<Measurement>& tests,
                                                  const FitOptions& fit_options);

/// The joints with every parametric term marked fixed (its parameters as they are): the
/// equation-error fit then identifies the coefficient terms with these forces known.
std::vector<joints::Joint> with_parametric_fixed(std::vector<joints::Joint> joints);

} // namespace jointid::identify

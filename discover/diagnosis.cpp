#include "discover/diagnosis.hpp"

#include "discover/selection.hpp"
#include "discover/text.hpp"
#include "fem/constants.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <stdexcept>
#include <tuple>
#include <utility>

namespace jointid::discover::detail {

namespace {

using Complex = std::complex<double>;

// The largest unexplained second harmonic: its share of the fundamental and of the noise, where
// and in which tests it appears (5 × beyond the noise).
struct EvenHarmonics {
  double content = 0.0, noise = 0.0;
  std::string where, test;
  std::set<int> tests;
};

// Which channel disagrees most (into the diagnosis), and the second harmonic the model misses.
EvenHarmonics disagreement(Diagnosis& d, const Compared& compared,
                           const std::vector<identify::Measurement>& tests, const State& s) {
  std::map<std::string, std::pair<double, double>> per_channel; // error², measured²
  EvenHarmonics even;
  for (const auto& e : compared.entries) {
    const auto& m = tests[e.test];
    const std::string ch = channel_name(m, e.response);
    const Complex err = e.measured - s.X[e.test](e.row, e.response);
    per_channel[ch].first += std::norm(err);
    per_channel[ch].second += std::norm(e.measured);
    // The second harmonic (a mean displacement can also come from a sensor's offset or a
    // friction joint's memory of where it stuck). A periodic test's lines are not harmonics of
    // one fundamental: they say nothing of even harmonics.
    if (e.harmonic == 2 && !e.line) {
      const double x1 = std::abs(m.X(1, e.response));
      const double ratio = std::abs(err) / std::max(x1, 1e-300);
      const double noise = e.variance > 0.0 ? std::sqrt(e.variance) / std::max(x1, 1e-300) : 0.0;
      if (ratio - 3.0 * noise > even.content - 3.0 * even.noise)
        even.content = ratio, even.noise = noise, even.where = ch, even.test = m.source;
      if (ratio > 5.0 * noise && (noise > 0.0 || ratio > 1e-3)) even.tests.insert(e.test);
    }
  }
  for (const auto& [ch, v] : per_channel) {
    const double rel = std::sqrt(v.first / std::max(v.second, 1e-300));
    if (rel > d.channel_error) d.channel_error = rel, d.channel = ch;
  }
  return even;
}

// The best candidate of a family by the criterion (the rule that adds terms), and its share.
struct Best {
  double share = 0.0;
  const Candidate* who = nullptr;
};
template <class Keep> Best best_of(const std::vector<Candidate>& ranking, Keep&& keep) {
  const Candidate* who = nullptr;
  for (const auto& c : ranking)
    if (std::isfinite(c.criterion) && keep(c) && (!who || c.criterion < who->criterion)) who = &c;
  return {who ? std::max(who->explained, 0.0) : 0.0, who};
}

bool nonlinear_of_nature(const Candidate& c, joints::Nature nature) {
  return c.term && !c.linear() && joints::term_info(*c.term).nature == nature;
}

struct Families {
  Best linear, nonlinear, conservative, dissipative;
};

Families families(const std::vector<Candidate>& ranking) {
  return {best_of(ranking, [](const Candidate& c) { return c.linear(); }),
          best_of(ranking, [](const Candidate& c) { return !c.linear(); }),
          best_of(ranking,
                  [](const Candidate& c) {
                    return nonlinear_of_nature(c, joints::Nature::conservative);
                  }),
          best_of(ranking, [](const Candidate& c) {
            return nonlinear_of_nature(c, joints::Nature::dissipative);
          })};
}

// Linear or not: can a linear correction do as well as a non-linear term? Returns whether a
// non-linear term does better. From tests at one force level that is not a change with the
// level, which they cannot show: it is said so, and level_dependent stays empty.
bool level_finding(Diagnosis& d, const Families& f, int values, bool several_levels) {
  const Best &lin = f.linear, &non = f.nonlinear;
  const bool nonlinear = changes_with_level(lin.who ? lin.who->criterion : inf,
                                            non.who ? non.who->criterion : inf, values);
  if (!several_levels) {
    d.findings.push_back(fmt::format(
        "The tests are all at one force level: they cannot tell whether the disagreement "
        "changes with the level. {}",
        nonlinear
            ? fmt::format("A non-linear term ({}) explains {} of it, the best linear correction{} "
                          "{}.",
                          non.who->name(), pct(non.share),
                          lin.who ? " (" + lin.who->name() + ")" : std::string(),
                          pct(std::max(lin.share, 0.0)))
            : fmt::format("The best linear correction ({}) explains {} of it{}; no non-linear "
                          "term does better.",
                          lin.who ? lin.who->name() : std::string("none"),
                          pct(std::max(lin.share, 0.0)),
                          non.who ? fmt::format(", the best non-linear term ({}) {}",
                                                non.who->name(), pct(non.share))
                                  : std::string())));
    return nonlinear;
  }
  d.level_dependent = nonlinear;
  if (*d.level_dependent) {
    d.findings.push_back(fmt::format(
        "The disagreement changes with force level (non-linear): the best linear correction{} "
        "explains {} of it, the best non-linear term ({}) {}.",
        lin.who ? " (" + lin.who->name() + ")" : std::string(), pct(std::max(lin.share, 0.0)),
        non.who->name(), pct(non.share)));
  } else {
    d.findings.push_back(fmt::format(
        "The disagreement does not change with force level: a linear model error. The best "
        "linear correction ({}) explains {} of it{}; no non-linear term does better.",
        lin.who ? lin.who->name() : std::string("none"), pct(std::max(lin.share, 0.0)),
        non.who ? fmt::format(", the best non-linear term ({}) {}", non.who->name(), pct(non.share))
                : std::string()));
  }
  return nonlinear;
}

// Where: the joint of the best candidate of the family that explains it, against the others.
void where_finding(Diagnosis& d, const std::vector<Candidate>& ranking, const Families& f,
                   bool nonlinear) {
  std::map<std::string, double> by_joint;
  for (const auto& c : ranking)
    if (std::isfinite(c.gap) && (!c.refit))
      by_joint[c.joint] = std::max(by_joint[c.joint], c.explained);
  const Candidate* where = nonlinear ? f.nonlinear.who : f.linear.who;
  if (!where) return;
  d.joint = where->joint;
  std::string others;
  for (const auto& [name, share] : by_joint)
    if (name != d.joint)
      others += fmt::format("{}{} at most {}", others.empty() ? "" : ", ",
                            name == "substructure" ? std::string("the substructure")
                                                   : "terms at '" + name + "'",
                            pct(std::max(share, 0.0)));
  const bool substructure = d.joint == "substructure";
  d.findings.push_back(fmt::format(
      "It sits at {}: {} explain{} {}{}.",
      substructure ? std::string("the substructure") : "joint '" + d.joint + "'",
      substructure ? std::string("its damping") : "terms at '" + d.joint + "'",
      substructure ? "s" : "", pct(by_joint[d.joint]), others.empty() ? "" : "; " + others));
}

// "(c2 at 'tip') 12.3 %", or "none".
std::string named_share(const Best& b) {
  return b.who ? fmt::format("({}) {}", b.who->name(), pct(b.share)) : std::string("none");
}

// Conservative or dissipative: which non-linear family explains more. What it does with the
// level only where the tests have several levels.
void nature_finding(Diagnosis& d, const Families& f, bool several_levels) {
  const Best &cons = f.conservative, &diss = f.dissipative;
  // A slider term (jenkins, iwan) explains it best: its loop both softens and dissipates.
  if (const Candidate* best = f.nonlinear.who;
      best && best->term && joints::is_hysteretic(*best->term)) {
    d.nature = "hysteretic";
    d.findings.push_back(fmt::format(
        "Hysteretic: a slider term ({}) explains {}, the best stiffness term {}, the best damping "
        "term {}: the joint softens and dissipates at once.",
        best->name(), pct(f.nonlinear.share), named_share(cons), named_share(diss)));
    return;
  }
  d.nature = cons.share > diss.share ? "conservative" : "dissipative";
  if (d.nature == "conservative") {
    std::string how;
    if (cons.who && cons.who->term == joints::Term::k3)
      how = cons.who->value > 0.0
                ? several_levels ? " (hardening: the resonance rises with level)" : " (hardening)"
            : several_levels ? " (softening: the resonance falls with level)"
                             : " (softening)";
    d.findings.push_back(
        fmt::format("Conservative: a stiffness term ({}) explains {}, the best damping term {}{}.",
                    cons.who->name(), pct(cons.share), named_share(diss), how));
  } else {
    d.findings.push_back(
        fmt::format("Dissipative: a damping term ({}) explains {}, the best stiffness term {}{}.",
                    diss.who->name(), pct(diss.share), named_share(cons),
                    several_levels ? "; the damping changes with level" : ""));
  }
}

// An asymmetric joint force (k2) makes even harmonics in every test that moves it; a symmetric
// system's response can also lose its symmetry in a few tests (a bifurcation).
void even_finding(Diagnosis& d, const EvenHarmonics& even, const std::vector<Candidate>& ranking,
                  std::size_t tests, bool noise_known) {
  double k2_share = 0.0;
  for (const auto& c : ranking)
    if (c.term == joints::Term::k2 && std::isfinite(c.explained))
      k2_share = std::max(k2_share, c.explained);
  const std::string seen = fmt::format(
      "Even harmonics: the measured response at {} holds a second harmonic of {} of its "
      "fundamental in {}{} that the model does not produce{}",
      even.where, pct(even.content), even.test,
      even.tests.size() > 1 ? fmt::format(" (and {} other tests)", even.tests.size() - 1)
                            : std::string(),
      noise_known ? fmt::format(" (noise {})", pct(even.noise)) : std::string());
  d.asymmetric = k2_share >= 0.5 || even.tests.size() * 2 > tests;
  if (d.asymmetric)
    d.findings.push_back(seen + fmt::format(": an asymmetric force (k2 explains {}).",
                                            pct(std::max(k2_share, 0.0))));
  else
    d.findings.push_back(
        seen + fmt::format(": confined to {} of {} tests, it is not what an asymmetric joint "
                           "force would give (k2 explains {}); a symmetric system's response "
                           "can lose its symmetry at some frequencies and levels.",
                           even.tests.size(), tests, pct(std::max(k2_share, 0.0))));
}

} // namespace

std::string unjudged(const std::vector<Candidate>& ranking, const State& s,
                     const std::vector<identify::Measurement>& tests) {
  std::vector<std::string> names;
  for (const auto& c : ranking)
    if (!c.converged && !c.varies) names.push_back(c.name());
  std::string why;
  if (!names.empty())
    why = fmt::format("the re-simulations of {} did not converge for every test", join(names));
  if (!s.failed.empty())
    why += fmt::format("{}the model's did not converge for {} test{} (e.g. {})",
                       why.empty() ? "" : ", and ", s.failed.size(),
                       s.failed.size() == 1 ? "" : "s", tests[s.failed.front()].source);
  return why;
}

std::vector<identify::EquivalentStiffness>
equivalent_stiffness(const Problem& problem, const State& state, const Simulator& sim,
                     std::size_t jj, std::vector<int>* used) {
  std::vector<joints::Joint> model = state.joints;
  for (auto& j : model) // held at the state's values (parametric terms: their forces known)
    j.fixed.assign(j.terms.size(), true);
  joints::Joint& J = model[jj];
  J.terms = {joints::Term::k, joints::Term::c};
  J.values = {0.0, 0.0};
  J.fixed = {false, false};
  J.given.clear();
  J.parameters.clear();
  const std::vector<int> first{1}; // a linear joint makes no harmonics: the fundamental alone
  std::vector<identify::EquivalentStiffness> out;
  const auto& tests = problem.tests();
  for (std::size_t i = 0; i < tests.size(); ++i) {
    const auto [a, w] = identify::joint_equivalent_sine(tests[i], state.joints[jj]);
    if (!(a > 0.0) || !std::isfinite(a)) continue;
    try {
      const identify::FitResult r = problem.identify(model, sim, {static_cast<int>(i)}, &first);
      const double k = r.joints[jj].terms[0].value, c = r.joints[jj].terms[1].value;
      if (!std::isfinite(k) || !std::isfinite(c)) continue;
      out.push_back({a, w, Complex(k, w * c)});
      if (used) used->push_back(static_cast<int>(i));
    } catch (const std::invalid_argument&) {
      continue; // this test alone does not determine the joint's k and c
    }
  }
  return out;
}

Complex joint_describing_function(const joints::Joint& j, double a, double omega,
                                  const std::function<bool(std::size_t)>& include) {
  constexpr int n = 128;
  Complex N = 0.0;
  for (std::size_t t = 0; t < j.terms.size(); ++t) {
    if (include && !include(t)) continue;
    if (joints::has_parameters(j.terms[t])) {
      try {
        N += identify::describing_function(j, t, a);
      } catch (const std::invalid_argument&) {
        // parameters without values: no force to speak of
      }
      continue;
    }
    Complex G1 = 0.0; // g = Re(G₁ e^{iθ}) + … under y = a cos θ, ẏ = −a ω sin θ
    for (int s = 0; s < n; ++s) {
      const double theta = 2.0 * std::numbers::pi * s / n;
      G1 += j.values[t] *
            joints::basis(j.terms[t], a * std::cos(theta), -a * omega * std::sin(theta)) *
            std::polar(2.0 / n, -theta);
    }
    N += G1 / a;
  }
  return N;
}

double joint_dissipation(const joints::Joint& joint, double amplitude, double omega) {
  return std::numbers::pi * amplitude * amplitude *
         joint_describing_function(joint, amplitude, omega).imag();
}

namespace {

// Weighted least squares of y on the columns of A (weights w), the coefficients kept >= 0 by
// dropping a negative one; the weighted squared residual.
double nonnegative_fit(const Eigen::MatrixXd& A, const Eigen::VectorXd& y, const Eigen::VectorXd& w,
                       Eigen::VectorXd& x) {
  const Eigen::MatrixXd Aw = w.asDiagonal() * A;
  const Eigen::VectorXd yw = w.cwiseProduct(y);
  x = Aw.colPivHouseholderQr().solve(yw);
  if ((x.array() < 0.0).any()) {
    double best = inf;
    Eigen::VectorXd keep = Eigen::VectorXd::Zero(A.cols());
    for (Eigen::Index c = 0; c < A.cols(); ++c) {
      const double n2 = Aw.col(c).squaredNorm();
      const double xc = n2 > 0.0 ? std::max(Aw.col(c).dot(yw) / n2, 0.0) : 0.0;
      const double r = (yw - xc * Aw.col(c)).squaredNorm();
      if (r < best) best = r, keep.setZero(), keep(c) = xc;
    }
    x = keep;
  }
  return (yw - Aw * x).squaredNorm();
}

// The gap's describing function over kg: 0 inside the clearance, → 1 far beyond it.
double clearance_shape(double a, double delta) {
  if (a <= delta) return 0.0;
  const double r = delta / a;
  return 1.0 - 2.0 / std::numbers::pi * (std::asin(r) + r * std::sqrt(1.0 - r * r));
}

} // namespace

namespace {

// "falls by 23 %", or where the smaller amplitude's stiffness is near 0 next to the change (a
// substructure fitted to a low-level test holds the joint's stiffness: the joint's own is then
// a correction, about 0 at small amplitudes), "falls from 12 to -3.4e+04" (N/m or N m/rad).
std::string stiffness_change_text(const JointBehaviour& b) {
  const auto [lo, hi] = std::minmax_element(b.amplitude.begin(), b.amplitude.end());
  const double k_lo = b.stiffness[static_cast<std::size_t>(lo - b.amplitude.begin())];
  const double k_hi = b.stiffness[static_cast<std::size_t>(hi - b.amplitude.begin())];
  const char* way = k_hi < k_lo ? "falls" : "rises";
  if (std::abs(k_lo) >= 0.1 * std::abs(k_hi - k_lo) && k_lo > 0.0)
    return fmt::format("{} by {}", way, pct(std::abs(b.stiffness_change)));
  return fmt::format("{} from {} to {}", way, number(k_lo), number(k_hi));
}

} // namespace

JointBehaviour behaviour(const std::string& joint,
                         const std::vector<identify::EquivalentStiffness>& points,
                         const std::vector<std::string>& tests) {
  JointBehaviour b;
  b.joint = joint;
  b.tests = tests;
  for (const auto& p : points) {
    b.amplitude.push_back(p.amplitude);
    b.frequency_hz.push_back(p.omega / (2.0 * std::numbers::pi));
    b.dissipation.push_back(std::numbers::pi * p.amplitude * p.amplitude * p.Z.imag());
    b.stiffness.push_back(p.Z.real());
  }
  const auto n = static_cast<Eigen::Index>(points.size());
  if (n < 4) return b;
  const auto [lo, hi] = std::minmax_element(b.amplitude.begin(), b.amplitude.end());
  if (!(*hi > 1.2 * *lo)) return b; // one amplitude: nothing to say about a trend
  const auto ilo = lo - b.amplitude.begin(), ihi = hi - b.amplitude.begin();
  b.stiffness_change =
      b.stiffness[static_cast<std::size_t>(ihi)] / b.stiffness[static_cast<std::size_t>(ilo)] - 1.0;

  // Dissipation: π c ω a² + A a^s, weighted relatively (each test's D is as good as its share).
  Eigen::VectorXd D(n), w(n);
  double Dmax = 0.0;
  for (Eigen::Index i = 0; i < n; ++i)
    D(i) = b.dissipation[static_cast<std::size_t>(i)], Dmax = std::max(Dmax, std::abs(D(i)));
  for (Eigen::Index i = 0; i < n; ++i)
    w(i) = 1.0 / (std::abs(D(i)) + 0.02 * Dmax + 1e-300);
  double best = inf;
  Eigen::VectorXd x;
  for (double s = 0.5; s <= 4.0 + 1e-9; s += 0.05) {
    Eigen::MatrixXd A(n, 2);
    for (Eigen::Index i = 0; i < n; ++i) {
      const auto& p = points[static_cast<std::size_t>(i)];
      A(i, 0) = std::numbers::pi * p.omega * p.amplitude * p.amplitude;
      A(i, 1) = std::pow(p.amplitude / *hi, s); // scaled: A is D's hysteretic part at the top
    }
    const double r = nonnegative_fit(A, D, w, x);
    if (r < best) {
      best = r;
      b.slope = s;
      b.hysteretic_share = 0.0;
      for (Eigen::Index i = 0; i < n; ++i) {
        const double viscous = x(0) * A(i, 0), slip = x(1) * A(i, 1);
        b.hysteretic_share = std::max(b.hysteretic_share, slip / std::max(slip + viscous, 1e-300));
      }
    }
  }

  // Stiffness: constant up to an amplitude and rising beyond it (a clearance), against a rise
  // that starts at once (a cubic hardening) and none.
  Eigen::VectorXd K(n), ones = Eigen::VectorXd::Ones(n);
  for (Eigen::Index i = 0; i < n; ++i)
    K(i) = b.stiffness[static_cast<std::size_t>(i)];
  Eigen::MatrixXd Ac(n, 2);
  for (Eigen::Index i = 0; i < n; ++i)
    Ac(i, 0) = 1.0, Ac(i, 1) = std::pow(b.amplitude[static_cast<std::size_t>(i)] / *hi, 2);
  const double smooth = nonnegative_fit(Ac, K, ones, x);
  double gap_best = inf, delta = std::numeric_limits<double>::quiet_NaN(), rise = 0.0;
  for (int g = 0; g <= 40; ++g) {
    const double d = *lo * std::pow(*hi / *lo, g / 40.0);
    Eigen::MatrixXd Ag(n, 2);
    for (Eigen::Index i = 0; i < n; ++i)
      Ag(i, 0) = 1.0, Ag(i, 1) = clearance_shape(b.amplitude[static_cast<std::size_t>(i)], d);
    if (Ag.col(1).squaredNorm() == 0.0) continue;
    const double r = nonnegative_fit(Ag, K, ones, x);
    if (r < gap_best) gap_best = r, delta = d, rise = x(1) * clearance_shape(*hi, d);
  }
  const double scatter = std::sqrt(gap_best / static_cast<double>(n - 2));
  const double k_low = b.stiffness[static_cast<std::size_t>(ilo)];
  const bool clearance = std::isfinite(delta) && delta > 1.05 * *lo && gap_best < 0.5 * smooth &&
                         rise > 3.0 * scatter && rise > 0.02 * std::abs(k_low);
  if (clearance) {
    b.contact_amplitude = delta;
    b.behaviour = "clearance";
    b.finding = fmt::format(
        "Joint '{}': its stiffness stays at {} up to a deformation of about {} and rises beyond it "
        "(by {} at {}), as a contact closing does, not from the start as a cubic stiffness would: "
        "a clearance of about ±{}.",
        joint, number(k_low), number(delta), number(rise), number(*hi), number(delta));
    return b;
  }
  if (!(b.hysteretic_share >= 0.25)) {
    b.finding = fmt::format(
        "Joint '{}': its dissipation per cycle grows with the amplitude as viscous damping's does "
        "(a² ω): no sign of slip{}.",
        joint,
        std::abs(b.stiffness_change) > 0.02
            ? fmt::format("; its stiffness {} between the smallest and the largest amplitude",
                          stiffness_change_text(b))
            : std::string());
    return b;
  }
  const std::string grows = fmt::format(
      "Joint '{}': its dissipation per cycle beyond the viscous part grows as the amplitude to the "
      "power {:.2g} (up to {} of it) and its stiffness {} over the amplitudes",
      joint, b.slope, pct(b.hysteretic_share), stiffness_change_text(b));
  // Slip softens a joint: a smooth dissipation (power 2.2 or more) beside a stiffness that
  // rises over the amplitudes is more likely a damping that grows with the velocity (power 3
  // for a velocity-squared damping, 4 for a cubic one) beside a hardening; or slip and a contact
  // at once. It is not named.
  if (b.slope >= 2.2 && b.stiffness_change > 0.02 && k_low > 0.0) {
    b.finding = grows + ": not slip alone, which softens a joint — a damping that grows with "
                        "the velocity (power 3 for velocity-squared damping, 4 for cubic) beside "
                        "a hardening (a cubic stiffness or a contact), or slip and a contact at "
                        "once.";
    return b;
  }
  if (b.slope < 1.6) {
    b.behaviour = "macroslip";
    b.finding = grows + ": macroslip — the joint slides, dissipating like Coulomb friction "
                        "(power 1).";
  } else if (b.slope < 2.2) {
    b.behaviour = "microslip to macroslip";
    b.finding = grows + ": between microslip (power 3 + chi, 2 … 3) and macroslip (Coulomb "
                        "sliding, power 1) — the joint's slip spreads over the tests.";
  } else if (b.slope <= 3.3) {
    b.behaviour = "microslip";
    b.finding = grows + fmt::format(": microslip — part of the interface slips while the rest "
                                    "sticks (an Iwan joint's power 3 + chi, chi ≈ {:.2g}).",
                                    std::min(b.slope - 3.0, 0.0));
  } else {
    b.finding = grows + ": faster than any slip gives (at most 3).";
  }
  return b;
}

void model_lines(JointBehaviour& b, const joints::Joint& start, const joints::Joint& last) {
  if (b.amplitude.empty()) return;
  std::vector<double> f = b.frequency_hz;
  std::nth_element(f.begin(), f.begin() + static_cast<std::ptrdiff_t>(f.size() / 2), f.end());
  b.model_frequency_hz = f[f.size() / 2];
  const double w = 2.0 * std::numbers::pi * b.model_frequency_hz;
  const auto [lo, hi] = std::minmax_element(b.amplitude.begin(), b.amplitude.end());
  const double a0 = *lo / 1.5, a1 = *hi * 1.5;
  b.model_amplitude.clear(), b.start_dissipation.clear(), b.final_dissipation.clear();
  b.start_stiffness.clear(), b.final_stiffness.clear();
  for (int i = 0; i <= 40; ++i) {
    const double a = a0 * std::pow(a1 / a0, i / 40.0);
    b.model_amplitude.push_back(a);
    for (const auto& [joint, D, K] :
         {std::tuple{&start, &b.start_dissipation, &b.start_stiffness},
          std::tuple{&last, &b.final_dissipation, &b.final_stiffness}}) {
      const Complex N = joint_describing_function(*joint, a, w);
      D->push_back(std::numbers::pi * a * a * N.imag());
      K->push_back(N.real());
    }
  }
}

bool changes_with_level(double linear_criterion, double nonlinear_criterion, int values) {
  const double N = values;
  return nonlinear_criterion + std::log(N) < linear_criterion;
}

Diagnosis diagnose(const Compared& compared, const std::vector<identify::Measurement>& tests,
                   const State& s, const std::vector<Candidate>& ranking, const Candidate* outside,
                   const Preconditions& preconditions) {
  Diagnosis d;
  const EvenHarmonics even = disagreement(d, compared, tests, s);
  d.even_content = even.content;
  // Harmonics of one excitation frequency: a sine test's (a periodic test's lines are not).
  const bool any_harmonics = std::any_of(tests.begin(), tests.end(), [](const auto& m) {
    return !m.fundamental_only && m.kind != identify::RecordKind::periodic;
  });
  const bool any_periodic = std::any_of(tests.begin(), tests.end(), [](const auto& m) {
    return m.kind == identify::RecordKind::periodic;
  });
  d.even_harmonics = any_harmonics && even.content > 5.0 * even.noise &&
                     (compared.noise_known || even.content > 1e-3);
  const Families f = families(ranking);
  d.linear_explains = f.linear.share;
  d.nonlinear_explains = f.nonlinear.share;
  d.conservative_explains = f.conservative.share;
  d.dissipative_explains = f.dissipative.share;
  // Admissible, or failing only the rule that could not be applied (held-out tests).
  const bool significant = std::any_of(ranking.begin(), ranking.end(), [](const Candidate& c) {
    return c.rejected.empty() || only_unchecked(c);
  });

  if (compared.noise_known)
    d.findings.push_back(fmt::format(
        "The starting model leaves a gap of {} against a noise level of {} (the gap a perfect "
        "model would leave, from the records' own scatter).",
        number(s.gap), number(compared.noise_gap)));
  else
    d.findings.push_back(fmt::format("The starting model leaves a gap of {}; the noise level "
                                     "is unknown (stepped-sine tables carry no time records).",
                                     number(s.gap)));
  if (!d.channel.empty())
    d.findings.push_back(fmt::format("The largest disagreement is at channel {} ({} of its "
                                     "measured amplitude over all tests).",
                                     d.channel, pct(d.channel_error)));
  for (const auto& finding : level_evidence(tests))
    d.findings.push_back(finding);
  if (outside) {
    const auto best = std::min_element(
        ranking.begin(), ranking.end(),
        [](const Candidate& a, const Candidate& b) { return a.criterion < b.criterion; });
    d.joint = outside->joint;
    d.findings.push_back(fmt::format(
        "No addition explains it as well as a coefficient that changes between tests: {} "
        "explains {} of it{}.",
        outside->name(), pct(outside->explained),
        best != ranking.end() && std::isfinite(best->gap)
            ? fmt::format(", the best addition ({}) {}", best->name(), pct(best->explained))
            : std::string()));
    return d;
  }
  if (!significant) {
    const std::string why = unjudged(ranking, s, tests);
    if (why.empty())
      d.findings.push_back(
          "No candidate explains a significant share of the disagreement: nothing is missing "
          "that these tests can reveal.");
    else
      d.findings.push_back(fmt::format(
          "No candidate that could be judged explains a significant share of the disagreement; "
          "but the conclusion is limited: {}, so what those would explain there is unknown.",
          why));
    return d;
  }
  const bool nonlinear = level_finding(d, f, compared.values, preconditions.several_levels);
  where_finding(d, ranking, f, nonlinear);
  if (nonlinear) nature_finding(d, f, preconditions.several_levels);
  if (d.even_harmonics)
    even_finding(d, even, ranking, tests.size(), compared.noise_known);
  else if (any_harmonics)
    d.findings.push_back("No even harmonics beyond the noise: the missing force is symmetric.");
  else if (any_periodic)
    d.findings.push_back("The periodic tests' lines are not harmonics of one frequency: even "
                         "harmonics are not judged apart (the even terms are candidates as the "
                         "others are).");
  else
    d.findings.push_back("The tables give the fundamental only: harmonics cannot be judged.");
  return d;
}

std::vector<std::string> level_evidence(const std::vector<identify::Measurement>& tests) {
  // The pair that says most: the largest change in standard deviations of the noise (or, the
  // noise unknown, the largest change).
  double best = -1.0;
  std::string text;
  for (std::size_t a = 0; a < tests.size(); ++a)
    for (std::size_t b = a + 1; b < tests.size(); ++b) {
      const auto &ta = tests[a], &tb = tests[b];
      // A periodic test's lines are compared in the gap; a receptance at one frequency is a
      // sine test's.
      if (ta.kind == identify::RecordKind::periodic || tb.kind == identify::RecordKind::periodic)
        continue;
      if (std::abs(ta.frequency_hz - tb.frequency_hz) > 0.005 * ta.frequency_hz) continue;
      const double Fa = identify::force_level(ta), Fb = identify::force_level(tb);
      if (std::max(Fa, Fb) < 1.5 * std::min(Fa, Fb) || ta.force_at.empty() || tb.force_at.empty())
        continue;
      for (std::size_t j = 0; j < ta.response_at.size(); ++j) {
        const int jb = tb.response_index(ta.response_at[j]);
        if (jb < 0) continue;
        const auto ja = static_cast<Eigen::Index>(j);
        const Complex Ra = ta.X(1, ja) / ta.F(1, 0), Rb = tb.X(1, jb) / tb.F(1, 0);
        const double change = std::abs(Ra - Rb) / std::max(std::abs(Rb), 1e-300);
        const double va = ta.X_variance(1, ja), vb = tb.X_variance(1, jb);
        const double sd =
            va > 0.0 && vb > 0.0
                ? std::sqrt(va / std::norm(ta.F(1, 0)) + vb / std::norm(tb.F(1, 0))) / std::abs(Rb)
                : 0.0;
        const double score = sd > 0.0 ? change / sd : change;
        if (score <= best) continue;
        best = score;
        const std::string verdict =
            sd <= 0.0 ? std::string()
            : change > 5 * sd
                ? fmt::format(", far beyond what the noise allows (about {})", pct(sd))
                : fmt::format(", which the noise explains (about {})", pct(sd));
        text = fmt::format("At {} Hz the measured receptance at {} changes by {} between force "
                           "amplitudes {} and {}{}.",
                           number(ta.frequency_hz), channel_name(ta, j), pct(change),
                           number(std::min(Fa, Fb)), number(std::max(Fa, Fb)), verdict);
      }
    }
  if (text.empty()) return {};
  return {text};
}

} // namespace jointid::discover::detail

#include "discover/diagnosis.hpp"

#include "discover/selection.hpp"
#include "discover/text.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <set>
#include <utility>

namespace jointid::discover::detail {

namespace {

using Complex = std::complex<double>;
constexpr double inf = std::numeric_limits<double>::infinity();

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

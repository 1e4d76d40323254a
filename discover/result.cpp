#include "discover/result.hpp"

#include "discover/text.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace jointid::discover {

std::string Candidate::name() const {
  if (refit) return "refit of the starting values";
  if (!term) return "substructure damping";
  if (varies) return fmt::format("{} at '{}', a value per test", joints::term_name(*term), joint);
  if (with)
    return fmt::format("{} and {} at '{}'", joints::term_name(*term), joints::term_name(*with),
                       joint);
  return fmt::format("{} at '{}'", joints::term_name(*term), joint);
}

std::string Candidate::effect() const {
  if (refit) return "linear terms identified again";
  if (!term) return "substructure damping";
  if (varies)
    return fmt::format("{} that changes between tests (no term of the library)",
                       joints::term_effect(*term));
  if (with) return fmt::format("{} and {}", joints::term_effect(*term), joints::term_effect(*with));
  return std::string(joints::term_effect(*term));
}

bool Candidate::determined() const {
  if (term && joints::has_parameters(*term)) {
    const auto one = [](const auto& p) {
      return !p.fixed && p.determined && std::isfinite(p.ci_low) && std::isfinite(p.ci_high) &&
             p.ci_high > p.ci_low;
    };
    return std::any_of(parameters.begin(), parameters.end(), one) ||
           std::any_of(with_parameters.begin(), with_parameters.end(), one);
  }
  return std::isfinite(ci_low) && std::isfinite(ci_high) && ci_high > ci_low &&
         std::isfinite(std) && std > 0.0;
}

bool Candidate::linear() const {
  return !varies && (refit || !term || joints::is_linear(*term));
}

namespace detail {

std::vector<Comparison> comparisons(const std::vector<identify::Measurement>& tests, int K,
                                    const State& s) {
  std::vector<Comparison> out;
  for (std::size_t i = 0; i < tests.size(); ++i) {
    const auto& m = tests[i];
    const bool periodic = m.kind == identify::RecordKind::periodic;
    // A sine test's fundamental; every excited line of a periodic test (its FRF over them).
    const std::vector<int> lines = periodic ? m.excited_lines : std::vector<int>{1};
    for (std::size_t j = 0; j < m.response_at.size(); ++j) {
      const auto jj = static_cast<Eigen::Index>(j);
      // Harmonics 2 … K over the fundamental; a periodic test's lines where only the joints put
      // response over its excited lines.
      double hm = 0.0, hs = 0.0, reference = 0.0;
      if (periodic) {
        for (int k : m.lines)
          if (std::binary_search(m.excited_lines.begin(), m.excited_lines.end(), k))
            reference += std::norm(m.X(k, jj));
          else
            hm += std::norm(m.X(k, jj)), hs += std::norm(s.X[i](k, jj));
      } else {
        reference = std::norm(m.X(1, jj));
        if (!m.fundamental_only)
          for (int k = 2; k <= K; ++k)
            hm += std::norm(m.X(k, jj)), hs += std::norm(s.X[i](k, jj));
      }
      for (int k : lines) {
        Comparison c;
        c.test = m.source;
        c.channel = channel_name(m, j);
        c.frequency_hz = k * m.frequency_hz;
        c.force = identify::force_level(m);
        c.force_phasor = m.F.cols() > 0 ? m.F(k, 0) : std::complex<double>();
        c.measured = m.X(k, jj);
        c.simulated = s.X[i](k, jj);
        c.amplitude_error = std::abs(c.simulated) / std::max(std::abs(c.measured), 1e-300) - 1.0;
        c.phase_error_deg = std::arg(c.simulated / c.measured) * 180.0 / std::numbers::pi;
        c.harmonics_measured = std::sqrt(hm / std::max(reference, 1e-300));
        c.harmonics_simulated = std::sqrt(hs / std::max(reference, 1e-300));
        c.converged = !std::binary_search(s.failed.begin(), s.failed.end(), static_cast<int>(i));
        out.push_back(c);
      }
    }
  }
  return out;
}

std::string finding(const Step& s) {
  const std::string interval =
      s.added.determined()
          ? fmt::format("[{}, {}]", number(s.added.ci_low), number(s.added.ci_high))
          : std::string("(its interval undetermined: the value is not a result)");
  const std::string left_out =
      s.added.left_out.empty()
          ? std::string()
          : fmt::format("; {} test{} it could not re-simulate left out", s.added.left_out.size(),
                        s.added.left_out.size() == 1 ? "" : "s");
  return fmt::format("Added {} ({}) = {} {}: the gap fell from {} to {} ({} of it explained{}).",
                     s.added.name(), s.added.effect(), number(s.added.value), interval,
                     number(s.gap_before), number(s.gap_after), pct(s.added.explained), left_out);
}

std::string refit_finding(const Step& s, const std::vector<joints::Joint>& before,
                          const std::vector<joints::Joint>& after) {
  std::string changes;
  for (std::size_t j = 0; j < before.size() && j < after.size(); ++j)
    for (std::size_t t = 0; t < before[j].terms.size() && t < after[j].values.size(); ++t)
      if (!before[j].fixed[t])
        changes += fmt::format("{}{} at '{}' {} → {}", changes.empty() ? "" : ", ",
                               joints::term_name(before[j].terms[t]), before[j].name,
                               number(before[j].values[t]), number(after[j].values[t]));
  return fmt::format("Refitted the starting values ({}): the gap fell from {} to {} ({} of it "
                     "explained).",
                     changes, number(s.gap_before), number(s.gap_after), pct(s.added.explained));
}

std::string summary(const Result& r, const Compared& compared) {
  std::string added, removed;
  for (const auto& s : r.steps)
    if (!s.removed) added += (added.empty() ? "" : ", ") + s.added.name();
  for (const auto& s : r.steps)
    if (s.removed) removed += (removed.empty() ? "" : ", ") + s.added.name();
  if (!removed.empty()) removed = fmt::format(" (and took {} out again)", removed);
  const double first = r.gap.front(), last = r.gap.back();
  std::string floor;
  if (!compared.noise_known)
    floor = "; the noise level is unknown (stepped-sine tables)";
  else
    floor = fmt::format(
        "; the noise level is {}{}, {}", number(compared.noise_gap),
        r.simulation_gap > 0.1 * compared.noise_gap
            ? fmt::format(" and the simulation's own error {}", number(r.simulation_gap))
            : std::string(),
        r.at_noise_level ? "which it has reached"
                         : fmt::format("not reached (χ² per value {:.3g})", r.chi2_per_value));
  if (added.empty())
    return fmt::format("Nothing was added: the gap stays at {}{}.", number(last), floor);
  return fmt::format("Added {}{}: the gap shrank from {} to {} ({}× smaller){}.", added, removed,
                     number(first), number(last), number(first / std::max(last, 1e-300)), floor);
}

} // namespace detail
} // namespace jointid::discover

#pragma once
/// The candidates of a step (discover.hpp): each term of the library at each joint that lacks
/// it, a scale factor on the substructure's damping, a refit of starting values never fitted,
/// and each term of the model with a value per test. Each is identified and re-simulated, and
/// judged by rules 1 and 2 (selection.hpp); rules 3–5 compare it with the others.
#include "discover/problem.hpp"
#include "identify/parametric.hpp"

#include <functional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace jointid::discover::detail {

/// A candidate and the state it gives.
using Outcome = std::pair<Candidate, State>;

/// A candidate that gives no model: rejected with `why`, its gap and criterion infinite, its
/// state nothing simulated (the joints of `state`).
Outcome refused(Candidate candidate, const State& state, const std::string& why);

/// The starting values identified again (when none was identified at the start).
Outcome consider_refit(const Problem& problem, const State& state, const Simulator& sim);
/// `term` added at `joint`, every non-fixed term identified again by equation error.
Outcome consider_term(const Problem& problem, const State& state, const Simulator& sim,
                      const std::string& joint, joints::Term term);
/// The parametric `term` (jenkins, iwan, gap) added at `joint`: its parameters started from a
/// describing-function fit to each test's equivalent stiffness of the joint (less its other
/// terms), the coefficient terms by equation error with its force known. Its parameters get
/// intervals only from output error: the best parametric candidate of a step is among the
/// finalists (selection.hpp), the others stay undetermined.
Outcome consider_parametric(const Problem& problem, const State& state, const Simulator& sim,
                            const std::string& joint, joints::Term term);
/// Whether the equivalent stiffness's real part, in the order of the amplitudes, falls to an
/// interior least point and rises after it, each by more than a tenth of the largest |Z|.
bool softens_then_stiffens(const std::vector<identify::EquivalentStiffness>& points);
/// Why a pair was not tried: the joint's stiffness does not turn. Such an outcome is left out of
/// the ranking (it was never a candidate).
inline constexpr std::string_view pair_not_asked =
    "not tried: the joint's stiffness does not fall and then rise with the deformation amplitude "
    "over the tests";
/// Two parametric terms added to the joint together (jenkins and gap), started from one
/// describing-function fit of both (identify::fit_describing_functions); refused with
/// pair_not_asked unless the joint's equivalent stiffness softens and then stiffens
/// (softens_then_stiffens).
Outcome consider_pair(const Problem& problem, const State& state, const Simulator& sim,
                      const std::string& joint, joints::Term term, joints::Term with);
/// The joint's `term` identified from each test alone (every other term held at the state's
/// value), and every test simulated at its own value: does the coefficient change between
/// tests, beyond the noise, and with what? Admissible when the values disagree
/// (agreement_problem).
Outcome consider_variation(const Problem& problem, const State& state, const Simulator& sim,
                           const std::string& joint, joints::Term term);
/// The substructure's damping scaled by s: ln s is searched by a coarse scan and a golden
/// section on the criterion, every joint term identified again at each trial. With more tests
/// than RefineScope::spread, the search runs on that spread of them, and the scale is then
/// judged on every test with one parabolic step from the misfit's curvature there.
Outcome consider_damping(const Problem& problem, const State& state);

/// Every candidate of a step from `state` (simulated with `current`), as jobs to run in
/// parallel: a refit unless `values_fitted`, the library's terms at every joint (even ones only
/// where some test has harmonics beyond the fundamental), the damping scale (if asked and the
/// substructure has modes), and, with four tests or more, a value per test of every non-fixed
/// term (Problem::preconditions). The jobs refer to the arguments, which must outlive them.
std::vector<std::function<Outcome()>> candidate_jobs(const Problem& problem, const State& state,
                                                     const Simulator& current, bool values_fitted);

} // namespace jointid::discover::detail

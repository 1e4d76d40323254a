#pragma once
/// The diagnosis of the starting model's disagreement with the measurement (discover.hpp's
/// Diagnosis): where it is largest, whether it changes with the force level (a non-linear effect)
/// or not (a linear model error), at which joint, conservative or dissipative, and whether even
/// harmonics point to an asymmetric joint force; in sentences.
#include "discover/gap.hpp"
#include "discover/preconditions.hpp"

#include <string>
#include <vector>

namespace jointid::discover::detail {

/// From the starting state, its compared values and tests, and the first step's additions
/// (each with its criterion and its share of the squared gap explained). `outside`: the best
/// explanation, when it is a coefficient that changes between tests. What the tests cannot
/// tell (`preconditions`) is not said: from tests at one force level, nothing about a change
/// with the level; when a candidate's re-simulations or the model's did not converge for every
/// test, never that nothing is missing.
Diagnosis diagnose(const Compared& compared, const std::vector<identify::Measurement>& tests,
                   const State& state, const std::vector<Candidate>& additions,
                   const Candidate* outside, const Preconditions& preconditions);

/// What the rules could not judge: the additions whose re-simulations did not converge for
/// every test (left out or rejected), and the tests the state could not re-simulate — "the
/// re-simulations of k3 at 'tip' did not converge for every test, and the model's did not
/// converge for 2 tests (e.g. t.csv:12)". Empty when everything was judged.
std::string unjudged(const std::vector<Candidate>& additions, const State& state,
                     const std::vector<identify::Measurement>& tests);

/// The disagreement changes with the force level when the best non-linear addition's criterion
/// is below the best linear one's by more than ln N (N real values compared): a non-linear term
/// must beat a linear correction by more than what one parameter costs.
bool changes_with_level(double linear_criterion, double nonlinear_criterion, int values);

/// Direct evidence of level dependence: of the tests at the same frequency (within 0.5 %) and
/// force levels apart by 1.5× or more, the pair whose measured receptance X₁/F₁ changes most
/// (in standard deviations of its noise, or relatively when the noise is unknown), in a
/// sentence saying whether the noise explains it. Empty when no pair qualifies.
std::vector<std::string> level_evidence(const std::vector<identify::Measurement>& tests);

} // namespace jointid::discover::detail

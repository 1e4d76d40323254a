#pragma once
/// The diagnosis of the starting model's disagreement with the measurement (discover.hpp's
/// Diagnosis): where it is largest, whether it changes with the force level (a non-linear effect)
/// or not (a linear model error), at which joint, conservative or dissipative, and whether even
/// harmonics point to an asymmetric joint force; in sentences.
#include "discover/gap.hpp"
#include "discover/preconditions.hpp"
#include "discover/problem.hpp"
#include "identify/parametric.hpp"

#include <complex>
#include <functional>

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

/// Each test's equivalent stiffness of joint `joint` of the state (JointBehaviour): the joint as
/// k + c identified from that test alone at harmonic 1, the other joints held at the state's
/// values. Tests that do not determine it alone are skipped; `sources` (if given) gets the
/// tests used.
std::vector<identify::EquivalentStiffness>
equivalent_stiffness(const Problem& problem, const State& state, const Simulator& sim,
                     std::size_t joint, std::vector<int>* used = nullptr);

/// The describing function N(a) = G₁/a of the joint's terms that `include` keeps (all when
/// empty), under y = a cos ωt: its equivalent stiffness k_eq + iω c_eq at that amplitude.
/// A parametric term without its parameters is left out.
std::complex<double>
joint_describing_function(const joints::Joint& joint, double amplitude, double omega,
                          const std::function<bool(std::size_t)>& include = {});

/// The dissipation per cycle π a² Im N(a) of the joint's force, J.
double joint_dissipation(const joints::Joint& joint, double amplitude, double omega);

/// What the points show (JointBehaviour's fits and words), `tests` their sources.
JointBehaviour behaviour(const std::string& joint,
                         const std::vector<identify::EquivalentStiffness>& points,
                         const std::vector<std::string>& tests);

/// The model lines of a behaviour: D of the start's and the final model's joint over the
/// measured amplitudes (and a little beyond), at the tests' median frequency.
void model_lines(JointBehaviour& behaviour, const joints::Joint& start, const joints::Joint& last);

} // namespace jointid::discover::detail

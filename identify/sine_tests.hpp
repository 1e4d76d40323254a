#pragma once
/// Virtual sine tests: the model with its joints at their values, driven by F0 sin(2π f t) at
/// one DOF, simulated to its periodic steady state, and written as measurement records
/// (DESIGN.md's CSV contract) — by implicit time integration of the finite element model
/// (exact stick–slip friction) or by harmonic balance on the joint DOFs. Optionally with
/// measurement noise, so that identification and discovery can be tested on data whose truth
/// is known.
#include "fem/status.hpp"
#include "frf/harmonic_balance.hpp"
#include "frf/substructure.hpp"
#include "identify/record.hpp"
#include "joints/joint.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace jointid::identify {

struct SineTestPlan {
  double frequency_hz = 0.0; ///< Hz
  double amplitude = 0.0;    ///< N or N·m (peak)
};

enum class SimulationMethod { time_integration, harmonic_balance };

struct SimulationOptions {
  SimulationMethod method = SimulationMethod::time_integration;
  int periods = 8;             ///< periods in each record
  int steps_per_period = 2048; ///< time steps per period (time integration; samples for hb)
  int samples_per_period = 0;  ///< samples kept per period; 0: every step. Must divide steps.
  /// Response channels written at every output DOF: any of displacement, velocity,
  /// acceleration (acceleration: the derivative of the velocity from its harmonics).
  std::vector<Quantity> quantities{Quantity::displacement, Quantity::velocity};
  /// Outputs beyond the joints' DOFs and the force DOF.
  std::vector<fem::NodeDof> extra_outputs;
  frf::HarmonicBalanceOptions balance{}; ///< harmonic balance
  double steady_tolerance = 1e-10;       ///< time integration: period-to-period change
  /// Harmonic balance: start each test from the solution of the one below it in frequency at
  /// the same force (a sweep up, which follows a hardening joint's upper branch); false: every
  /// test from the linear response.
  bool warm_start = true;
  /// Called with the fraction of the tests done (0 … 1] after each test, from one thread at a
  /// time (time integration runs tests in parallel); empty: nothing is called.
  std::function<void(double)> progress;
};

struct SimulatedTest {
  /// ok, or why the test has no record (its channels empty; record.source is still its name):
  /// the harmonic balance found no periodic solution (not_converging), the joints' Newton
  /// iteration failed at a time step (not_converging), the effective stiffness or the modal
  /// analysis failed. Each reason names the test.
  fem::Status status;
  Record record; ///< source = its file name, sine_f<freq>Hz_F<amp>N.csv
  SineTestPlan plan;
  std::vector<std::string> comments; ///< how it was made, for the CSV's comment lines
  /// A record that is not a periodic steady state after the most periods allowed (time
  /// integration; the record holds the last periods all the same).
  std::vector<std::string> warnings;
};

/// "joint 'tip': 7:uy to ground; k = 4800, c = 20": a record's comment line describing a joint.
std::string joint_comment(const joints::Joint& joint);

/// "sine_f3.4Hz_F80N.csv": numbers in their shortest exact form.
std::string sine_test_name(const SineTestPlan& plan);

/// Simulates every test. Outputs: every joint DOF, then the force DOF, then `extra_outputs`
/// (each once). Throws std::invalid_argument for bad plans or options (naming the value), or a
/// force DOF the model lacks. A test that cannot be simulated has a status that says why
/// (SimulatedTest::status) and no record; the others are simulated all the same. Time
/// integration needs a finite element substructure.
std::vector<SimulatedTest> simulate_sine_tests(const frf::Substructure& substructure,
                                               const std::vector<joints::Joint>& joints,
                                               const fem::NodeDof& force_at,
                                               const std::vector<SineTestPlan>& plans,
                                               const SimulationOptions& options = {});

/// Adds white Gaussian noise to every channel of a record (force too, unless `force` is
/// false): standard deviation `level` × the channel's RMS about its mean. Deterministic for a
/// given generator state.
void add_noise(Record& record, double level, std::uint64_t seed, bool force = true);

/// Measurement noise on a series of simulated tests (add_noise, every channel, force too): test
/// i draws from seed + i, so that each record's noise is its own and the series is repeated
/// exactly from one seed. Each record's comments say the level and its seed. Level 0: nothing.
void add_noise(std::vector<SimulatedTest>& tests, double level, std::uint64_t seed);

/// The comment lines of a stepped-sine table made of these tests' fundamentals
/// (identify::stepped_sine_table): what a row is, then how the series was made — the first
/// test's lines on its joints, its method and its noise (those of one test alone, its force,
/// periods and convergence, are left out).
std::vector<std::string> stepped_sine_comments(const std::vector<SimulatedTest>& tests);

} // namespace jointid::identify

#pragma once
/// Virtual tests under any force history (band-limited random, sine sweep, multisine, or a force
/// channel of a measured record): the finite element model with its joints at their values,
/// simulated in time (fem/transient.hpp) — in full (the reference) or in modal coordinates with
/// a static correction (fast) — and written as a measurement record (DESIGN.md's CSV contract).
/// SI units; the record's sample rate is the force history's.
#include "fem/status.hpp"
#include "frf/substructure.hpp"
#include "identify/record.hpp"
#include "joints/joint.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace jointid::identify {

enum class TransientRoute {
  full, ///< Newmark on the whole finite element model
  modal ///< Newmark on the retained modes, the rest as static flexibility at the loaded DOFs
};

struct ForcedOptions {
  TransientRoute route = TransientRoute::modal;
  /// Modal route: modes below this frequency are integrated (Hz); 0: below the record's
  /// Nyquist frequency. The rest enter through their static flexibility at the forced and the
  /// joints' DOFs (see fem::modal_reduction) unless static_correction is false. Models of up to
  /// 200 equations get every mode from the dense eigensolver; larger ones only the band below
  /// the cutoff (sparse engine). Modes above the cutoff that a non-linear joint's harmonics
  /// excite are missing from the response (velocity and acceleration most): raise the cutoff
  /// when those matter.
  double modal_cutoff_hz = 0.0;
  bool static_correction = true;
  int substeps = 4;       ///< Newmark steps per sample interval
  double fade_in_s = 0.0; ///< the force is faded in over this time (half-cosine), s
  /// Response channels written at every output DOF: displacement, velocity, acceleration.
  std::vector<Quantity> quantities{Quantity::displacement, Quantity::velocity};
  /// Outputs beyond the joints' DOFs and the force DOFs.
  std::vector<fem::NodeDof> extra_outputs;
  /// Called with the fraction of the time simulation done (0 … 1); empty: not called.
  std::function<void(double)> progress;
};

/// Forces at one or more DOFs, sampled at sample_rate_hz from t = 0.
struct ForceInput {
  std::vector<fem::NodeDof> at;
  Eigen::MatrixXd samples; ///< n_samples × |at|, N or N·m
  double sample_rate_hz = 0.0;
  std::string description; ///< how it was made, for the record's comments
};

struct ForcedTest {
  /// ok, or why the simulation stopped: the joints' Newton iteration failed at a step
  /// (not_converging, the reason says when; the record holds nothing), the modal analysis or
  /// the effective stiffness failed.
  fem::Status status;
  Record record; ///< the force channels as applied (faded in), then x/v/a at every output
  std::vector<std::string> comments; ///< how it was made, for the CSV's comment lines
  std::vector<std::string> warnings;
  int modes_kept = 0;     ///< modal route: modes integrated
  int static_columns = 0; ///< modal route: static-correction coordinates
};

/// Simulates the structure from rest under the forces. Outputs: every joint DOF, then the force
/// DOFs, then extra_outputs (each once). Throws std::invalid_argument for bad options or a
/// modal substructure (time integration needs a finite element model). A numerical failure
/// (the joints' iteration at a step, the modal analysis) is the result's status.
ForcedTest simulate_forced(const frf::Substructure& substructure,
                           const std::vector<joints::Joint>& joints, const ForceInput& input,
                           const ForcedOptions& options = {});

enum class Excitation { random, sweep, multisine };

/// A generated force at one DOF: band-limited Gaussian random (level = RMS, seeded), linear sine
/// sweep (level = peak) or Schroeder multisine (level = RMS) over [f0_hz, f1_hz].
struct ExcitationSpec {
  Excitation kind = Excitation::random;
  double f0_hz = 0.0, f1_hz = 0.0, level = 0.0; ///< Hz, N or N·m
  std::uint64_t seed = 1;                       ///< random only
  double duration_s = 0.0, sample_rate_hz = 0.0;
};

/// The force history of the spec at `at`, with its description for the record's comments.
/// Throws std::invalid_argument (from fem/excitation.hpp) for a bad band or sampling.
ForceInput generated_force(const ExcitationSpec& spec, const fem::NodeDof& at);

/// The record's file name: "random_2-40Hz_40N_seed1.csv", "sweep_2-40Hz_10N.csv", …
std::string excitation_record_name(const ExcitationSpec& spec);

/// The force channels of a record as a ForceInput (every `f@` channel; std::invalid_argument
/// naming the record when it has none or its sampling is not uniform).
ForceInput force_input(const Record& record);

/// The fade-in (ForcedOptions::fade_in_s) of a generated force unless told otherwise: 5 % of
/// its duration, so that a structure at rest is not struck by the force at full level.
double default_fade_in_s(const ExcitationSpec& spec);

/// The fade-in of a measured force (force_input) unless told otherwise: none when it already
/// starts at zero (its first samples within 1e-9 of its peak), else 5 % of its duration.
double default_fade_in_s(const ForceInput& measured);

/// Measurement noise on a simulated record (add_noise, every channel, force too), drawn from
/// seed + 1000003, not from the force's own seed: the same generator state would make the
/// noise the very white sequence a random force was filtered from, correlated with it. A
/// comment line says the level and the seed. Level 0: nothing.
void add_noise(ForcedTest& test, double level, std::uint64_t force_seed);

} // namespace jointid::identify

#pragma once
/// The `jointid` commands: each checks its options, reads its inputs, calls the library, and
/// only then writes its outputs. Errors are exceptions (io::Error for bad input); warnings go
/// to stderr.
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace jointid::cli {

struct SimulateOptions {
  std::filesystem::path model;
  std::string force;               ///< NODE:DOF of the sine force
  std::vector<double> frequencies; ///< Hz
  std::vector<double> amplitudes;  ///< N or N·m (peak)
  std::string method = "time";     ///< time (Newmark to steady state) or hb (harmonic balance)
  int periods = 8;                 ///< periods in each record
  int steps_per_period = 2048;     ///< time steps per period
  int samples_per_period = 0;      ///< samples kept per period (0: every step)
  int harmonics = 9;               ///< hb: harmonics 0 … K
  std::vector<std::string> channels{"x", "v"}; ///< response quantities written: x, v, a
  std::vector<std::string> outputs;            ///< more response points, NODE:DOF
  double noise = 0.0;                          ///< noise RMS / channel RMS
  unsigned long long seed = 1;                 ///< noise generator seed
  bool table = false;          ///< write one stepped-sine table (fundamentals) instead of records
  std::string engine = "auto"; ///< modes of a large model: auto or slepc (MPI)
  std::filesystem::path output_dir;
  // Any other force history (one record): --excitation random|sweep|multisine.
  std::string excitation = "sine";  ///< sine (steady state, the options above), random, sweep,
                                    ///< multisine, record (the force channels of --force-from)
  std::string band;                 ///< F0:F1, Hz (random, multisine; sweep: from F0 to F1)
  double rms = 0.0;                 ///< N or N·m (random, multisine); sweep: --amplitude
  double duration = 0.0;            ///< s
  double sample_rate = 0.0;         ///< Hz
  std::string route = "modal";      ///< modal (retained modes + static correction) or full
  double modal_cutoff = 0.0;        ///< Hz; 0: the Nyquist frequency
  int substeps = 4;                 ///< Newmark steps per sample
  std::optional<double> fade_in;    ///< s; not given: 5 % of the duration
  std::filesystem::path force_from; ///< --excitation record: the record whose f@ channels drive
};

/// One record per frequency × amplitude: DIR/sine_f<freq>Hz_F<amp>N.csv; or, with `table`,
/// DIR/stepped_sine.csv. Other excitations: one record DIR/<excitation>_<F0>-<F1>Hz_....csv, or
/// DIR/<record stem>_simulated.csv for --excitation record.
void simulate(const SimulateOptions& options);

struct CompareOptions {
  std::filesystem::path model;
  std::filesystem::path record;
  std::string band;            ///< F0:F1, Hz; empty: the whole spectrum
  int segment = 0;             ///< Welch segment, samples; 0: automatic
  std::optional<double> skip;  ///< s left out at the start; not given: 10 % of the record
  std::string route = "modal"; ///< modal or full
  double modal_cutoff = 0.0;   ///< Hz; 0: the Nyquist frequency
  int substeps = 4;
  bool plot = true;
  std::filesystem::path output_dir;
};

/// Measured vs predicted response spectra: DIR/compare.json and DIR/compare.png.
void compare(const CompareOptions& options);

struct IdentifyOptions {
  std::filesystem::path model;
  std::vector<std::filesystem::path> records; ///< time records or stepped-sine tables
  std::filesystem::path output;
  std::vector<int> harmonics{1};
  std::string engine = "auto";      ///< modes of a large model: auto or slepc (MPI)
  std::filesystem::path fit_png;    ///< not empty: the records with their harmonic fits
  std::filesystem::path params_png; ///< not empty: identified / model values with intervals
  bool output_error = false;        ///< refine by output error (identify/output_error.hpp)
  int balance_harmonics = 15;       ///< its harmonic balance
};

/// Identifies the joints' non-fixed terms from the tests; writes the JSON result and prints
/// a table; with fit_png, a picture of each test's joint displacements and their harmonic fits;
/// with params_png, the identified values against the model's with their intervals.
void identify(const IdentifyOptions& options);

struct DiscoverOptions {
  std::filesystem::path model;
  std::vector<std::filesystem::path> records; ///< time records or stepped-sine tables
  std::filesystem::path output_dir;
  std::vector<int> harmonics{1, 2, 3};
  int balance_harmonics = 15;
  int max_steps = 6;
  std::vector<std::string> terms; ///< candidate terms; empty: the whole library
  bool substructure_damping = true;
  bool plots = true;
  std::string engine = "auto"; ///< modes of a large model: auto or slepc (MPI)
};

/// Model discovery: writes DIR/discovery.json and DIR/report.md with its plots.
void discover(const DiscoverOptions& options);

struct ModesOptions {
  std::filesystem::path model;
  std::filesystem::path output_dir;
  int count = 10;
  int pictures = 4;            ///< modes drawn in DIR/modes.png (0: no picture)
  std::string engine = "auto"; ///< auto, dense, sparse or slepc (MPI, distributed)
  /// Iterative engines (sparse, slepc): relative residual at which a mode has converged, and
  /// the restarts allowed (the defaults of fem::ModalOptions); the dense engine has neither.
  double tolerance = 1e-10;
  int max_restarts = 1000;
};

/// Writes DIR/modes.json with the lowest `count` natural frequencies (and warnings about
/// rigid-body modes or mechanisms), the VTK files of the mode shapes (DIR/modes.vtu,
/// DIR/mesh.vtu, DIR/mode_<r>.pvd animations) and DIR/modes.png with the first `pictures` modes.
/// The picture needs an X display (main() re-runs the command under xvfb-run when there is
/// none); without one it is skipped with a warning.
void modes(const ModesOptions& options);

struct ResponseOptions {
  std::filesystem::path model;
  std::string force;              ///< NODE:DOF of the sine force
  std::vector<double> amplitudes; ///< N or N·m (peak), one curve each
  std::string freq_range;         ///< F0:F1, Hz (traced from F0 to F1; either order)
  int harmonics = 9;              ///< harmonics 0 … K of the harmonic balance
  std::string plot_dof;           ///< NODE:DOF drawn in response.png; empty: the force DOF
  bool plot = true;
  std::string engine = "auto"; ///< modes of large models: auto or slepc
  std::filesystem::path output_dir;
};

/// Response curves by harmonic balance with continuation: DIR/response.json (README's
/// contract) and DIR/response.png. Progress on a terminal (stderr), nothing otherwise.
void response(const ResponseOptions& options);

struct FrfOptions {
  std::filesystem::path model;
  std::string drive;                  ///< NODE:DOF of the force
  std::vector<std::string> responses; ///< NODE:DOF each; empty: the drive DOF
  std::string freq_range;             ///< F0:F1, Hz (F0 >= 0)
  int points = 1000;                  ///< evenly spaced frequencies, both ends included
  std::string kind = "receptance";    ///< receptance, mobility or accelerance
  bool plot = true;
  std::string engine = "auto";
  std::filesystem::path output_dir;
};

/// The linear substructure's FRFs from one force: DIR/frf.csv, DIR/frf.uff (dataset 58, FRFs)
/// and DIR/frf.png (magnitude and phase).
void frf(const FrfOptions& options);

struct DesignOptions {
  std::filesystem::path model;
  std::string force;                    ///< NODE:DOF of the sine force
  std::vector<std::string> frequencies; ///< Hz: values or ranges F0:STEP:F1
  std::vector<std::string> amplitudes;  ///< N or N·m (peak): values or ranges A0:STEP:A1
  int count = 10;                       ///< tests to choose
  std::vector<int> harmonics{1};        ///< harmonics the identification will use
  double noise = 0.01;                  ///< expected noise RMS / channel RMS
  int periods = 8;                      ///< periods in each record
  int balance_harmonics = 9;            ///< harmonics 0 … K of the prediction
  double max_misfit = 0.2;     ///< leave out candidates whose equations miss by more (noise std)
  std::string engine = "auto"; ///< modes of large models: auto or slepc
  std::filesystem::path output_dir;
};

/// D-optimal experiment design: the `count` candidate tests (frequencies × amplitudes) that
/// determine the joints' non-fixed terms best, predicted at the model's values; writes
/// DIR/design.json and prints the chosen tests and the standard deviations to expect.
void design(const DesignOptions& options);

} // namespace jointid::cli

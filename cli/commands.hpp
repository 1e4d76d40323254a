#pragma once
/// The `jointid` commands: each reads its inputs, checks everything it can before computing,
/// computes, and only then writes its outputs. Errors are exceptions (io::Error for bad input);
/// warnings go to stderr.
#include <filesystem>
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
  int steps_per_period = 2048;     ///< time steps (= samples) per period
  int harmonics = 9;               ///< hb: harmonics 0 … K
  std::filesystem::path output_dir;
};

/// One record per frequency × amplitude: DIR/sine_f<freq>Hz_F<amp>N.csv.
void simulate(const SimulateOptions& options);

struct IdentifyOptions {
  std::filesystem::path model;
  std::vector<std::filesystem::path> records;
  std::filesystem::path output;
  std::vector<int> harmonics{1};
};

/// Identifies the joints' non-fixed terms from the records; writes the JSON result and prints
/// a table.
void identify(const IdentifyOptions& options);

struct ModesOptions {
  std::filesystem::path model;
  std::filesystem::path output_dir;
  int count = 10;
  int pictures = 4; ///< modes drawn in DIR/modes.png (0: no picture)
};

/// Writes DIR/modes.json with the lowest `count` natural frequencies (and warnings about
/// rigid-body modes or mechanisms), the VTK files of the mode shapes (DIR/modes.vtu,
/// DIR/mesh.vtu, DIR/mode_<r>.pvd animations) and DIR/modes.png with the first `pictures` modes.
/// The picture needs an X display (main() re-runs the command under xvfb-run when there is
/// none); without one it is skipped with a warning.
void modes(const ModesOptions& options);

} // namespace jointid::cli

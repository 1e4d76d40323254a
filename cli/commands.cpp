#include "cli/commands.hpp"

#include "fem/assembly.hpp"
#include "fem/damping.hpp"
#include "fem/modal.hpp"
#include "fem/time_integration.hpp"
#include "fem/zero_modes.hpp"
#include "frf/harmonic_balance.hpp"
#include "frf/receptance.hpp"
#include "identify/fit.hpp"
#include "identify/harmonics.hpp"
#include "io/files.hpp"
#include "io/model_file.hpp"
#include "io/record_csv.hpp"
#include "io/results_json.hpp"
#include "io/vtk_output.hpp"
#include "joints/joint.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <numbers>
#include <optional>
#include <set>
#include <span>
#include <stdexcept>

namespace jointid::cli {

namespace fs = std::filesystem;

namespace {

/// Up to this many equations every mode is computed by the dense eigensolver (as fem's
/// automatic engine choice); above it modal damping cannot be used in the time domain.
constexpr int dense_limit = 1500;

void warn(const std::string& what) {
  std::cerr << "jointid: warning: " << what << "\n";
}

// Numbers in file names and comments: the shortest form that reads back exactly (3.4, 80).
std::string compact(double value) {
  return fmt::format("{}", value);
}

void add_unique(std::vector<int>& list, int value) {
  if (std::find(list.begin(), list.end(), value) == list.end()) list.push_back(value);
}

void check_output_dir(const fs::path& dir) {
  std::error_code ec;
  if (dir.empty()) throw io::Error("-o: expected a directory");
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw io::Error(fmt::format("-o {}: exists and is not a directory", dir.string()));
}

void make_output_dir(const fs::path& dir) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec)
    throw io::Error(fmt::format("{}: cannot create the directory: {}", dir.string(), ec.message()));
}

void check_output_file(const fs::path& file) {
  std::error_code ec;
  if (file.filename().empty() || fs::is_directory(file, ec))
    throw io::Error(fmt::format("-o {}: expected a file name, got a directory", file.string()));
  const fs::path parent = file.parent_path();
  if (!parent.empty() && !fs::is_directory(parent, ec))
    throw io::Error(
        fmt::format("-o {}: the directory {} does not exist", file.string(), parent.string()));
}

// Modes for modal synthesis (and modal damping): every mode when the dense solver can find
// them (the synthesis is then exact), else the modes below f_max_hz, the residual flexibility
// standing in for the others.
fem::Modes synthesis_modes(const fem::Assembled& system, double f_max_hz) {
  const bool all = system.dofs.num_equations() <= dense_limit;
  fem::ModalOptions options;
  if (all) {
    options.num_modes = 0;
    options.engine = fem::ModalEngine::dense;
  } else {
    options.max_frequency_hz = f_max_hz;
    options.engine = fem::ModalEngine::sparse;
  }
  fem::Modes modes = fem::modal_analysis(system, options);
  if (modes.status != fem::ModalStatus::success)
    throw std::runtime_error(
        modes.status == fem::ModalStatus::not_converging
            ? "modal analysis: the eigensolver did not converge"
            : "modal analysis: numerical issue (is the mass matrix positive definite?)");
  return modes;
}

std::string describe(const joints::Joint& j) {
  std::string text =
      fmt::format("joint '{}': {}:{} {}", j.name, j.node, fem::dof_name(j.dof),
                  j.to_ground() ? std::string("to ground") : fmt::format("to node {}", j.node_b));
  for (std::size_t t = 0; t < j.terms.size(); ++t)
    text += fmt::format("{} {} = {}", t == 0 ? ";" : ",", joints::term_name(j.terms[t]),
                        compact(j.values[t]));
  return text;
}

struct Output {
  fs::path path;
  identify::Record record;
  std::vector<std::string> comments;
};

} // namespace

void simulate(const SimulateOptions& o) {
  // 1. Everything that can be checked before computing.
  if (o.frequencies.empty()) throw io::Error("--freq: expected at least one frequency (Hz)");
  if (o.amplitudes.empty()) throw io::Error("--amplitude: expected at least one amplitude (N)");
  for (double f : o.frequencies)
    if (!(std::isfinite(f) && f > 0.0))
      throw io::Error(fmt::format("--freq: expected frequencies > 0 Hz, got {}", f));
  for (double a : o.amplitudes)
    if (!(std::isfinite(a) && a > 0.0))
      throw io::Error(
          fmt::format("--amplitude: expected finite amplitudes > 0 (N or N m), got {}", a));
  if (o.method != "time" && o.method != "hb")
    throw io::Error(fmt::format("--method: expected time or hb, got \"{}\"", o.method));
  if (o.periods < 1)
    throw io::Error(fmt::format("--periods: expected at least 1, got {}", o.periods));
  if (o.steps_per_period < 8)
    throw io::Error(
        fmt::format("--steps-per-period: expected at least 8, got {}", o.steps_per_period));
  if (o.harmonics < 1)
    throw io::Error(fmt::format("--harmonics: expected at least 1, got {}", o.harmonics));
  check_output_dir(o.output_dir);
  struct Test {
    double frequency_hz, amplitude;
    std::string file;
  };
  std::vector<Test> tests;
  std::set<std::string> names;
  for (double f : o.frequencies)
    for (double a : o.amplitudes) {
      std::string file = fmt::format("sine_f{}Hz_F{}N.csv", compact(f), compact(a));
      if (!names.insert(file).second)
        throw io::Error(fmt::format("--freq, --amplitude: the test at {} Hz, {} N is listed twice",
                                    compact(f), compact(a)));
      tests.push_back({f, a, std::move(file)});
    }

  const io::ModelFile file = io::read_model(o.model);
  const fem::Model& model = file.model;
  const fem::Assembled system = fem::assemble(model);
  fem::NodeDof force_at;
  int force_equation = -1;
  try {
    force_at = io::resolve_node_dof(file, o.force);
    force_equation = system.dofs.equation(force_at);
  } catch (const std::invalid_argument& e) {
    throw io::Error(fmt::format("--force {}: {} (expected NODE:DOF of a free DOF of {}, e.g. "
                                "7:uy, or a one-node Gmsh group such as tip:uy)",
                                o.force, e.what(), o.model.string()));
  }
  // Outputs: every joint DOF, then the force DOF.
  std::vector<int> outputs;
  for (const auto& j : file.joints) {
    add_unique(outputs, system.dofs.equation({j.node, j.dof}));
    if (!j.to_ground()) add_unique(outputs, system.dofs.equation({j.node_b, j.dof}));
  }
  add_unique(outputs, force_equation);

  // 2. The substructure's modes where needed: modal damping in the time domain, and the
  // harmonic balance's modal synthesis.
  const int n = system.dofs.num_equations();
  const bool time_domain = o.method == "time";
  const double f_max = *std::max_element(o.frequencies.begin(), o.frequencies.end());
  std::optional<fem::Modes> modes;
  if (time_domain && model.damping.kind == fem::Damping::Kind::modal) {
    if (n > dense_limit)
      throw io::Error(fmt::format(
          "{}: modal damping in a time simulation needs every mode, and the model has {} "
          "equations (more than {}); use [damping] rayleigh = [alpha, beta]",
          o.model.string(), n, dense_limit));
    modes = synthesis_modes(system, 0.0);
  }
  if (!time_domain) modes = synthesis_modes(system, 4.0 * o.harmonics * f_max);

  // 3. Simulate every test, keeping the records in memory: nothing is written unless all succeed.
  const std::vector<std::string> common{"jointid simulate", "model: " + o.model.string()};
  std::vector<Output> outs;
  auto make_record = [&](const Test& test, const Eigen::VectorXd& t, const Eigen::VectorXd& force,
                         const Eigen::MatrixXd& u, const Eigen::MatrixXd& v) {
    identify::Record r;
    r.source = test.file;
    r.t = t;
    r.excitation_hz = test.frequency_hz;
    r.channels.push_back({identify::Quantity::force, force_at, force});
    for (std::size_t j = 0; j < outputs.size(); ++j) {
      const fem::NodeDof at = system.dofs.node_dof(outputs[j]);
      r.channels.push_back(
          {identify::Quantity::displacement, at, u.col(static_cast<Eigen::Index>(j))});
      r.channels.push_back({identify::Quantity::velocity, at, v.col(static_cast<Eigen::Index>(j))});
    }
    std::vector<std::string> comments = common;
    comments.push_back(fmt::format("sine force {} N (peak) at {} Hz on {}", compact(test.amplitude),
                                   compact(test.frequency_hz), fem::to_string(force_at)));
    for (const auto& j : file.joints)
      comments.push_back(describe(j));
    return Output{o.output_dir / test.file, std::move(r), std::move(comments)};
  };

  if (time_domain) {
    const fem::SparseMatrix C =
        fem::damping_matrix(system, model.damping, modes ? &*modes : nullptr);
    const joints::JointForces forces(file.joints, system.dofs);
    fem::SteadyStateOptions options;
    options.steps_per_period = o.steps_per_period;
    options.output_periods = o.periods;
    options.max_periods = std::max(options.max_periods, o.periods + 2);
    for (const Test& test : tests) {
      const fem::SteadyState s =
          fem::steady_state(system, C, &forces, {force_equation, test.amplitude, test.frequency_hz},
                            outputs, options);
      if (s.status == fem::SteadyStateStatus::newton_failed)
        throw std::runtime_error(
            fmt::format("time integration at {} Hz, {} N: the joints' Newton iteration failed in "
                        "period {}",
                        compact(test.frequency_hz), compact(test.amplitude), s.periods_run));
      Output out = make_record(test, s.t, s.force, s.u, s.v);
      out.comments.push_back(fmt::format(
          "method: time (Newmark, average acceleration, {} steps per period)", o.steps_per_period));
      const bool converged = s.status == fem::SteadyStateStatus::converged;
      out.comments.push_back(fmt::format(
          "periods run: {} from rest ({}; last period-to-period change {:.3g}); the record "
          "holds the last {}",
          s.periods_run, converged ? "steady state reached" : "NOT periodic", s.period_change,
          o.periods));
      if (!converged) {
        const std::string what =
            fmt::format("{}: not a periodic steady state after {} periods (last period-to-period "
                        "change {:.3g})",
                        test.file, s.periods_run, s.period_change);
        out.comments.push_back("WARNING: " + what);
        warn(what);
      }
      outs.push_back(std::move(out));
    }
  } else {
    const frf::ModalSynthesis synthesis(system, *modes, model.damping, outputs);
    frf::HarmonicBalanceOptions options;
    options.harmonics = o.harmonics;
    for (const Test& test : tests) {
      const frf::HarmonicBalanceResult hb =
          frf::harmonic_balance(synthesis, file.joints, system.dofs, force_equation, test.amplitude,
                                test.frequency_hz, outputs, options);
      const int samples = o.periods * o.steps_per_period;
      const double h = 1.0 / (test.frequency_hz * o.steps_per_period);
      const double omega = 2.0 * std::numbers::pi * test.frequency_hz;
      Eigen::VectorXd t(samples), force(samples);
      Eigen::MatrixXd u(samples, static_cast<Eigen::Index>(outputs.size())), v(u.rows(), u.cols());
      for (int i = 0; i < samples; ++i) {
        t(i) = i * h;
        force(i) = test.amplitude * std::sin(omega * t(i));
        for (Eigen::Index j = 0; j < u.cols(); ++j) {
          u(i, j) = hb.displacement(static_cast<int>(j), t(i));
          v(i, j) = hb.velocity(static_cast<int>(j), t(i));
        }
      }
      Output out = make_record(test, t, force, u, v);
      out.comments.push_back(fmt::format(
          "method: hb (harmonic balance, harmonics 0 to {}; modal synthesis of {} of {} "
          "modes{})",
          o.harmonics, modes->num_modes(), n,
          synthesis.has_residual() ? ", residual flexibility" : ""));
      out.comments.push_back(fmt::format(
          "harmonic balance: {} after {} iterations (relative residual {:.3g}); {} "
          "periods sampled from the harmonics",
          hb.converged ? "converged" : "NOT converged", hb.iterations, hb.residual, o.periods));
      if (!hb.converged) {
        const std::string what =
            fmt::format("{}: the harmonic balance did not converge (relative residual {:.3g})",
                        test.file, hb.residual);
        out.comments.push_back("WARNING: " + what);
        warn(what);
      }
      outs.push_back(std::move(out));
    }
  }

  // 4. Write.
  std::vector<std::string> texts;
  for (const auto& out : outs)
    texts.push_back(io::record_csv(out.record, out.comments));
  make_output_dir(o.output_dir);
  for (std::size_t i = 0; i < outs.size(); ++i) {
    io::write_file_atomically(outs[i].path, texts[i]);
    fmt::print("wrote {}\n", outs[i].path.string());
  }
}

void identify(const IdentifyOptions& o) {
  if (o.records.empty()) throw io::Error("expected at least one record (CSV file)");
  if (o.harmonics.empty())
    throw io::Error("--harmonics: expected at least one harmonic, e.g. 1,2,3");
  std::set<int> seen;
  for (int k : o.harmonics) {
    if (k < 0 || k > 50)
      throw io::Error(fmt::format("--harmonics: expected harmonics from 0 to 50, got {}", k));
    if (!seen.insert(k).second)
      throw io::Error(fmt::format("--harmonics: harmonic {} is listed twice", k));
  }
  check_output_file(o.output);

  const io::ModelFile file = io::read_model(o.model);
  if (file.joints.empty()) throw io::Error(o.model.string() + ": no [[joints]] to identify");
  const std::vector<identify::Record> records = io::read_records(o.records);
  const fem::Assembled system = fem::assemble(file.model);
  for (const auto& r : records)
    io::check_record_channels(r, system.dofs, file.joints);

  // Receptance over the joints' DOFs and the force DOFs.
  std::vector<int> dofs = identify::joint_dof_set(file.joints, system.dofs);
  for (const auto& r : records)
    for (const identify::Channel* f : r.all(identify::Quantity::force))
      add_unique(dofs, system.dofs.equation(f->at));
  double f_max = 0.0; // only needed when the modes are truncated
  if (system.dofs.num_equations() > dense_limit)
    for (const auto& r : records)
      f_max =
          std::max(f_max, r.excitation_hz ? *r.excitation_hz
                                          : identify::estimate_frequency(
                                                r.t, r.all(identify::Quantity::force)[0]->samples));
  const int max_harmonic = std::max(1, *std::max_element(o.harmonics.begin(), o.harmonics.end()));
  const fem::Modes modes = synthesis_modes(system, 4.0 * max_harmonic * f_max);
  const frf::ModalSynthesis synthesis(system, modes, file.model.damping, dofs);
  std::vector<std::string> extra;
  if (modes.num_modes() < system.dofs.num_equations() && !synthesis.has_residual())
    extra.push_back(fmt::format(
        "receptance from {} of {} modes without residual flexibility (the model has rigid-body "
        "modes): the modes left out are ignored",
        modes.num_modes(), system.dofs.num_equations()));
  const identify::ReceptanceFn H = [&synthesis](double omega, std::span<const int> rows,
                                                std::span<const int> cols) {
    return synthesis.receptance(omega, rows, cols);
  };
  identify::FitOptions options;
  options.harmonics = o.harmonics;
  const identify::FitResult result = identify::fit(H, system.dofs, file.joints, records, options);

  io::write_json(o.output, io::identify_result_json(result, extra));

  fmt::print("{:<12} {:<5} {:<26} {:>14} {:>11}  {}\n", "joint", "term", "effect", "value", "std",
             "95 % interval");
  for (const auto& j : result.joints)
    for (const auto& t : j.terms)
      fmt::print("{:<12} {:<5} {:<26} {:>14.7g} {:>11.3g}  {}\n", j.name, joints::term_name(t.term),
                 joints::term_effect(t.term), t.value, t.std,
                 t.fixed ? std::string("(fixed)")
                         : fmt::format("[{:.7g}, {:.7g}]", t.ci_low, t.ci_high));
  fmt::print("{} equations, {} unknowns, condition number {:.3g}, residual {:.3g} m rms ({:.3g} "
             "relative)\n",
             result.equations, result.unknowns, result.condition_number, result.residual_rms,
             result.residual_relative);
  fmt::print("wrote {}\n", o.output.string());
  for (const auto& w : result.warnings)
    warn(w);
  for (const auto& w : extra)
    warn(w);
}

void modes(const ModesOptions& o) {
  if (o.count < 1) throw io::Error(fmt::format("--count: expected at least 1, got {}", o.count));
  check_output_dir(o.output_dir);
  const io::ModelFile file = io::read_model(o.model);
  const fem::Assembled system = fem::assemble(file.model);
  const int count = std::min(o.count, system.dofs.num_equations());
  fem::ModalOptions options;
  options.num_modes = count;
  const fem::Modes modes = fem::modal_analysis(system, options);
  if (modes.status != fem::ModalStatus::success)
    throw std::runtime_error(modes.status == fem::ModalStatus::not_converging
                                 ? "modal analysis did not converge"
                                 : "modal analysis failed: the mass matrix is not positive "
                                   "definite (a DOF without mass?)");
  std::vector<std::string> warnings;
  if (const fem::ZeroModes z = fem::zero_modes(file.model, system, modes); z.count > 0)
    warnings.push_back(z.describe());
  make_output_dir(o.output_dir);
  const fs::path out = o.output_dir / "modes.json";
  io::write_json(out, io::modes_json(modes, count, warnings));
  io::write_modes_vtk(o.output_dir, file.model, system.dofs, modes);
  fmt::print("{:>5} {:>16}\n", "mode", "frequency (Hz)");
  for (int r = 0; r < std::min(count, modes.num_modes()); ++r)
    fmt::print("{:>5} {:>16.8g}\n", r + 1, modes.frequency_hz(r));
  fmt::print("wrote {}, {} and {} (ParaView)\n", out.string(),
             (o.output_dir / "modes.vtu").string(), (o.output_dir / "mode_<r>.pvd").string());
  if (o.pictures > 0) {
    const fs::path png = o.output_dir / "modes.png";
    const char* display = std::getenv("DISPLAY");
    if (display && *display) {
      io::render_modes_png(png, file.model, system.dofs, modes,
                           std::min(o.pictures, modes.num_modes()));
      fmt::print("wrote {}\n", png.string());
    } else {
      warnings.push_back(
          "no X display: modes.png not drawn (install xvfb, or run under xvfb-run -a)");
    }
  }
  for (const auto& w : warnings)
    warn(w);
}

} // namespace jointid::cli

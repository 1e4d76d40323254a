#include "cli/command.hpp"

#include "cli/common.hpp"
#include "io/files.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

namespace jointid::cli {

namespace {

std::vector<std::string> renamed;

// "a, b or c".
std::string either(const std::vector<std::string>& names) {
  std::string text;
  for (std::size_t i = 0; i < names.size(); ++i)
    text += (i == 0 ? "" : i + 1 == names.size() ? " or " : ", ") + names[i];
  return text;
}

} // namespace

CLI::Validator choices(const std::vector<std::string>& names) {
  return CLI::Validator(
      [names](std::string& value) {
        if (std::find(names.begin(), names.end(), value) != names.end()) return std::string();
        return fmt::format("expected {}, got \"{}\"", either(names), value);
      },
      fmt::format("{{{}}}", fmt::join(names, ",")));
}

const std::vector<std::string>& renamed_options() {
  return renamed;
}

Command::Command(CLI::App& parent, const std::string& name, const std::string& description)
    : app_(parent.add_subcommand(name, description)) {}

void Command::add_model(const std::string& description) {
  app_->add_option("MODEL", model_, description)->required();
}

void Command::add_output_dir() {
  app_->add_option("-o,--output", output_dir_, "Output directory (created if missing)")->required();
}

void Command::add_engine(bool every_engine) {
  if (every_engine)
    app_->add_option("--engine", engine_,
                     "auto (dense up to 1500 equations, else CHOLMOD), dense, sparse (CHOLMOD) or "
                     "slepc (distributed, run under mpirun -np N; only rank 0 writes)")
        ->check(choices({"auto", "dense", "sparse", "slepc"}))
        ->capture_default_str();
  else
    app_->add_option("--engine", engine_,
                     "Modes of models above the dense limit: auto (CHOLMOD on this machine) or "
                     "slepc (distributed, run under mpirun -np N; only rank 0 writes)")
        ->check(choices({"auto", "slepc"}))
        ->capture_default_str();
}

void Command::add_no_plot(const std::string& what) {
  has_plot_ = true;
  app_->add_flag_callback(
      "--no-plot", [this] { plot_ = false; }, "Write no " + what);
  app_->add_flag_callback("--no-plots",
                          [this] {
                            plot_ = false;
                            renamed.push_back("--no-plots is now --no-plot");
                          })
      ->group("");
}

void Command::add_harmonics(std::vector<int>& harmonics, const std::string& description) {
  app_->add_option("--harmonics", harmonics, description)
      ->delimiter(',')
      ->allow_extra_args(false)
      ->capture_default_str();
}

template <class T, class Set>
void Command::add_old_spelling(const std::string& old, const std::string& now, Set set) {
  app_->add_option_function<T>(
          old,
          [old, now, set](const T& value) {
            set(value);
            renamed.push_back(old + " is now " + now);
          },
          "Old spelling of " + now)
      ->group("");
}

void Command::add_balance_harmonics(int& harmonics, const std::string& description,
                                    bool was_harmonics) {
  app_->add_option("--balance-harmonics", harmonics, description)->capture_default_str();
  auto set = [&harmonics](const int& k) { harmonics = k; };
  add_old_spelling<int>("--hb-harmonics", "--balance-harmonics", set);
  if (was_harmonics) add_old_spelling<int>("--harmonics", "--balance-harmonics", set);
}

void TransientOptions::add_to(CLI::App& app, const std::string& which) {
  app.add_option("--route", route,
                 "modal: retained modes + static correction (fast); full: the whole FE model")
      ->check(choices({"modal", "full"}))
      ->capture_default_str();
  app.add_option("--modal-cutoff", modal_cutoff,
                 "Modal route: modes below this are integrated, Hz (0: the Nyquist frequency)")
      ->capture_default_str();
  app.add_option("--substeps", substeps, "Newmark steps per sample" + which)->capture_default_str();
}

void TransientOptions::apply(identify::ForcedOptions& options) const {
  options.route = parse_route(route);
  if (substeps < 1)
    throw io::Error(fmt::format("--substeps: expected at least 1, got {}", substeps));
  if (!(std::isfinite(modal_cutoff) && modal_cutoff >= 0.0))
    throw io::Error(fmt::format("--modal-cutoff: expected >= 0 Hz, got {}", modal_cutoff));
  options.substeps = substeps;
  options.modal_cutoff_hz = modal_cutoff;
}

} // namespace jointid::cli

#include "cli/common.hpp"

#include "io/arguments.hpp"

#include "frf/time_model.hpp"
#include "identify/fit.hpp"
#include "identify/parametric.hpp"
#include "io/files.hpp"
#include "joints/basis.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <iostream>
#include <set>
#include <stdexcept>

namespace jointid::cli {

namespace fs = std::filesystem;

void warn(const std::string& what) {
  std::cerr << "jointid: warning: " << what << "\n";
}

void require(const fem::Status& status) {
  if (!status.ok()) throw std::runtime_error(status.reason);
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

void check_output_file(const fs::path& file, const std::string& option) {
  std::error_code ec;
  if (file.filename().empty() || fs::is_directory(file, ec))
    throw io::Error(
        fmt::format("{} {}: expected a file name, got a directory", option, file.string()));
  const fs::path parent = file.parent_path();
  if (!parent.empty() && !fs::is_directory(parent, ec))
    throw io::Error(fmt::format("{} {}: the directory {} does not exist", option, file.string(),
                                parent.string()));
}

void require_values(const io::ModelFile& file, const std::string& command) {
  for (std::size_t i = 0; i < file.joints.size(); ++i) {
    const joints::Joint& j = file.joints[i];
    std::vector<std::string> missing;
    for (std::size_t t = 0; t < j.terms.size(); ++t)
      if (!j.has_value(t)) missing.emplace_back(joints::term_name(j.terms[t]));
    if (missing.empty()) continue;
    const int line = i < file.joint_lines.size() ? file.joint_lines[i] : 0;
    const std::string where =
        line > 0 ? fmt::format("{}:{}", file.path.string(), line) : file.path.string();
    throw io::Error(fmt::format(
        "{}: joint '{}': {} {} no value in 'values': {} runs the model with its joints at their "
        "values (identify or discover finds them from tests)",
        where, j.name, fmt::join(missing, ", "), missing.size() == 1 ? "has" : "have", command));
  }
}

void check_time_simulation(const io::ModelFile& file, const std::string& alternative) {
  std::string what;
  if (file.measured) what = "the substructure is given by measured FRFs ([frf])";
  for (std::size_t p = 0; p < file.parts.size() && what.empty(); ++p) {
    if (!file.parts[p].measured) continue;
    // The part's file as the model file names it (relative to its directory).
    fs::path part = file.parts[p].path.lexically_relative(file.path.parent_path());
    if (part.empty()) part = file.parts[p].path;
    what =
        fmt::format("substructure {} ({}) is given by measured FRFs ([frf])", p + 1, part.string());
  }
  if (what.empty()) return;
  throw io::Error(fmt::format("{}: {}{}", file.path.string(), frf::no_time_domain_model(what),
                              alternative.empty() ? "" : "; " + alternative));
}

void check_harmonics(const std::vector<int>& harmonics, int lowest) {
  io::check_harmonics("--harmonics", harmonics, lowest);
}

void check_balance_harmonics(int harmonics, int lowest, const std::string& why) {
  io::check_balance_harmonics("--balance-harmonics", harmonics, lowest, why);
}

void check_amplitudes(const std::vector<double>& amplitudes) {
  io::check_amplitudes("--amplitude", amplitudes);
}

void check_noise(double noise) {
  io::check_noise("--noise", noise);
}

std::pair<double, double> parse_pair(const std::string& option, const std::string& text,
                                     const char* example) {
  double f0 = 0.0, f1 = 0.0;
  const auto colon = text.find(':');
  bool ok = colon != std::string::npos;
  if (ok) {
    try {
      std::size_t n0 = 0, n1 = 0;
      const std::string a = text.substr(0, colon), b = text.substr(colon + 1);
      f0 = std::stod(a, &n0);
      f1 = std::stod(b, &n1);
      ok = n0 == a.size() && n1 == b.size() && std::isfinite(f0) && std::isfinite(f1);
    } catch (const std::exception&) {
      ok = false;
    }
  }
  if (!ok)
    throw io::Error(
        fmt::format("{}: expected F0:F1 in Hz, e.g. {}, got \"{}\"", option, example, text));
  return {f0, f1};
}

// "3", "1.5e3" or a range "F0:STEP:F1" (F0, F0 + STEP, … up to F1 within a millionth of STEP),
// every value finite and > 0; sorted, each once.
std::vector<double> parse_values(const std::string& option, const std::vector<std::string>& items,
                                 const char* unit) {
  auto refuse = [&](const std::string& item) {
    return io::Error(fmt::format("{}: expected numbers ({}) or ranges START:STEP:STOP, got \"{}\"",
                                 option, unit, item));
  };
  auto number = [&](const std::string& text, const std::string& item) {
    std::size_t used = 0;
    double v = 0.0;
    try {
      v = std::stod(text, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != text.size() || !std::isfinite(v)) throw refuse(item);
    return v;
  };
  std::vector<double> out;
  for (const auto& item : items) {
    std::vector<std::string> parts;
    std::size_t start = 0;
    for (std::size_t c = item.find(':'); c != std::string::npos; c = item.find(':', start)) {
      parts.push_back(item.substr(start, c - start));
      start = c + 1;
    }
    parts.push_back(item.substr(start));
    if (parts.size() == 1) {
      out.push_back(number(parts[0], item));
    } else if (parts.size() == 3) {
      const double a = number(parts[0], item), step = number(parts[1], item),
                   b = number(parts[2], item);
      if (!(step > 0.0) || b < a)
        throw io::Error(fmt::format(
            "{} {}: expected START:STEP:STOP with STEP > 0 and STOP >= START", option, item));
      const double n = std::floor((b - a) / step + 1e-6);
      if (n > 10000) throw io::Error(fmt::format("{} {}: more than 10000 values", option, item));
      for (int i = 0; i <= static_cast<int>(n); ++i)
        out.push_back(a + i * step);
    } else {
      throw refuse(item);
    }
  }
  if (out.empty())
    throw io::Error(fmt::format("{}: expected at least one value ({})", option, unit));
  for (double v : out)
    if (!(v > 0.0))
      throw io::Error(fmt::format("{}: expected values > 0 {}, got {}", option, unit, v));
  std::sort(out.begin(), out.end());
  if (std::adjacent_find(out.begin(), out.end()) != out.end())
    throw io::Error(fmt::format("{}: a value is listed twice", option));
  return out;
}

std::pair<double, double> parse_band(const std::string& option, const std::string& text) {
  const auto [f0, f1] = parse_pair(option, text, "2:40");
  if (!(f0 >= 0.0 && f1 > f0))
    throw io::Error(fmt::format("{}: expected 0 <= F0 < F1 (Hz), got {} and {}", option, f0, f1));
  return {f0, f1};
}

std::vector<identify::Quantity> parse_channels(const std::vector<std::string>& channels) {
  return io::parse_channels("--channels", channels);
}

identify::TransientRoute parse_route(const std::string& text) {
  if (text == "modal") return identify::TransientRoute::modal;
  if (text == "full") return identify::TransientRoute::full;
  throw io::Error(fmt::format("--route: expected modal or full, got \"{}\"", text));
}

Model::Model(const fs::path& path, Engine engine)
    : file(io::read_model(path)), sub(file.substructure()) {
  use_engine(sub, engine);
}

void check_identifiable(const Model& model, Parametric how) {
  const auto& joints = model.file.joints;
  const auto& lines = model.file.joint_lines;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const int line = i < lines.size() && lines.size() == joints.size() ? lines[i] : 0;
    const std::string where =
        line > 0 ? fmt::format("{}:{}: ", model.name(), line) : model.name() + ": ";
    const joints::Joint& j = joints[i];
    try {
      if (how == Parametric::output_error) {
        identify::check_one_parametric_term({j});
        continue;
      }
      if (how == Parametric::needs_output_error)
        for (std::size_t t = 0; t < j.terms.size(); ++t)
          if (joints::has_parameters(j.terms[t]) && !j.fixed[t]) {
            const std::string name(joints::term_name(j.terms[t]));
            throw std::invalid_argument(fmt::format(
                "joint '{}': term '{}' is not fixed: its parameters ({}) enter the joint's force "
                "non-linearly and need --output-error (a describing-function start, then output "
                "error); or, to identify the joint's other terms with this one known, give all "
                "of them in 'values' and list \"{}\" in 'fixed'",
                j.name, name, joints::parameter_names(j.terms[t]), name));
          }
      identify::check_identifiable({j});
    } catch (const std::invalid_argument& e) {
      throw io::Error(where + e.what());
    }
  }
}

fem::NodeDof Model::dof(const std::string& option, const std::string& text) const {
  try {
    const fem::NodeDof at = io::resolve_node_dof(file, text);
    sub.dofs().equation(at);
    return at;
  } catch (const std::invalid_argument& e) {
    throw io::Error(fmt::format("{} {}: {} (expected NODE:DOF of a free DOF of {}, e.g. 7:uy, or "
                                "a one-node Gmsh group such as tip:uy)",
                                option, text, e.what(), name()));
  }
}

void draw_chart(const fs::path& png, const std::function<report::Figure()>& figure) {
  std::string why;
  if (!report::can_render_charts(&why)) {
    warn("no " + png.string() + ": " + why + " (run under xvfb-run -a)");
    return;
  }
  try {
    report::write_chart_png(png, figure());
    fmt::print("wrote {}\n", png.string());
  } catch (const std::invalid_argument& e) {
    warn("no " + png.string() + ": " + e.what());
  }
}

void write_outputs(const std::vector<std::pair<fs::path, std::string>>& outputs) {
  io::OutputFiles files;
  for (const auto& [path, text] : outputs)
    files.add(path, text);
  files.commit();
  for (const auto& [path, text] : outputs)
    fmt::print("wrote {}\n", path.string());
}

} // namespace jointid::cli

// The paper's numerical study (METHOD.md): a 6-element cantilever with a non-linear joint
// between its free end and ground, models I (k, c, c2, k3) and II (k, c, fc, k3), sine-test
// cases I–IV. "Measured" responses come from implicit time integration of the FE model with
// the joint (exact stick–slip for friction) run to a periodic steady state; identification
// uses only those records and the modal FRFs of the substructure. Prints the paper's tables
// with the exact values, the paper's values and ours, and the relative errors.
//
//   paper_cantilever [MODEL.toml] [--steps N] [--json FILE] [--check]
#include "fem/damping.hpp"
#include "fem/time_integration.hpp"
#include "frf/receptance.hpp"
#include "identify/fit.hpp"
#include "identify/sine_tests.hpp"
#include "io/model_file.hpp"
#include "io/results_json.hpp"
#include "paper_cases.hpp"

#include <array>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

using namespace jointid;

namespace {

using Case = examples::PaperCase;
using examples::paper_cases;

struct PaperModel {
  const char* name;
  std::vector<joints::Term> terms;
  std::vector<double> exact;
  std::array<std::array<double, 4>, 4> paper; // [case][term], the paper's Tables 2 and 3
};

std::vector<PaperModel> paper_models() {
  using joints::Term;
  return {
      {"I",
       {Term::k, Term::c, Term::c2, Term::k3},
       {4800.0, 20.0, 500.0, 1.6e8},
       {{{4799.6, 20.003, 499.95, 1.6003e8},
         {4800.0, 20.063, 499.68, 1.5998e8},
         {4800.0, 20.000, 500.00, 1.6000e8},
         {4800.0, 20.000, 499.99, 1.5998e8}}}},
      {"II",
       {Term::k, Term::c, Term::fc, Term::k3},
       {4800.0, 20.0, 3.0, 1.6e8},
       {{{4707.3, 20.040, 2.9806, 1.6226e8},
         {4740.2, 20.068, 2.9192, 1.6146e8},
         {4754.2, 20.631, 2.9205, 1.6108e8},
         {4821.8, 20.054, 2.9784, 1.5940e8}}}},
  };
}

class PaperStudy {
public:
  PaperStudy(const std::string& model_path, int steps)
      : file_(io::read_model(model_path)), steps_(steps) {}

  nlohmann::json run() {
    setup_system();
    nlohmann::json out;
    out["substructure_modes_hz"] = {modes_.frequency_hz(0), modes_.frequency_hz(1),
                                    modes_.frequency_hz(2)};
    out["steps_per_period"] = steps_;
    const std::vector<Case> cases = paper_cases();
    for (const auto& model : paper_models()) {
      std::printf("\nModel %s: g = %s\n", model.name, describe(model).c_str());
      for (std::size_t c = 0; c < cases.size(); ++c) {
        const Case& test_case = cases[c];
        const auto records = measure(model, test_case);
        for (const std::vector<int>& harmonics : {std::vector<int>{1}, std::vector<int>{1, 2, 3}}) {
          const identify::FitResult r = identify(model, records, harmonics);
          print_table(model, test_case.name.c_str(), c, harmonics, r);
          if (harmonics.size() == 1)
            for (std::size_t t = 0; t < model.terms.size(); ++t)
              worst_[model.name] = std::max(
                  worst_[model.name], std::abs(r.joints[0].terms[t].value / model.exact[t] - 1.0));
          out["models"][model.name][test_case.name]
             [harmonics.size() == 1 ? "harmonic_1" : "harmonics_1_3"] =
                 nlohmann::json::parse(io::identify_result_json(r));
        }
      }
    }
    diagnose_stick_slip(out);
    return out;
  }

  /// The bars (fundamental only): model I within 0.05 %, model II within 1 %.
  bool check() const {
    bool ok = true;
    for (const auto& [name, limit] : {std::pair<std::string, double>{"I", 5e-4}, {"II", 1e-2}}) {
      const double worst = worst_.at(name);
      std::printf("check: model %s worst relative error %.4f %% (limit %.2f %%) %s\n", name.c_str(),
                  100 * worst, 100 * limit, worst <= limit ? "ok" : "FAILED");
      ok = ok && worst <= limit;
    }
    return ok;
  }

private:
  // Coulomb friction sticks near each velocity reversal at low frequency and force; while
  // stuck, the basis sign(ẏ) = 0 does not describe the force. Re-identify model II case I
  // with harmonics 1–3 from the tests at 2.2–4.6 Hz only (below 0.2 % stick) to show that
  // the stuck tests cause the bias.
  void diagnose_stick_slip(nlohmann::json& out) const {
    const PaperModel model = paper_models()[1];
    Case slipping{"I (2.2-4.6 Hz)", "2.2–4.6 Hz, 80 N", {}};
    for (int i = 3; i < 10; ++i)
      slipping.tests.push_back({1.0 + 0.4 * i, 80.0});
    const auto records = measure(model, slipping);
    std::printf(
        "\nStick-slip diagnosis, model II, case I without the tests that stick (1.0-1.8 Hz):\n");
    const identify::FitResult r = identify(model, records, {1, 2, 3});
    print_table(model, "I*", 0, {1, 2, 3}, r);
    out["stick_slip_diagnosis"] = nlohmann::json::parse(io::identify_result_json(r));
  }

  // Step 1: the substructure — assemble, all modes, FRF synthesis.
  void setup_system() {
    if (file_.joints.size() != 1)
      throw std::runtime_error("the paper study expects one joint in the model file");
    substructure_.emplace(file_.substructure());
    const fem::Assembled& system = *substructure_->system();
    modes_ = fem::modal_analysis(system, {.num_modes = 3});
    if (!modes_.status.ok())
      throw std::runtime_error("modal analysis failed: " + modes_.status.reason);
    tip_ = system.dofs.equation({file_.joints[0].node, file_.joints[0].dof});
    synthesis_.emplace(substructure_->synthesis({tip_}, 0.0));
    std::printf("Substructure: %d DOFs, modes %.4f Hz, %.4f Hz, %.4f Hz (modal damping %.3g)\n",
                system.dofs.num_equations(), modes_.frequency_hz(0), modes_.frequency_hz(1),
                modes_.frequency_hz(2), file_.model.damping.modal_ratio);
  }

  joints::Joint joint_of(const PaperModel& m) const {
    joints::Joint j = file_.joints[0];
    j.terms = m.terms;
    j.values = m.exact;
    j.fixed.assign(m.terms.size(), false);
    return j;
  }

  // Step 2: "measure" every test of a case by time integration to the periodic steady state.
  std::vector<identify::Record> measure(const PaperModel& m, const Case& c) const {
    const std::vector<identify::SineTestPlan>& plans = c.tests;
    identify::SimulationOptions options;
    options.steps_per_period = steps_;
    options.periods = 4;
    const fem::NodeDof tip = substructure_->dofs().node_dof(tip_);
    std::vector<identify::Record> records;
    for (auto& test :
         identify::simulate_sine_tests(*substructure_, {joint_of(m)}, tip, plans, options)) {
      if (!test.status.ok()) throw std::runtime_error(test.status.reason);
      if (!test.warnings.empty()) throw std::runtime_error(test.warnings.front());
      records.push_back(std::move(test.record));
    }
    return records;
  }

  // Step 3: identify the joint from the records and the substructure's FRFs.
  identify::FitResult identify(const PaperModel& m, const std::vector<identify::Record>& records,
                               const std::vector<int>& harmonics) const {
    const identify::ReceptanceFn H = [this](double w, std::span<const int> rows,
                                            std::span<const int> cols) {
      return synthesis_->receptance(w, rows, cols);
    };
    return identify::fit(H, substructure_->dofs(), {joint_of(m)}, records,
                         {.harmonics = harmonics});
  }

  // Step 4: the paper's table with our values and errors.
  static void print_table(const PaperModel& m, const char* case_name, std::size_t c,
                          const std::vector<int>& harmonics, const identify::FitResult& r) {
    std::printf("  case %-3s harmonics %-5s  %-4s %14s %14s %9s %14s %9s\n", case_name,
                harmonics.size() == 1 ? "1" : "1-3", "term", "exact", "paper", "paper err",
                "jointid", "our err");
    for (std::size_t t = 0; t < m.terms.size(); ++t) {
      const double exact = m.exact[t], paper = m.paper[c][t], ours = r.joints[0].terms[t].value;
      std::printf("  %25s %-4s %14.6g %14.6g %8.3f%% %14.8g %8.4f%%\n", "",
                  std::string(joints::term_name(m.terms[t])).c_str(), exact, paper,
                  100.0 * (paper - exact) / exact, ours, 100.0 * (ours - exact) / exact);
    }
    std::printf("  %25s equations %d, condition %.3g, residual %.3g (relative)\n", "", r.equations,
                r.condition_number, r.residual_relative);
    for (const auto& w : r.warnings)
      std::printf("  %25s warning: %s\n", "", w.c_str());
  }

  static std::string describe(const PaperModel& m) {
    std::string s;
    for (std::size_t t = 0; t < m.terms.size(); ++t)
      s += std::string(t ? " + " : "") + std::string(joints::term_name(m.terms[t])) + "·" +
           std::string(joints::term_effect(m.terms[t]));
    return s;
  }

  io::ModelFile file_;
  int steps_;
  std::optional<frf::Substructure> substructure_;
  fem::Modes modes_;
  int tip_ = 0;
  std::optional<frf::ModalSynthesis> synthesis_;
  std::map<std::string, double> worst_;
};

} // namespace

int main(int argc, char** argv) {
  try {
    std::string model = JOINTID_PAPER_MODEL, json_path;
    int steps = 2048;
    bool check = false;
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      if (a == "--steps" && i + 1 < argc)
        steps = std::stoi(argv[++i]);
      else if (a == "--check")
        check = true;
      else if (a == "--json" && i + 1 < argc)
        json_path = argv[++i];
      else if (a == "--help" || a == "-h") {
        std::puts("paper_cantilever [MODEL.toml] [--steps N (time steps per period, default 2048)] "
                  "[--json FILE]\n"
                  "  [--check: exit 2 unless model I is within 0.05 % and model II within 1 %]");
        return 0;
      } else
        model = a;
    }
    PaperStudy study(model, steps);
    const nlohmann::json result = study.run();
    if (!json_path.empty()) io::write_json(json_path, result.dump(2));
    return check && !study.check() ? 2 : 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "paper_cantilever: %s\n", e.what());
    return 1;
  }
}

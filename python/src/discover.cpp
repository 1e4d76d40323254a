// jointid.discover (as `jointid discover`, without its report files) and its result.
#include "common.hpp"

#include "discover/discover.hpp"
#include "joints/basis.hpp"
#include "report/discovery_json.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace jointid::python {

namespace {

struct DiscoveryResult {
  discover::Result result;
};

DiscoveryResult discover_terms(const ModelPtr& model, const py::object& tests_given,
                               const std::vector<int>& harmonics,
                               const py::object& balance_harmonics, int max_steps,
                               const py::object& terms, bool damping_candidate,
                               int max_balance_lines) {
  // 1. The arguments, as `jointid discover` checks its options.
  discover::Options options;
  options.harmonics = harmonics;
  check_harmonics(options.harmonics, 1);
  const int K = *std::max_element(options.harmonics.begin(), options.harmonics.end());
  if (!balance_harmonics.is_none()) options.balance.harmonics = balance_harmonics.cast<int>();
  check_balance_harmonics(options.balance.harmonics, K, "the largest of harmonics");
  if (max_steps < 1)
    throw io::Error(fmt::format("max_steps: expected at least 1, got {}", max_steps));
  options.max_steps = max_steps;
  if (max_balance_lines < 1)
    throw io::Error(
        fmt::format("max_balance_lines: expected at least 1, got {}", max_balance_lines));
  options.max_balance_lines = max_balance_lines;
  if (!terms.is_none()) {
    options.terms.clear();
    for (const std::string& t : strings(terms, "terms")) {
      try {
        options.terms.push_back(joints::parse_term(t));
      } catch (const std::invalid_argument&) {
        std::vector<std::string> names;
        for (const joints::Term all : joints::all_terms)
          names.emplace_back(joints::term_name(all));
        throw io::Error(fmt::format("terms: expected {} or {}, got \"{}\"",
                                    fmt::join(names.begin(), names.end() - 1, ", "), names.back(),
                                    t));
      }
    }
  }
  options.substructure_damping = damping_candidate;
  if (model->file.joints.empty())
    throw io::Error(model->name() + ": no [[joints]]: discovery starts from the joints' terms");
  const std::vector<TestPtr> tests = tests_of(tests_given);

  // 2. Discover; Ctrl-C is looked for before every re-simulation.
  return released([&](InterruptCheck& check) {
    const std::lock_guard<std::mutex> lock(model->busy);
    options.checkpoint = [&check] { check(); };
    const std::vector<identify::Measurement> measured = measure(tests, {.harmonics = K});
    return DiscoveryResult{discover::discover(model->sub, model->file.joints, measured, options)};
  });
}

} // namespace

void bind_discover(py::module_& m) {
  py::class_<DiscoveryResult>(m, "DiscoveryResult",
                              "Model discovery's result (jointid.discover): the steps, the gap "
                              "after each, the final model and the diagnosis.")
      .def_property_readonly(
          "gap", [](const DiscoveryResult& self) { return to_numpy(self.result.gap); },
          "The gap after each step, gap[0] the starting model's.")
      .def_property_readonly(
          "noise_gap",
          [](const DiscoveryResult& self) -> py::object {
            if (self.result.noise_gap < 0.0) return py::none();
            return py::float_(self.result.noise_gap);
          },
          "The gap a perfect model would leave (the noise); None when unknown (tables).")
      .def_property_readonly("at_noise_level",
                             [](const DiscoveryResult& self) { return self.result.at_noise_level; })
      .def_property_readonly(
          "steps",
          [](const DiscoveryResult& self) {
            py::list out;
            for (const auto& s : self.result.steps) {
              py::dict d;
              d["action"] = s.removed ? "removed" : "added";
              d["joint"] = s.added.joint;
              d["term"] = s.added.term ? std::string(joints::term_name(*s.added.term))
                                       : std::string("damping_scale");
              if (s.added.with) // a second parametric term added with it (jenkins with gap)
                d["with"] = std::string(joints::term_name(*s.added.with));
              d["effect"] = s.added.effect();
              d["value"] = s.added.value;
              d["ci95"] = py::make_tuple(s.added.ci_low, s.added.ci_high);
              d["gap_before"] = s.gap_before;
              d["gap_after"] = s.gap_after;
              d["finding"] = s.finding;
              out.append(d);
            }
            return out;
          },
          "The terms added, one dict per step: action (\"added\", or \"removed\": a term taken "
          "out again after the forward search), joint, term (and with: a second parametric term "
          "added together), effect, value, ci95, gap_before, gap_after, finding.")
      .def_property_readonly(
          "final_joints",
          [](const DiscoveryResult& self) {
            return joint_dicts(self.result.states.back().joints, true);
          },
          "The final model's joints, as the model file's [[joints]].")
      .def_property_readonly(
          "damping_scale",
          [](const DiscoveryResult& self) { return self.result.states.back().damping_scale; },
          "The final model's scale on the substructure's damping.")
      .def_property_readonly(
          "findings", [](const DiscoveryResult& self) { return self.result.diagnosis.findings; },
          "The diagnosis in sentences, the run's summary last.")
      .def_property_readonly("stop_reason",
                             [](const DiscoveryResult& self) { return self.result.stop_reason; })
      .def_property_readonly("warnings",
                             [](const DiscoveryResult& self) { return self.result.warnings; })
      .def(
          "to_dict",
          [](const DiscoveryResult& self) {
            return py::module_::import("json").attr("loads")(report::discovery_json(self.result));
          },
          "The result as `jointid discover` writes DIR/discovery.json.")
      .def("__repr__", [](const DiscoveryResult& self) {
        std::vector<std::string> added;
        for (const auto& s : self.result.steps)
          added.push_back((s.removed ? "− " : "") + s.added.name());
        return fmt::format("<jointid.DiscoveryResult: {} step{}{}{}, gap {:.4g} → {:.4g}>",
                           self.result.steps.size(), self.result.steps.size() == 1 ? "" : "s",
                           added.empty() ? "" : ": ", fmt::join(added, ", "),
                           self.result.gap.front(), self.result.gap.back());
      });

  m.def(
      "discover",
      [](const ModelPtr& model, const py::object& tests, const py::object& harmonics,
         const py::object& balance_harmonics, int max_steps, const py::object& terms,
         bool damping_candidate, int max_balance_lines) {
        return discover_terms(model, tests, integers(harmonics, "harmonics"), balance_harmonics,
                              max_steps, terms, damping_candidate, max_balance_lines);
      },
      py::arg("model"), py::arg("tests"), py::kw_only(),
      py::arg("harmonics") = discover::Options{}.harmonics,
      py::arg("balance_harmonics") = py::none(),
      py::arg("max_steps") = discover::Options{}.max_steps, py::arg("terms") = py::none(),
      py::arg("damping_candidate") = true,
      py::arg("max_balance_lines") = discover::Options{}.max_balance_lines,
      "Model discovery (as `jointid discover`): from the model's joints, adds the missing joint "
      "terms one at a time while they explain the gap between the tests and the model's "
      "re-simulation of them. terms: the candidate terms (default: all); damping_candidate: "
      "also try scaling the substructure's damping. Ctrl-C stops it.");
}

} // namespace jointid::python

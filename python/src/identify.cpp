// jointid.identify (as `jointid identify`) and its result.
#include "common.hpp"

#include "identify/fit.hpp"
#include "identify/output_error.hpp"
#include "io/results_json.hpp"
#include "joints/basis.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace jointid::python {

namespace {

struct IdentifyResult {
  identify::FitResult result;
  std::vector<identify::Measurement> measured; ///< the tests as the fit saw them
  std::vector<joints::Joint> joints;           ///< the model's joints with the values identified
};

// {joint: {term: what(term)}} over every joint and term of the result.
template <class What> py::dict by_joint(const identify::FitResult& r, What&& what) {
  py::dict out;
  for (const auto& j : r.joints) {
    py::dict terms;
    for (const auto& t : j.terms)
      terms[py::str(std::string(joints::term_name(t.term)))] = what(t);
    out[py::str(j.name)] = terms;
  }
  return out;
}

IdentifyResult identify_joints(const ModelPtr& model, const py::object& tests_given,
                               const std::vector<int>& harmonics, bool output_error,
                               const py::object& balance_harmonics) {
  // 1. The arguments, as `jointid identify` checks its options.
  identify::FitOptions fit;
  fit.harmonics = harmonics;
  check_harmonics(fit.harmonics, 0);
  identify::OutputErrorOptions refined;
  if (!balance_harmonics.is_none()) refined.balance.harmonics = balance_harmonics.cast<int>();
  if (output_error) {
    const int K = *std::max_element(fit.harmonics.begin(), fit.harmonics.end());
    check_balance_harmonics(refined.balance.harmonics, std::max(K, 1), "the largest of harmonics");
  }
  if (model->file.joints.empty()) throw io::Error(model->name() + ": no [[joints]] to identify");
  const std::vector<TestPtr> tests = tests_of(tests_given);

  // 2. The tests reduced, and the fit: a status other than ok is the reason, raised whole.
  refined.harmonics = fit.harmonics;
  return released([&](InterruptCheck&) {
    const std::lock_guard<std::mutex> lock(model->busy);
    IdentifyResult out;
    out.measured = measure(tests, identify::measure_options(fit));
    out.result = output_error ? identify::output_error(model->sub, model->file.joints, out.measured,
                                                       fit, refined)
                              : identify::fit(model->sub, model->file.joints, out.measured, fit);
    if (!out.result.status.ok()) throw io::Error("identify: " + out.result.status.reason);
    out.joints = out.result.identified(model->file.joints);
    return out;
  });
}

} // namespace

void bind_identify(py::module_& m) {
  py::class_<IdentifyResult>(m, "IdentifyResult",
                             "The joints' terms identified from the tests (jointid.identify).")
      .def_property_readonly(
          "values",
          [](const IdentifyResult& self) {
            return by_joint(self.result, [](const identify::TermEstimate& t) { return t.value; });
          },
          "{joint: {term: value}} (SI; fixed terms at the model's values).")
      .def_property_readonly(
          "std",
          [](const IdentifyResult& self) {
            return by_joint(self.result, [](const identify::TermEstimate& t) { return t.std; });
          },
          "{joint: {term: standard deviation}}")
      .def_property_readonly(
          "ci95",
          [](const IdentifyResult& self) {
            return by_joint(self.result, [](const identify::TermEstimate& t) {
              return py::make_tuple(t.ci_low, t.ci_high);
            });
          },
          "{joint: {term: (low, high)}}: the 95 % confidence intervals.")
      .def_property_readonly(
          "warnings", [](const IdentifyResult& self) { return self.result.warnings; },
          "What the tests and the fit warn about (as `jointid identify` prints them).")
      .def_property_readonly(
          "identifiability", [](const IdentifyResult& self) { return self.result.identifiability; },
          "What the tests do not determine, in words.")
      .def_property_readonly(
          "interval_method", [](const IdentifyResult& self) { return self.result.interval_method; },
          "How the intervals were found: \"propagated noise\", \"residual\" or \"output error\".")
      .def_property_readonly("equations",
                             [](const IdentifyResult& self) { return self.result.equations; })
      .def_property_readonly("unknowns",
                             [](const IdentifyResult& self) { return self.result.unknowns; })
      .def_property_readonly(
          "condition_number",
          [](const IdentifyResult& self) { return self.result.condition_number; })
      .def_property_readonly("residual_rms",
                             [](const IdentifyResult& self) { return self.result.residual_rms; })
      .def_property_readonly(
          "singular_values",
          [](const IdentifyResult& self) { return to_numpy(self.result.singular_values); })
      .def_property_readonly(
          "joints", [](const IdentifyResult& self) { return joint_dicts(self.joints, true); },
          "The model's joints with the identified values, as the model file's [[joints]].")
      .def(
          "to_dict",
          [](const IdentifyResult& self) {
            return py::module_::import("json").attr("loads")(
                io::identify_result_json(self.result, {}, &self.measured));
          },
          "The result as `jointid identify` writes its JSON file.")
      .def("__repr__", [](const IdentifyResult& self) {
        std::vector<std::string> terms;
        for (const auto& j : self.result.joints)
          for (const auto& t : j.terms)
            terms.push_back(
                fmt::format("{}.{} = {:.7g}", j.name, joints::term_name(t.term), t.value));
        return fmt::format("<jointid.IdentifyResult: {}; {} equations, {} warnings>",
                           fmt::join(terms, ", "), self.result.equations,
                           self.result.warnings.size());
      });

  m.def(
      "identify",
      [](const ModelPtr& model, const py::object& tests, const py::object& harmonics,
         bool output_error, const py::object& balance_harmonics) {
        return identify_joints(model, tests, integers(harmonics, "harmonics"), output_error,
                               balance_harmonics);
      },
      py::arg("model"), py::arg("tests"), py::kw_only(), py::arg("harmonics") = std::vector<int>{1},
      py::arg("output_error") = false, py::arg("balance_harmonics") = py::none(),
      "Identifies the joints' non-fixed terms from sine tests (as `jointid identify`): `tests` "
      "is a list of Records, SteppedSineRows and paths of files (CSV records, stepped-sine "
      "tables, universal files). harmonics: those whose equations are used; output_error: "
      "refine by output error (maximum likelihood), with a harmonic balance of "
      "balance_harmonics.");
}

} // namespace jointid::python

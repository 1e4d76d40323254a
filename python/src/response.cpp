// jointid.response (as `jointid response`, without its picture) and its curves.
#include "common.hpp"

#include "frf/continuation.hpp"
#include "io/response_curves.hpp"

#include <pybind11/complex.h>

#include <fmt/format.h>

#include <cmath>
#include <set>

namespace jointid::python {

namespace {

struct ResponseCurves {
  frf::ResponseCurves curves;
};

/// One branch's points as arrays (copies: each point is a steady state of its own).
struct ResponseBranch {
  double amplitude = 0.0;
  py::array_t<double> freq_hz;
  py::array_t<std::complex<double>> X;
  py::list stable;
  py::array_t<double> max_multiplier;
  std::vector<bool> stability_checked;
  std::vector<int> folds;
  bool complete = false;
  std::vector<std::string> notes;
};

ResponseBranch branch_of(const frf::ResponseBranch& b, double amplitude, int harmonics,
                         std::size_t dofs) {
  ResponseBranch out;
  out.amplitude = amplitude;
  const auto n = static_cast<py::ssize_t>(b.points.size());
  const auto k = static_cast<py::ssize_t>(harmonics + 1), d = static_cast<py::ssize_t>(dofs);
  out.freq_hz = py::array_t<double>(n);
  out.max_multiplier = py::array_t<double>(n);
  out.X = py::array_t<std::complex<double>>({n, k, d});
  std::complex<double>* X = out.X.mutable_data();
  for (py::ssize_t i = 0; i < n; ++i) {
    const frf::ResponsePoint& p = b.points[static_cast<std::size_t>(i)];
    out.freq_hz.mutable_data()[i] = p.hb.frequency_hz;
    out.max_multiplier.mutable_data()[i] = p.max_multiplier;
    out.stable.append(p.stable ? py::object(py::bool_(*p.stable)) : py::object(py::none()));
    out.stability_checked.push_back(p.stability_checked);
    for (py::ssize_t h = 0; h < k; ++h)
      for (py::ssize_t j = 0; j < d; ++j)
        X[(i * k + h) * d + j] =
            h < p.hb.X.rows() && j < p.hb.X.cols() ? p.hb.X(h, j) : std::complex<double>(NAN, NAN);
  }
  out.folds = b.folds;
  out.complete = b.complete;
  out.notes = b.notes;
  return out;
}

ResponseCurves response(const ModelPtr& model, const std::string& force,
                        const std::vector<double>& amplitudes, const py::object& freq_range,
                        const py::object& balance_harmonics, int stability_stride) {
  // 1. The arguments, as `jointid response` checks its options.
  check_amplitudes(amplitudes);
  if (std::set<double>(amplitudes.begin(), amplitudes.end()).size() != amplitudes.size())
    throw io::Error("amplitude: an amplitude is listed twice");
  const std::vector<double> band = numbers(freq_range, "freq_range");
  if (band.size() != 2) throw io::Error("freq_range: expected (F0, F1) in Hz, e.g. (15, 25)");
  const double f0 = band[0], f1 = band[1];
  if (!(f0 > 0.0 && f1 > 0.0 && f0 != f1 && std::isfinite(f0) && std::isfinite(f1)))
    throw io::Error(fmt::format(
        "freq_range: expected two different frequencies > 0 Hz, got {} and {}", f0, f1));
  frf::ContinuationOptions options;
  if (!balance_harmonics.is_none()) options.hb.harmonics = balance_harmonics.cast<int>();
  check_balance_harmonics(options.hb.harmonics, 1);
  if (stability_stride < 1)
    throw io::Error(
        fmt::format("stability_stride: expected a whole number >= 1 (1: every point), got {}",
                    stability_stride));
  options.stability_stride = stability_stride;
  if (model->file.joints.empty()) {
    const std::string warning =
        model->name() + ": no [[joints]]: the response is the linear substructure's";
    if (PyErr_WarnEx(PyExc_UserWarning, warning.c_str(), 1) != 0) throw py::error_already_set();
  }
  const fem::NodeDof force_at = model->dof("force", force);

  // 2. The curves; Ctrl-C is looked for after every point traced and every point whose
  // stability is computed.
  return released([&](InterruptCheck& check) {
    const std::lock_guard<std::mutex> lock(model->busy);
    const std::function<void(std::size_t, double)> each = [&check](std::size_t, double) {
      check();
    };
    ResponseCurves out{for_model(*model, [&] {
      return frf::response_curves(model->sub, model->file.joints, force_at, amplitudes, f0, f1,
                                  options, each);
    })};
    // A modal analysis that failed: its reason, as `jointid response` fails with it.
    if (!out.curves.status.ok()) throw std::runtime_error(out.curves.status.reason);
    return out;
  });
}

} // namespace

void bind_response(py::module_& m) {
  py::class_<ResponseBranch>(m, "ResponseBranch",
                             "One response curve (a force amplitude): its points in the order "
                             "of the branch (the frequency may turn back at folds).")
      .def_readonly("amplitude", &ResponseBranch::amplitude, "Force amplitude, N or N m (peak).")
      .def_readonly("freq_hz", &ResponseBranch::freq_hz, "Each point's frequency, Hz.")
      .def_readonly("X", &ResponseBranch::X,
                    "Displacement harmonics, points × (K+1) × dofs (complex, peak, SI, "
                    "x(t) = Re Σ X_k e^{ikωt}); the dofs are ResponseCurves.dofs.")
      .def_readonly("stable", &ResponseBranch::stable,
                    "Each point's stability: True, False or None (not determined).")
      .def_readonly("max_multiplier", &ResponseBranch::max_multiplier,
                    "Each point's largest Floquet multiplier |μ| (NaN: not computed).")
      .def_readonly("stability_checked", &ResponseBranch::stability_checked,
                    "Whether each point's multipliers were computed (at least every "
                    "stability_stride-th point and wherever the stability may change); a point "
                    "not computed has the verdict of the computed points on both sides.")
      .def_readonly("folds", &ResponseBranch::folds, "Indices of the turning points in frequency.")
      .def_readonly("complete", &ResponseBranch::complete, "The branch reached the band's end.")
      .def_readonly("notes", &ResponseBranch::notes,
                    "Why it stopped early, what was not determined.")
      .def("__repr__", [](const ResponseBranch& self) {
        return fmt::format("<jointid.ResponseBranch {} N: {} points, {} folds{}>", self.amplitude,
                           self.freq_hz.size(), self.folds.size(),
                           self.complete ? "" : " (incomplete)");
      });

  py::class_<ResponseCurves>(m, "ResponseCurves",
                             "Response curves by harmonic balance with continuation "
                             "(jointid.response): one branch per force amplitude.")
      .def_property_readonly(
          "harmonics", [](const ResponseCurves& self) { return self.curves.harmonics; },
          "K: harmonics 0 … K of the balance.")
      .def_property_readonly(
          "dofs",
          [](const ResponseCurves& self) {
            std::vector<std::string> out;
            for (const auto& d : self.curves.dofs)
              out.push_back(fem::to_string(d));
            return out;
          },
          "The outputs: every joint DOF, then the force DOF, \"NODE:DOF\".")
      .def_property_readonly("amplitudes",
                             [](const ResponseCurves& self) { return self.curves.amplitudes; })
      .def_property_readonly("notes", [](const ResponseCurves& self) { return self.curves.notes; })
      .def_property_readonly(
          "curves",
          [](const ResponseCurves& self) {
            py::list out;
            for (std::size_t i = 0; i < self.curves.curves.size(); ++i)
              out.append(branch_of(self.curves.curves[i], self.curves.amplitudes[i],
                                   self.curves.harmonics, self.curves.dofs.size()));
            return out;
          },
          "One ResponseBranch per amplitude.")
      .def(
          "to_dict",
          [](const ResponseCurves& self) {
            return py::module_::import("json").attr("loads")(io::response_json(self.curves));
          },
          "The curves as `jointid response` writes DIR/response.json.")
      .def("__repr__", [](const ResponseCurves& self) {
        return fmt::format("<jointid.ResponseCurves: {} curves, harmonics 0 … {}>",
                           self.curves.curves.size(), self.curves.harmonics);
      });

  m.def(
      "response",
      [](const ModelPtr& model, const std::string& force, const py::object& amplitude,
         const py::object& freq_range, const py::object& balance_harmonics, int stability_stride) {
        return response(model, force, numbers(amplitude, "amplitude"), freq_range,
                        balance_harmonics, stability_stride);
      },
      py::arg("model"), py::kw_only(), py::arg("force"), py::arg("amplitude"),
      py::arg("freq_range"), py::arg("balance_harmonics") = py::none(),
      py::arg("stability_stride") = frf::ContinuationOptions{}.stability_stride,
      "Response curves of the model with its joints (as `jointid response`): the steady states "
      "under F sin ωt at `force` traced from F0 to F1 (freq_range, Hz) by continuation, one "
      "curve per amplitude, with folds and stability. Ctrl-C stops it.");
}

} // namespace jointid::python

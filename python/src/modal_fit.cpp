// jointid.modal_fit (as `jointid modal-fit`): the linear substructure from a low-level test, and
// its result.
#include "common.hpp"

#include "io/low_level_test.hpp"
#include "io/modal_fit_output.hpp"

#include <fmt/format.h>

#include <complex>
#include <filesystem>
#include <limits>

namespace jointid::python {

namespace {

namespace fs = std::filesystem;

struct ModalFitResult {
  io::LowLevelFit result;
  std::vector<std::string> inputs; ///< the files given, or "<Record …>" for records
  double f0_hz = 0.0, f1_hz = 0.0;
};

// A complex numpy array (a copy: lines × responses, small beside the records it came from).
py::array complex_array(const Eigen::MatrixXcd& m) {
  py::array_t<std::complex<double>, py::array::f_style> a({m.rows(), m.cols()});
  std::copy(m.data(), m.data() + m.size(), a.mutable_data());
  return a;
}

// One number of every mode, in frequency order.
std::vector<double> per_mode(const ModalFitResult& self, double identify::FittedMode::*field) {
  std::vector<double> out;
  for (const auto& mode : self.result.fit.modes)
    out.push_back(mode.*field);
  return out;
}

// The comment lines of substructure.toml, as `jointid modal-fit` writes them.
std::vector<std::string> comments(const ModalFitResult& self) {
  std::string sources;
  for (const auto& s : self.inputs)
    sources += (sources.empty() ? "" : ", ") + s;
  const identify::MeasuredFrfs& data = self.result.data;
  return {"jointid.modal_fit", "from " + sources,
          fmt::format("band {} to {} Hz: {} lines; FRFs: {}", self.f0_hz, self.f1_hz,
                      data.num_lines(), identify::spectra_method_name(data.method))};
}

ModalFitResult fit(const py::object& inputs, std::pair<double, double> band, int modes,
                   int max_order, const std::string& spectra, int segment, double period_s) {
  // 1. The arguments, as `jointid modal-fit` checks its options.
  const io::ModalFitArguments arguments{band.first, band.second, modes,    max_order,
                                        spectra,    segment,     period_s, false};
  io::check_modal_fit_arguments(arguments);
  // 2. The inputs: paths (read as the command reads its FILES) or Records.
  if (is_path(inputs) || py::isinstance<Record>(inputs))
    throw io::Error("inputs: expected a list of records or paths of files (time records or FRF "
                    "files)");
  ModalFitResult out;
  out.f0_hz = band.first;
  out.f1_hz = band.second;
  std::vector<fs::path> paths;
  std::vector<std::shared_ptr<Record>> records;
  for (py::handle item : inputs) {
    if (is_path(item)) {
      paths.emplace_back(py::str(item).cast<std::string>());
      out.inputs.push_back(paths.back().string());
    } else if (py::isinstance<Record>(item)) {
      records.push_back(item.cast<std::shared_ptr<Record>>());
      out.inputs.push_back(identify::source_of(records.back()->test));
    } else {
      throw py::type_error(fmt::format("inputs: expected records or paths, got {}",
                                       py::repr(item).cast<std::string>()));
    }
  }
  return released([&](InterruptCheck&) {
    io::LowLevelTest test;
    for (const auto& r : records)
      test.records.push_back(std::get<identify::Record>(r->test));
    io::add_low_level_files(test, paths);
    // 3. The FRFs and the fit; a fit without the modes asked is its reason, raised whole.
    out.result = io::fit_low_level_test(test, arguments);
    if (!out.result.fit.status.ok())
      throw io::Error(out.result.fit.status.within("no substructure: ").reason);
    return std::move(out);
  });
}

} // namespace

void bind_modal_fit(py::module_& m) {
  using R = ModalFitResult;
  py::class_<R>(m, "ModalFitResult",
                "The modes of a low-level test and the substructure they give (jointid.modal_fit).")
      .def_property_readonly(
          "frequencies_hz",
          [](const R& self) {
            return to_numpy(per_mode(self, &identify::FittedMode::frequency_hz));
          },
          "The modes' undamped natural frequencies (Hz), increasing.")
      .def_property_readonly(
          "damping",
          [](const R& self) { return to_numpy(per_mode(self, &identify::FittedMode::damping)); },
          "The modes' damping ratios ζ.")
      .def_property_readonly(
          "in_model",
          [](const R& self) {
            std::vector<bool> in;
            for (const auto& mode : self.result.fit.modes)
              in.push_back(mode.in_model());
            return in;
          },
          "Per mode: written into the substructure (mass-normalised at the driving point).")
      .def_property_readonly(
          "shapes",
          [](const R& self) {
            const auto& modes = self.result.fit.modes;
            Eigen::MatrixXd phi = Eigen::MatrixXd::Constant(
                self.result.data.num_responses(), static_cast<Eigen::Index>(modes.size()),
                std::numeric_limits<double>::quiet_NaN());
            for (std::size_t r = 0; r < modes.size(); ++r)
              if (modes[r].in_model()) phi.col(static_cast<Eigen::Index>(r)) = modes[r].shape;
            py::array_t<double, py::array::f_style> a({phi.rows(), phi.cols()});
            std::copy(phi.data(), phi.data() + phi.size(), a.mutable_data());
            return a;
          },
          "Responses × modes, mass-normalised (1/√kg); NaN for a mode not in the model.")
      .def_property_readonly(
          "dofs",
          [](const R& self) {
            std::vector<std::string> d;
            for (const auto& at : self.result.data.responses)
              d.push_back(fem::to_string(at));
            return d;
          },
          "The rows of `shapes` and the columns of `H`, \"NODE:DOF\".")
      .def_property_readonly(
          "drive", [](const R& self) { return fem::to_string(self.result.data.drive); },
          "The driving point, \"NODE:DOF\".")
      .def_property_readonly(
          "freq_hz",
          [](const R& self) {
            return to_numpy(std::vector<double>(self.result.data.frequency_hz.begin(),
                                                self.result.data.frequency_hz.end()));
          },
          "The lines fitted (Hz).")
      .def_property_readonly(
          "H", [](const R& self) { return complex_array(self.result.data.H); },
          "The measured receptance, lines × responses (m/N).")
      .def_property_readonly(
          "fitted", [](const R& self) { return complex_array(self.result.fit.fitted); },
          "The fit (modes and both residuals), lines × responses (m/N).")
      .def_property_readonly(
          "model_frf", [](const R& self) { return complex_array(self.result.fit.model_frf); },
          "The substructure as written, at the driving point, lines × responses (m/N).")
      .def_property_readonly(
          "fit_error",
          [](const R& self) {
            const Eigen::VectorXd& e = self.result.fit.fit_error;
            return to_numpy(std::vector<double>(e.begin(), e.end()));
          },
          "Per response: √(Σ|H − H_fit|²/Σ|H|²) over the lines.")
      .def_property_readonly(
          "model_error",
          [](const R& self) {
            const Eigen::VectorXd& e = self.result.fit.model_error;
            return to_numpy(std::vector<double>(e.begin(), e.end()));
          },
          "Per response: the same for the substructure as written.")
      .def_property_readonly(
          "notes", [](const R& self) { return self.result.data.notes; },
          "What the estimate of the FRFs says (lines left out, channels ignored).")
      .def_property_readonly(
          "warnings", [](const R& self) { return self.result.fit.warnings; },
          "What the fit warns about (as `jointid modal-fit` prints them).")
      .def(
          "substructure_toml",
          [](const R& self) {
            return io::modal_fit_toml(self.result.fit, self.result.data, comments(self));
          },
          "The model file `jointid modal-fit` writes as substructure.toml ([modal]); add "
          "[[joints]] and read it with jointid.read_model (a dict from tomllib.loads, or the "
          "text written to a file).")
      .def(
          "to_dict",
          [](const R& self) {
            const io::ModalFitRun run{self.f0_hz, self.f1_hz, self.inputs, "substructure.toml"};
            return py::module_::import("json").attr("loads")(
                io::modal_fit_json(self.result.fit, self.result.data, run));
          },
          "The result as `jointid modal-fit` writes modal_fit.json.")
      .def("__repr__", [](const R& self) {
        std::vector<std::string> f;
        for (const auto& mode : self.result.fit.modes)
          f.push_back(fmt::format("{:.6g}", mode.frequency_hz));
        return fmt::format("<jointid.ModalFitResult: {} modes at {} Hz; drive {}, {} responses>",
                           f.size(), fmt::join(f, ", "), fem::to_string(self.result.data.drive),
                           self.result.data.num_responses());
      });

  m.def("modal_fit", &fit, py::arg("inputs"), py::arg("band"), py::kw_only(), py::arg("modes") = 0,
        py::arg("max_order") = 0, py::arg("spectra") = "auto", py::arg("segment") = 0,
        py::arg("period") = 0.0,
        "The linear substructure from a low-level test (as `jointid modal-fit`): `inputs` is a "
        "list of Records and paths of files (time records: CSV or universal files, one force "
        "channel and x, v or a channels; or FRF files: CSV tables or universal files of FRFs "
        "from one driving point), `band` (F0, F1) in Hz. modes: how many (0: as the "
        "stabilisation diagram shows); max_order: the highest LSCF order (0: automatic); "
        "spectra: auto, welch, periods or whole; segment: Welch samples (0: automatic); "
        "period: the records' period in s (0: their # period_s).");
}

} // namespace jointid::python

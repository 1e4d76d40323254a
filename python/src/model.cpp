// jointid.read_model (a file, or dicts mirroring one), jointid.Model with its DOFs and joints,
// Model.modes (as `jointid modes`) and Model.receptance (as `jointid frf`).
#include "common.hpp"

#include "fem/modal.hpp"
#include "fem/zero_modes.hpp"
#include "frf/sweep.hpp"
#include "io/model_toml.hpp"
#include "io/results_json.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

namespace jointid::python {

namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// A model from Python's dicts: the TOML document they mirror.

std::string type_name(const py::handle& value) {
  return py::str(py::type::handle_of(value).attr("__name__")).cast<std::string>();
}

toml::table table_of(const py::handle& dict, const std::string& where);

toml::array array_of(const py::handle& list, const std::string& where);

// One value: a dict, a list (or tuple, or numpy array: its tolist()), a bool, an int, a float or
// a str.
template <class Insert>
void insert_value(const py::handle& value, const std::string& where, Insert&& insert) {
  if (py::isinstance<py::dict>(value)) {
    insert(table_of(value, where));
  } else if (py::isinstance<py::bool_>(value)) {
    insert(value.cast<bool>());
  } else if (py::isinstance<py::int_>(value)) {
    insert(value.cast<std::int64_t>());
  } else if (py::isinstance<py::float_>(value)) {
    insert(value.cast<double>());
  } else if (py::isinstance<py::str>(value)) {
    insert(value.cast<std::string>());
  } else if (py::isinstance<py::list>(value) || py::isinstance<py::tuple>(value)) {
    insert(array_of(value, where));
  } else if (py::hasattr(value, "tolist")) { // numpy arrays and scalars
    py::object plain = value.attr("tolist")();
    insert_value(plain, where, insert);
  } else {
    throw io::Error(fmt::format("{}: expected a dict, list, str, int, float or bool, got {}", where,
                                type_name(value)));
  }
}

toml::array array_of(const py::handle& list, const std::string& where) {
  toml::array out;
  std::size_t i = 0;
  for (py::handle item : list) {
    insert_value(item, fmt::format("{}[{}]", where, i++),
                 [&](auto&& v) { out.push_back(std::forward<decltype(v)>(v)); });
  }
  return out;
}

toml::table table_of(const py::handle& dict, const std::string& where) {
  toml::table out;
  for (auto [key, value] : py::reinterpret_borrow<py::dict>(dict)) {
    if (!py::isinstance<py::str>(key))
      throw io::Error(fmt::format("{}: expected str keys, got {} {}", where, type_name(key),
                                  py::repr(key).cast<std::string>()));
    const std::string name = key.cast<std::string>();
    insert_value(value, where.empty() ? name : where + "." + name,
                 [&](auto&& v) { out.insert_or_assign(name, std::forward<decltype(v)>(v)); });
  }
  return out;
}

std::shared_ptr<Model> read(const py::object& source, const py::object& directory) {
  if (py::isinstance<py::dict>(source)) {
    // Named "<dict>" in messages; relative paths in it start from `directory`.
    const fs::path dir =
        directory.is_none() ? fs::path() : fs::path(py::str(directory).cast<std::string>());
    const toml::table document = table_of(source, "");
    py::gil_scoped_release release;
    return std::make_shared<Model>(io::read_model(document, dir / "<dict>"));
  }
  if (!directory.is_none())
    throw io::Error("directory: only for a model given as a dict (a file's paths start from its "
                    "own directory)");
  const fs::path path(py::str(source).cast<std::string>());
  py::gil_scoped_release release;
  return std::make_shared<Model>(io::read_model(path));
}

// ---------------------------------------------------------------------------------------------
// Modes.

struct Modes {
  fem::Modes modes;
  int count = 0;                     ///< the modes asked for (capped)
  std::vector<std::string> dofs;     ///< the rows of the shapes
  std::vector<std::string> warnings; ///< rigid-body modes or mechanisms
};

Modes modes_of(const Model& model, int count, const std::string& engine, double tolerance,
               int max_restarts) {
  // 1. The arguments and the model, as `jointid modes` checks them.
  if (count < 1) throw io::Error(fmt::format("count: expected at least 1, got {}", count));
  if (!(tolerance > 0.0 && tolerance < 1.0))
    throw io::Error(
        fmt::format("tolerance: expected a relative residual in (0, 1), got {}", tolerance));
  if (max_restarts < 1)
    throw io::Error(fmt::format("max_restarts: expected at least 1, got {}", max_restarts));
  fem::ModalOptions options;
  if (engine == "auto")
    options.engine = fem::ModalEngine::automatic;
  else if (engine == "dense")
    options.engine = fem::ModalEngine::dense;
  else if (engine == "sparse")
    options.engine = fem::ModalEngine::sparse;
  else
    throw io::Error("engine: expected auto, dense or sparse, got \"" + engine + "\"");
  const io::ModelFile& file = model.file;
  if (file.measured)
    throw io::Error(model.name() +
                    ": the substructure is given by measured FRFs ([frf]): there are no modes to "
                    "compute (identify, discover, simulate --method hb, response and frf read "
                    "the FRFs)");
  if (!file.parts.empty())
    throw io::Error(model.name() +
                    ": the substructure is made of several ([[substructures]]), which the "
                    "joints alone connect: run `jointid modes` on each substructure's file");
  Modes out;
  out.dofs = model.dof_labels();
  if (file.modal) { // given by its modes: the first `count` of them, as listed
    out.count = std::min(count, file.modal->num_modes());
    out.modes.omega = 2.0 * std::numbers::pi * file.modal->frequencies_hz.head(out.count);
    out.modes.phi = file.modal->shapes.topRows(out.count).transpose();
    return out;
  }

  // 2. The modes.
  const fem::Assembled& system = *model.sub.system();
  out.count = std::min(count, system.dofs.num_equations());
  options.num_modes = out.count;
  options.tolerance = tolerance;
  options.max_iterations = max_restarts;
  out.modes = fem::modal_analysis(system, options);
  if (!out.modes.status.ok())
    throw std::runtime_error("modal analysis failed: " + out.modes.status.reason);
  if (!file.matrices)
    if (const fem::ZeroModes z = fem::zero_modes(file.model, system, out.modes); z.count > 0)
      out.warnings.push_back(z.describe());
  return out;
}

py::object json_loads(const std::string& text) {
  return py::module_::import("json").attr("loads")(text);
}

// ---------------------------------------------------------------------------------------------
// Receptance.

py::array receptance(const Model& model, const py::object& freq_hz, const py::object& rows,
                     const py::object& cols, const std::string& kind_name) {
  frf::FrfKind kind;
  try {
    kind = frf::parse_frf_kind(kind_name);
  } catch (const std::invalid_argument&) {
    throw io::Error("kind: expected receptance, mobility or accelerance, got \"" + kind_name +
                    "\"");
  }
  // The frequencies as given, read in place when they are float64 already.
  const auto freq = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(freq_hz);
  if (!freq) throw py::error_already_set();
  const bool scalar = freq.ndim() == 0;
  if (freq.ndim() > 1)
    throw io::Error("freq_hz: expected a frequency or a 1-D array of frequencies (Hz)");
  const double* f = freq.data();
  const auto n_freq = freq.size();
  if (n_freq == 0) throw io::Error("freq_hz: expected at least one frequency (Hz)");
  for (py::ssize_t i = 0; i < n_freq; ++i)
    if (!(std::isfinite(f[i]) && f[i] >= 0.0))
      throw io::Error(fmt::format("freq_hz: expected finite frequencies >= 0 Hz, got {}", f[i]));
  auto equations = [&model](const py::object& dofs, const std::string& argument) {
    std::vector<int> out;
    const bool one = py::isinstance<py::str>(dofs) || !py::hasattr(dofs, "__iter__");
    if (one) {
      out.push_back(model.equation(argument, dofs));
    } else {
      for (py::handle d : dofs)
        out.push_back(model.equation(argument, d));
    }
    if (out.empty()) throw io::Error(argument + ": expected at least one DOF, e.g. \"7:uy\"");
    return out;
  };
  const std::vector<int> row_eq = equations(rows, "rows"), col_eq = equations(cols, "cols");
  std::vector<int> dofs = row_eq;
  for (int e : col_eq)
    if (std::find(dofs.begin(), dofs.end(), e) == dofs.end()) dofs.push_back(e);

  const auto r = static_cast<py::ssize_t>(row_eq.size()),
             c = static_cast<py::ssize_t>(col_eq.size());
  py::array_t<std::complex<double>> out = scalar
                                              ? py::array_t<std::complex<double>>({r, c})
                                              : py::array_t<std::complex<double>>({n_freq, r, c});
  std::complex<double>* values = out.mutable_data();
  std::vector<std::string> notes;
  released([&](InterruptCheck& check) {
    const std::lock_guard<std::mutex> lock(model.busy);
    // As frf::frf_sweep (`jointid frf`): the synthesis covers harmonic 1 up to the highest
    // frequency.
    const double f_max = *std::max_element(f, f + n_freq);
    const frf::ModalSynthesis H = for_model(model, [&] {
      return model.sub.synthesis(dofs, frf::synthesis_band_hz(std::max(f_max, 1e-3), 1), &notes);
    });
    // A modal analysis that failed: its reason, as `jointid frf` fails with it.
    if (!H.status().ok()) throw std::runtime_error(H.status().reason);
    for (py::ssize_t i = 0; i < n_freq; ++i) {
      if (i % 64 == 0) check();
      const double w = 2.0 * std::numbers::pi * f[i];
      const std::complex<double> factor = kind == frf::FrfKind::receptance ? 1.0
                                          : kind == frf::FrfKind::mobility
                                              ? std::complex<double>(0.0, w)
                                              : std::complex<double>(-w * w, 0.0);
      const frf::CMatrix block = H.receptance(w, row_eq, col_eq);
      for (py::ssize_t a = 0; a < r; ++a) // numpy's order: C, rows then columns
        for (py::ssize_t b = 0; b < c; ++b)
          values[(i * r + a) * c + b] = factor * block(a, b);
    }
    return 0;
  });
  for (const auto& n : notes)
    if (PyErr_WarnEx(PyExc_UserWarning, n.c_str(), 1) != 0) throw py::error_already_set();
  return out;
}

} // namespace

void bind_model(py::module_& m) {
  py::class_<Model, std::shared_ptr<Model>>(
      m, "Model", "A model file read (jointid.read_model): the linear substructure and its joints.")
      .def_property_readonly(
          "path", [](const Model& self) { return self.name(); },
          "The file it was read from (\"<dict>\" in its directory for a model given as dicts).")
      .def_property_readonly(
          "given_by", [](const Model& self) { return std::string(self.sub.given_by()); },
          "How the substructure is given: \"a finite element model\", \"its modes ([modal])\", …")
      .def_property_readonly(
          "dofs", &Model::dof_labels,
          "The substructure's DOFs in the order of its equations, as \"NODE:DOF\" labels.")
      .def_property_readonly(
          "joints", [](const Model& self) { return joint_dicts(self.file.joints); },
          "The joints as the model file's [[joints]]: dicts with name, node, (node_b,) dof, terms, "
          "values and fixed.")
      .def(
          "modes",
          [](const ModelPtr& self, int count, const std::string& engine, double tolerance,
             int max_restarts) {
            return released([&](InterruptCheck&) {
              const std::lock_guard<std::mutex> lock(self->busy);
              return modes_of(*self, count, engine, tolerance, max_restarts);
            });
          },
          py::arg("count") = 10, py::kw_only(), py::arg("engine") = "auto",
          py::arg("tolerance") = fem::ModalOptions{}.tolerance,
          py::arg("max_restarts") = fem::ModalOptions{}.max_iterations,
          "The lowest `count` natural frequencies and mass-normalised mode shapes of the linear "
          "substructure (as `jointid modes`).")
      .def("receptance", &receptance, py::arg("freq_hz"), py::arg("rows"), py::arg("cols"),
           py::kw_only(), py::arg("kind") = "receptance",
           "The substructure's FRFs H[rows, cols] by modal synthesis (as `jointid frf`): m/N for "
           "receptance, (m/s)/N mobility, (m/s^2)/N accelerance. rows, cols: \"NODE:DOF\" labels "
           "or equation numbers. A frequency gives a rows × cols array, an array of frequencies "
           "an n_freq × rows × cols one (complex).")
      .def("__repr__", [](const Model& self) {
        return fmt::format("<jointid.Model {}: {}, {} DOFs, {} joints>", self.name(),
                           self.sub.given_by(), self.sub.dofs().num_equations(),
                           self.file.joints.size());
      });

  py::class_<Modes>(m, "Modes",
                    "Natural frequencies and mass-normalised mode shapes (Model.modes).")
      .def_property_readonly(
          "frequencies_hz",
          [](const Modes& self) {
            std::vector<double> f;
            for (int r = 0; r < self.modes.num_modes(); ++r)
              f.push_back(self.modes.frequency_hz(r));
            return to_numpy(f);
          },
          "Natural frequencies f_r, Hz, ascending.")
      .def_property_readonly(
          "omega", [](py::object self) { return view(self.cast<Modes&>().modes.omega, self); },
          "Circular frequencies ω_r, rad/s (a read-only view).")
      .def_property_readonly(
          "shapes", [](py::object self) { return view(self.cast<Modes&>().modes.phi, self); },
          "Mode shapes, n_dof × n_modes, mass-normalised (φᵀMφ = 1); rows as `dofs` (a "
          "read-only view of the library's memory).")
      .def_readonly("dofs", &Modes::dofs, "The rows of `shapes`, \"NODE:DOF\".")
      .def_readonly("warnings", &Modes::warnings, "Rigid-body modes or mechanisms found.")
      .def(
          "to_dict",
          [](const Modes& self) {
            return json_loads(io::modes_json(self.modes, self.count, self.warnings));
          },
          "The modes as `jointid modes` writes modes.json.")
      .def("__len__", [](const Modes& self) { return self.modes.num_modes(); })
      .def("__repr__", [](const Modes& self) {
        std::vector<std::string> f;
        for (int r = 0; r < std::min(self.modes.num_modes(), 6); ++r)
          f.push_back(fmt::format("{:.6g}", self.modes.frequency_hz(r)));
        return fmt::format("<jointid.Modes: {} modes, {}{} Hz>", self.modes.num_modes(),
                           fmt::join(f, ", "), self.modes.num_modes() > 6 ? ", …" : "");
      });

  m.def("read_model", &read, py::arg("source"), py::kw_only(), py::arg("directory") = py::none(),
        "Reads and checks a model file (TOML, docs/formats/model.md), or a dict that mirrors one "
        "(as tomllib.load gives it: {\"model\": {...}, \"materials\": [...], \"joints\": [...]}); "
        "a dict's relative paths start from `directory`. Raises jointid.Error naming the file, "
        "line, key and what was expected.");
}

} // namespace jointid::python

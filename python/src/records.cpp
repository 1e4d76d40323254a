// jointid.Record (a measurement record: numpy views of its samples), jointid.SteppedSineRow,
// jointid.read_record / read_tests (the files `jointid identify` reads) and
// jointid.simulate_sine (as `jointid simulate`).
#include "common.hpp"
#include "io/arguments.hpp"

#include "identify/sine_tests.hpp"
#include "io/record_csv.hpp"

#include <fmt/format.h>

#include <cmath>
#include <optional>
#include <set>

namespace jointid::python {

namespace {

namespace fs = std::filesystem;

identify::Record& record_of(Test& test) {
  return std::get<identify::Record>(test.test);
}
const identify::Record& record_of(const Test& test) {
  return std::get<identify::Record>(test.test);
}

// ---------------------------------------------------------------------------------------------
// A record from numpy arrays: the samples copied once into the library's record (which owns
// them), checked as the CSV reader checks a file.

std::shared_ptr<Record> make_record(const py::object& t, const py::dict& channels,
                                    const std::optional<double>& excitation_hz,
                                    const std::string& source,
                                    const std::vector<std::string>& comments) {
  const std::string name = "Record " + source;
  auto samples = [&name](const py::handle& values, const std::string& what) {
    const auto a = py::array_t<double, py::array::c_style | py::array::forcecast>::ensure(values);
    if (!a) throw py::error_already_set();
    if (a.ndim() != 1)
      throw io::Error(fmt::format("{}: {}: expected a 1-D array of samples, got {} dimensions",
                                  name, what, a.ndim()));
    Eigen::VectorXd v = Eigen::Map<const Eigen::VectorXd>(a.data(), a.size());
    if (!v.allFinite()) throw io::Error(fmt::format("{}: {}: NaN or infinite values", name, what));
    return v;
  };
  auto out = std::make_shared<Record>();
  identify::Record r;
  r.source = source;
  r.excitation_hz = excitation_hz;
  if (excitation_hz && !(std::isfinite(*excitation_hz) && *excitation_hz > 0.0))
    throw io::Error(fmt::format("{}: excitation_hz: expected a frequency > 0 Hz, got {}", name,
                                *excitation_hz));
  r.t = samples(t, "t");
  const Eigen::Index n = r.t.size();
  if (n < 4) throw io::Error(fmt::format("{}: t: {} samples, expected at least 4", name, n));
  for (Eigen::Index i = 1; i < n; ++i)
    if (!(r.t(i) > r.t(i - 1)))
      throw io::Error(fmt::format("{}: t[{}] = {} does not increase from t[{}] = {} (time must "
                                  "increase strictly)",
                                  name, i, r.t(i), i - 1, r.t(i - 1)));
  const double mean_step = (r.t(n - 1) - r.t(0)) / static_cast<double>(n - 1);
  for (Eigen::Index i = 1; i < n; ++i) {
    const double deviation = std::abs((r.t(i) - r.t(i - 1)) - mean_step) / mean_step;
    if (!(deviation <= 1e-6))
      throw io::Error(fmt::format("{}: time step {} s at t[{}] differs from the mean step {} s by "
                                  "{:.3g} (relative; sampling must be uniform to 1e-6)",
                                  name, r.t(i) - r.t(i - 1), i, mean_step, deviation));
  }
  if (channels.empty())
    throw io::Error(name + ": channels: expected at least one, e.g. {\"f@7:uy\": ..., "
                           "\"x@7:uy\": ...}");
  std::set<std::string> seen;
  for (auto [key, values] : channels) {
    const std::string channel = py::str(key).cast<std::string>();
    identify::Channel c;
    try {
      c = identify::parse_channel_name(channel);
    } catch (const std::invalid_argument& e) {
      throw io::Error(fmt::format("{}: channels: {}", name, e.what()));
    }
    if (!seen.insert(c.name()).second)
      throw io::Error(fmt::format("{}: channels: {} is given twice", name, c.name()));
    c.samples = samples(values, "channel " + channel);
    if (c.samples.size() != n)
      throw io::Error(fmt::format("{}: channel {} has {} samples but t has {}", name, channel,
                                  c.samples.size(), n));
    r.channels.push_back(std::move(c));
  }
  out->test = std::move(r);
  out->comments = comments;
  return out;
}

const identify::Channel& channel(const identify::Record& r, const std::string& name) {
  for (const auto& c : r.channels)
    if (c.name() == name) return c;
  std::vector<std::string> names;
  for (const auto& c : r.channels)
    names.push_back(c.name());
  throw py::key_error(
      fmt::format("{}: no channel {} (it has {})", r.source, name, fmt::join(names, ", ")));
}

// ---------------------------------------------------------------------------------------------
// simulate_sine, as `jointid simulate` with sine excitation.

struct SimulateArguments {
  std::string force;
  std::vector<double> freq_hz, amplitude;
  std::string method;
  identify::SimulationOptions options;
  std::vector<std::string> channels, outputs;
  double noise = 0.0;
  unsigned long long seed = 1;
};

py::list simulate_sine(const ModelPtr& model, const SimulateArguments& a) {
  // 1. The arguments, as `jointid simulate` checks its options.
  io::check_sine_tests(
      {"freq_hz", "periods", "steps_per_period", "samples_per_period", "balance_harmonics"},
      a.freq_hz, a.options);
  check_amplitudes(a.amplitude);
  identify::SimulationOptions options = a.options;
  io::check_noise("noise", a.noise);
  options.quantities = io::parse_channels("channels", a.channels);
  if (a.method == "time")
    options.method = identify::SimulationMethod::time_integration;
  else if (a.method == "hb")
    options.method = identify::SimulationMethod::harmonic_balance;
  else
    throw io::Error("method: expected time or hb, got \"" + a.method + "\"");

  // 2. The model's DOFs and the tests.
  const fem::NodeDof force_at = model->dof("force", a.force);
  for (const auto& text : a.outputs)
    options.extra_outputs.push_back(model->dof("outputs", text));
  std::vector<identify::SineTestPlan> plans;
  std::set<std::string> names;
  for (double f : a.freq_hz)
    for (double amp : a.amplitude) {
      plans.push_back({f, amp});
      if (!names.insert(identify::sine_test_name(plans.back())).second)
        throw io::Error(
            fmt::format("freq_hz, amplitude: the test at {} Hz, {} N is listed twice", f, amp));
    }

  // 3. Every test, in parallel for time integration; progress checks for Ctrl-C.
  std::vector<identify::SimulatedTest> tests = released([&](InterruptCheck& check) {
    const std::lock_guard<std::mutex> lock(model->busy);
    options.progress = [&check](double) { check(); };
    auto out = for_model(*model, [&] {
      return identify::simulate_sine_tests(model->sub, model->file.joints, force_at, plans,
                                           options);
    });
    for (const auto& t : out) // a numerical failure ends the call, as it ends the command
      if (!t.status.ok()) throw std::runtime_error(t.status.reason);
    identify::add_noise(out, a.noise, a.seed);
    return out;
  });
  const std::vector<std::string> made_by{"jointid.simulate_sine (Python)",
                                         "model: " + model->name()};
  py::list records;
  for (auto& t : tests) {
    auto r = std::make_shared<Record>();
    r->comments = made_by;
    r->comments.insert(r->comments.end(), t.comments.begin(), t.comments.end());
    r->warnings = std::move(t.warnings);
    r->test = std::move(t.record);
    records.append(py::cast(std::move(r)));
  }
  return records;
}

} // namespace

void bind_records(py::module_& m) {
  py::class_<Record, std::shared_ptr<Record>>(
      m, "Record",
      "A measurement record: uniformly sampled time signals of one test (the record CSV "
      "contract, docs/formats/record.md). Its arrays are views of the record's own memory: "
      "changing them in place changes the record.")
      .def(py::init(&make_record), py::arg("t"), py::arg("channels"), py::kw_only(),
           py::arg("excitation_hz") = py::none(), py::arg("source") = "record",
           py::arg("comments") = std::vector<std::string>{},
           "A record from numpy arrays: t (s, uniform) and channels {\"f@7:uy\": samples, "
           "\"x@7:uy\": samples, …} (f force N, x m, v m/s, a m/s^2). The samples are copied once "
           "into the record, which owns them.")
      .def_property_readonly(
          "t", [](py::object self) { return view(record_of(self.cast<Record&>()).t, self, true); },
          "Times, s (a view).")
      .def_property_readonly(
          "channels",
          [](py::object self) {
            py::dict out;
            for (const auto& c : record_of(self.cast<Record&>()).channels)
              out[py::str(c.name())] = view(c.samples, self, true);
            return out;
          },
          "{name: samples} with every channel's samples as a view, in file order.")
      .def_property_readonly(
          "channel_names",
          [](const Record& self) {
            std::vector<std::string> names;
            for (const auto& c : record_of(self).channels)
              names.push_back(c.name());
            return names;
          },
          "The channels' names, \"x@7:uy\", in file order.")
      .def(
          "__getitem__",
          [](py::object self, const std::string& name) {
            return view(channel(record_of(self.cast<Record&>()), name).samples, self, true);
          },
          py::arg("name"), "One channel's samples (a view).")
      .def("__len__", [](const Record& self) { return record_of(self).t.size(); })
      .def_property(
          "excitation_hz", [](const Record& self) { return record_of(self).excitation_hz; },
          [](Record& self, std::optional<double> f) { record_of(self).excitation_hz = f; },
          "The sine's frequency (Hz) when the record says it (None: estimated from the force).")
      .def_property(
          "source", [](const Record& self) { return record_of(self).source; },
          [](Record& self, const std::string& s) { record_of(self).source = s; },
          "Its file name, for messages (a simulated record: the name `jointid simulate` gives "
          "its file).")
      .def_readwrite("comments", &Record::comments, "The CSV file's comment lines.")
      .def_readonly("warnings", &Record::warnings,
                    "What its simulation said (not periodic, not converged).")
      .def_property_readonly(
          "dt", [](const Record& self) { return record_of(self).dt(); }, "The time step, s.")
      .def(
          "to_csv",
          [](const Record& self, const py::object& path) -> py::object {
            const identify::Record& r = record_of(self);
            if (path.is_none()) return py::str(io::record_csv(r, self.comments));
            io::write_record(fs::path(py::str(path).cast<std::string>()), r, self.comments);
            return py::none();
          },
          py::arg("path") = py::none(),
          "The record as CSV (the contract): written to `path` (atomically), or returned as text "
          "when no path is given.")
      .def("__repr__", [](const Record& self) {
        const identify::Record& r = record_of(self);
        std::vector<std::string> names;
        for (const auto& c : r.channels)
          names.push_back(c.name());
        return fmt::format("<jointid.Record {}: {} samples, dt {:.6g} s, {}{}>", r.source,
                           r.t.size(), r.dt(), fmt::join(names, ", "),
                           r.excitation_hz ? fmt::format(", {} Hz", *r.excitation_hz) : "");
      });

  py::class_<SteppedSineRow, std::shared_ptr<SteppedSineRow>>(
      m, "SteppedSineRow",
      "One test of a stepped-sine table: the complex fundamental of every channel (peak, SI, "
      "x(t) = Re(X e^{iωt})).")
      .def_property_readonly(
          "source",
          [](const SteppedSineRow& self) { return std::get<identify::Phasors>(self.test).source; },
          "\"table.csv:LINE\"")
      .def_property_readonly(
          "frequency_hz",
          [](const SteppedSineRow& self) {
            return std::get<identify::Phasors>(self.test).frequency_hz;
          },
          "The excitation frequency, Hz.")
      .def_property_readonly(
          "channels",
          [](const SteppedSineRow& self) {
            py::dict out;
            for (const auto& c : std::get<identify::Phasors>(self.test).channels)
              out[py::str(c.name())] = c.value;
            return out;
          },
          "{name: complex amplitude}")
      .def("__repr__", [](const SteppedSineRow& self) {
        const auto& p = std::get<identify::Phasors>(self.test);
        return fmt::format("<jointid.SteppedSineRow {}: {} Hz, {} channels>", p.source,
                           p.frequency_hz, p.channels.size());
      });

  m.def(
      "read_record",
      [](const py::object& path) {
        const fs::path p(py::str(path).cast<std::string>());
        auto r = std::make_shared<Record>();
        py::gil_scoped_release release;
        r->test = io::read_record(p);
        return r;
      },
      py::arg("path"), "Reads a record (CSV). Raises jointid.Error naming the file and line.");
  m.def(
      "read_tests",
      [](const py::object& paths) {
        py::list out;
        if (py::isinstance<py::str>(paths) ||
            py::isinstance(paths, py::module_::import("os").attr("PathLike"))) {
          py::list one;
          one.append(paths);
          for (const TestPtr& t : tests_of(one))
            out.append(to_python(t));
          return out;
        }
        for (const TestPtr& t : tests_of(paths))
          out.append(to_python(t));
        return out;
      },
      py::arg("paths"),
      "Reads the sine tests of files as `jointid identify` reads its TESTS: CSV records "
      "(Record), stepped-sine tables (one SteppedSineRow per row) and universal files.");

  m.def(
      "simulate_sine",
      [](const ModelPtr& model, const std::string& force, const py::object& freq_hz,
         const py::object& amplitude, const std::string& method, int periods, int steps_per_period,
         int samples_per_period, const py::object& balance_harmonics, const py::object& channels,
         const py::object& outputs, double noise, unsigned long long seed) {
        SimulateArguments a;
        a.force = force;
        a.freq_hz = numbers(freq_hz, "freq_hz");
        a.amplitude = numbers(amplitude, "amplitude");
        a.method = method;
        a.options.periods = periods;
        a.options.steps_per_period = steps_per_period;
        a.options.samples_per_period = samples_per_period;
        if (!balance_harmonics.is_none())
          a.options.balance.harmonics = balance_harmonics.cast<int>();
        a.channels = strings(channels, "channels");
        a.outputs = strings(outputs, "outputs");
        a.noise = noise;
        a.seed = seed;
        return simulate_sine(model, a);
      },
      py::arg("model"), py::kw_only(), py::arg("force"), py::arg("freq_hz"), py::arg("amplitude"),
      py::arg("method") = "time", py::arg("periods") = identify::SimulationOptions{}.periods,
      py::arg("steps_per_period") = identify::SimulationOptions{}.steps_per_period,
      py::arg("samples_per_period") = identify::SimulationOptions{}.samples_per_period,
      py::arg("balance_harmonics") = py::none(),
      py::arg("channels") = std::vector<std::string>{"x", "v"},
      py::arg("outputs") = std::vector<std::string>{}, py::arg("noise") = 0.0,
      py::arg("seed") = 1ULL,
      "Virtual sine tests of the model with its joints at their values (as `jointid simulate`): "
      "one Record per frequency × amplitude, F sin(2π f t) at `force`, by time integration "
      "(method=\"time\") or harmonic balance (\"hb\"). Ctrl-C stops it.");
}

} // namespace jointid::python

#include "common.hpp"
#include "io/arguments.hpp"

#include "io/record_csv.hpp"
#include "joints/basis.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <map>
#include <set>

namespace jointid::python {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------------
// Interrupts.

InterruptCheck::InterruptCheck()
    : caller_(std::this_thread::get_id()), last_check_(std::chrono::steady_clock::now()) {}

InterruptCheck::~InterruptCheck() {
  // Only when restore() was never called (a second exception replaced the interrupt): drop it.
  if (type_ || value_ || traceback_) {
    py::gil_scoped_acquire gil;
    Py_XDECREF(type_);
    Py_XDECREF(value_);
    Py_XDECREF(traceback_);
  }
}

void InterruptCheck::operator()() {
  if (tripped_) throw Interrupted{};
  if (std::this_thread::get_id() != caller_) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_check_ < std::chrono::milliseconds(50)) return;
  last_check_ = now;
  py::gil_scoped_acquire gil;
  if (PyErr_CheckSignals() == 0) return;
  PyErr_Fetch(&type_, &value_, &traceback_);
  tripped_ = true;
  throw Interrupted{};
}

void InterruptCheck::restore() {
  if (!type_) { // tripped on another thread before the caller fetched anything: cannot happen
    PyErr_SetNone(PyExc_KeyboardInterrupt);
    return;
  }
  PyErr_Restore(type_, value_, traceback_);
  type_ = value_ = traceback_ = nullptr;
}

// ---------------------------------------------------------------------------------------------
// The model.

Model::Model(io::ModelFile model_file) : file(std::move(model_file)), sub(file.substructure()) {}

fem::NodeDof Model::dof(const std::string& argument, const std::string& text) const {
  try {
    const fem::NodeDof at = io::resolve_node_dof(file, text);
    sub.dofs().equation(at);
    return at;
  } catch (const std::invalid_argument& e) {
    throw io::Error(fmt::format("{} {}: {} (expected NODE:DOF of a free DOF of {}, e.g. 7:uy, or "
                                "a one-node Gmsh group such as tip:uy)",
                                argument, text, e.what(), name()));
  }
}

int Model::equation(const std::string& argument, const py::handle& dof) const {
  if (py::isinstance<py::str>(dof))
    return sub.dofs().equation(this->dof(argument, dof.cast<std::string>()));
  if (py::isinstance<py::int_>(dof) || py::hasattr(dof, "__index__")) {
    const long e = py::int_(py::reinterpret_borrow<py::object>(dof)).cast<long>();
    const int n = sub.dofs().num_equations();
    if (e < 0 || e >= n)
      throw io::Error(fmt::format("{} {}: expected an equation number from 0 to {} of {}", argument,
                                  e, n - 1, name()));
    return static_cast<int>(e);
  }
  throw io::Error(fmt::format("{}: expected NODE:DOF (e.g. \"7:uy\") or an equation number, got {}",
                              argument, py::str(py::type::handle_of(dof)).cast<std::string>()));
}

std::vector<std::string> Model::dof_labels() const {
  std::vector<std::string> labels;
  for (int e = 0; e < sub.dofs().num_equations(); ++e)
    labels.push_back(fem::to_string(sub.dofs().node_dof(e)));
  return labels;
}

py::dict joint_dict(const joints::Joint& joint, bool identified) {
  py::dict d;
  d["name"] = joint.name;
  d["node"] = joint.node;
  if (!joint.to_ground()) d["node_b"] = joint.node_b;
  d["dof"] = std::string(fem::dof_name(joint.dof));
  py::list terms, fixed;
  py::dict values;
  for (std::size_t t = 0; t < joint.terms.size(); ++t) {
    const std::string name(joints::term_name(joint.terms[t]));
    terms.append(name);
    if ((identified || joint.has_value(t)) && t < joint.values.size())
      values[py::str(name)] = joint.values[t];
    if (t < joint.fixed.size() && joint.fixed[t]) fixed.append(name);
  }
  d["terms"] = terms;
  d["values"] = values;
  d["fixed"] = fixed;
  return d;
}

py::list joint_dicts(const std::vector<joints::Joint>& joints, bool identified) {
  py::list out;
  for (const auto& j : joints)
    out.append(joint_dict(j, identified));
  return out;
}

// ---------------------------------------------------------------------------------------------
// Arrays.

namespace {

py::array view_of(const double* data, Eigen::Index rows, Eigen::Index cols, bool matrix,
                  py::handle owner, bool writeable) {
  const auto size = static_cast<py::ssize_t>(sizeof(double));
  py::array a = matrix ? py::array(py::dtype::of<double>(), {rows, cols},
                                   {size, size * static_cast<py::ssize_t>(rows)}, data, owner)
                       : py::array(py::dtype::of<double>(), {rows}, {size}, data, owner);
  if (!writeable) a.attr("flags").attr("writeable") = false;
  return a;
}

} // namespace

py::array view(const Eigen::MatrixXd& m, py::handle owner, bool writeable) {
  return view_of(m.data(), m.rows(), m.cols(), true, owner, writeable);
}

py::array view(const Eigen::VectorXd& v, py::handle owner, bool writeable) {
  return view_of(v.data(), v.size(), 1, false, owner, writeable);
}

py::array_t<double> to_numpy(const std::vector<double>& values) {
  py::array_t<double> a(static_cast<py::ssize_t>(values.size()));
  std::copy(values.begin(), values.end(), a.mutable_data());
  return a;
}

namespace {

// A scalar or a sequence (a numpy array too) as a list of its items.
py::list items_of(const py::handle& values) {
  if (py::isinstance<py::str>(values) || !py::hasattr(values, "__iter__")) {
    py::list one;
    one.append(values);
    return one;
  }
  py::list out;
  for (py::handle v : values)
    out.append(v);
  return out;
}

} // namespace

std::vector<double> numbers(const py::handle& values, const std::string& argument) {
  std::vector<double> out;
  for (py::handle v : items_of(values)) {
    if (!PyNumber_Check(v.ptr()) || py::isinstance<py::bool_>(v))
      throw io::Error(
          fmt::format("{}: expected numbers, got {}", argument, py::repr(v).cast<std::string>()));
    out.push_back(py::float_(py::reinterpret_borrow<py::object>(v)).cast<double>());
  }
  return out;
}

std::vector<int> integers(const py::handle& values, const std::string& argument) {
  std::vector<int> out;
  for (py::handle v : items_of(values)) {
    if (py::isinstance<py::bool_>(v) || !py::hasattr(v, "__index__"))
      throw io::Error(
          fmt::format("{}: expected integers, got {}", argument, py::repr(v).cast<std::string>()));
    out.push_back(py::int_(py::reinterpret_borrow<py::object>(v)).cast<int>());
  }
  return out;
}

std::vector<std::string> strings(const py::handle& values, const std::string& argument) {
  std::vector<std::string> out;
  for (py::handle v : items_of(values)) {
    if (!py::isinstance<py::str>(v))
      throw io::Error(
          fmt::format("{}: expected strings, got {}", argument, py::repr(v).cast<std::string>()));
    out.push_back(v.cast<std::string>());
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// The checks of arguments.

void check_harmonics(const std::vector<int>& harmonics, int lowest) {
  io::check_harmonics("harmonics", harmonics, lowest);
}

void check_balance_harmonics(int harmonics, int lowest, const std::string& why) {
  io::check_balance_harmonics("balance_harmonics", harmonics, lowest, why);
}

void check_amplitudes(const std::vector<double>& amplitudes) {
  io::check_amplitudes("amplitude", amplitudes);
}

// ---------------------------------------------------------------------------------------------
// Tests.

bool is_path(const py::handle& item) {
  return py::isinstance<py::str>(item) ||
         py::isinstance(item, py::module_::import("os").attr("PathLike"));
}

namespace {

TestPtr wrap(identify::SineTest&& test) {
  if (std::holds_alternative<identify::Record>(test)) {
    auto r = std::make_shared<Record>();
    r->test = std::move(test);
    return r;
  }
  auto row = std::make_shared<SteppedSineRow>();
  row->test = std::move(test);
  return row;
}

} // namespace

std::vector<TestPtr> tests_of(const py::handle& items) {
  if (is_path(items) || py::isinstance<Record>(items) || py::isinstance<SteppedSineRow>(items))
    throw io::Error("tests: expected a list of records, stepped-sine rows or paths of files "
                    "holding them");
  std::vector<py::object> given;
  for (py::handle item : items)
    given.push_back(py::reinterpret_borrow<py::object>(item));
  if (given.empty()) throw io::Error("tests: expected at least one record or table (CSV file)");
  // Paths as `jointid identify` reads its TESTS, all together (a file given twice is refused);
  // their tests then stand where the first path stood, the objects in their places.
  std::vector<fs::path> paths;
  for (const auto& item : given)
    if (is_path(item)) paths.emplace_back(py::str(item).cast<std::string>());
  std::vector<identify::SineTest> read;
  if (!paths.empty()) {
    py::gil_scoped_release release;
    read = io::read_tests(paths);
  }
  std::vector<TestPtr> out;
  std::set<const Test*> seen;
  bool files_placed = false;
  for (const auto& item : given) {
    if (is_path(item)) {
      if (!files_placed)
        for (auto& t : read)
          out.push_back(wrap(std::move(t)));
      files_placed = true;
    } else if (py::isinstance<Record>(item) || py::isinstance<SteppedSineRow>(item)) {
      TestPtr t = py::isinstance<Record>(item)
                      ? TestPtr(item.cast<std::shared_ptr<Record>>())
                      : TestPtr(item.cast<std::shared_ptr<SteppedSineRow>>());
      if (!seen.insert(t.get()).second)
        throw io::Error(fmt::format("tests: {} is given twice (each test would count twice and the "
                                    "uncertainty come out falsely small)",
                                    identify::source_of(t->test)));
      out.push_back(std::move(t));
    } else {
      throw py::type_error(fmt::format("tests: expected records, stepped-sine rows or paths, "
                                       "got {}",
                                       py::repr(item).cast<std::string>()));
    }
  }
  return out;
}

py::object to_python(const TestPtr& test) {
  if (std::holds_alternative<identify::Record>(test->test))
    return py::cast(std::static_pointer_cast<Record>(test));
  return py::cast(std::static_pointer_cast<SteppedSineRow>(test));
}

std::vector<identify::Measurement> measure(const std::vector<TestPtr>& tests,
                                           const identify::MeasureOptions& options) {
  std::vector<identify::Measurement> out;
  out.reserve(tests.size());
  for (const auto& t : tests)
    out.push_back(identify::measure(t->test, options));
  return out;
}

} // namespace jointid::python

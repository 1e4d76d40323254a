#pragma once
/// What the bindings of the module `jointid` share (docs/python.md): the model as Python holds
/// it, arrays that view the library's memory, the checks of arguments (the CLI's messages, the
/// Python keyword in place of the option), and calls that release the GIL and stop on Ctrl-C.
#include "fem/dof.hpp"
#include "frf/substructure.hpp"
#include "identify/measurement.hpp"
#include "io/files.hpp"
#include "io/model_file.hpp"
#include "joints/joint.hpp"

#include <Eigen/Core>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace jointid::python {

namespace py = pybind11;

// ---------------------------------------------------------------------------------------------
// Interrupts.

/// Thrown from the library's callbacks to stop a call that Ctrl-C interrupted. Not a
/// std::exception, so that no `catch (const std::exception&)` in the library takes it for a
/// failure of its own; fem::parallel_map passes it on from its worker threads.
struct Interrupted {};

/// Checks for a pending signal (Ctrl-C) while a library call runs without the GIL. Called from
/// the library's progress callbacks, on any of its threads: on the thread that made the call
/// (Python's main thread), at most every 50 ms, it takes the GIL and runs Python's signal
/// handlers (PyErr_CheckSignals, which does nothing on other threads); when one raised (the
/// KeyboardInterrupt of SIGINT), the exception is kept and Interrupted thrown, and from then on
/// on every thread.
class InterruptCheck {
public:
  InterruptCheck();
  ~InterruptCheck();
  InterruptCheck(const InterruptCheck&) = delete;
  InterruptCheck& operator=(const InterruptCheck&) = delete;

  /// Throws Interrupted when the call is to stop. Without the GIL.
  void operator()();
  /// Sets the exception the signal handler raised as Python's error again. With the GIL.
  void restore();

private:
  std::thread::id caller_;
  std::atomic<bool> tripped_{false};
  std::chrono::steady_clock::time_point last_check_;
  PyObject *type_ = nullptr, *value_ = nullptr, *traceback_ = nullptr;
};

/// Runs `compute(check)` without the GIL; `check` goes into the library's callbacks. An
/// interrupt becomes the Python exception its handler raised (KeyboardInterrupt); the library's
/// exceptions pass on to the module's translators.
template <class Compute> auto released(Compute&& compute) {
  InterruptCheck check;
  try {
    py::gil_scoped_release release;
    return compute(check);
  } catch (const Interrupted&) {
    check.restore();
    throw py::error_already_set();
  }
}

// ---------------------------------------------------------------------------------------------
// The model.

/// A model file read (or built from dicts) and its substructure, as cli::Model holds them.
struct Model {
  Model(io::ModelFile model_file);

  io::ModelFile file;
  frf::Substructure sub;
  /// One library call at a time on this model: the substructure caches its modes on first use.
  /// Taken after the GIL is released (the library's callbacks take the GIL while holding it).
  mutable std::mutex busy;

  std::string name() const { return file.path.string(); }
  /// `text` (NODE:DOF, or a one-node Gmsh group and a DOF) as a free DOF of the substructure;
  /// io::Error naming `argument` otherwise (cli::Model::dof's message).
  fem::NodeDof dof(const std::string& argument, const std::string& text) const;
  /// The equation of a DOF given as "NODE:DOF" or as an equation number.
  int equation(const std::string& argument, const py::handle& dof) const;
  /// "7:uy" for every equation.
  std::vector<std::string> dof_labels() const;
};

using ModelPtr = std::shared_ptr<const Model>;

/// Runs `compute()`; a std::invalid_argument from the library (the model's data or the
/// arguments refused) becomes io::Error after the model's name, its reason intact (cli's
/// for_model).
template <class Compute> auto for_model(const Model& model, Compute&& compute) {
  try {
    return compute();
  } catch (const std::invalid_argument& e) {
    throw io::Error(model.name() + ": " + e.what());
  }
}

/// A joint as the model file's [[joints]] entry: name, node, node_b, dof, terms, values (by
/// term: those given, or with `identified` every one), fixed.
py::dict joint_dict(const joints::Joint& joint, bool identified = false);
py::list joint_dicts(const std::vector<joints::Joint>& joints, bool identified = false);

// ---------------------------------------------------------------------------------------------
// Arrays.

/// A numpy array of the doubles of `m` (column-major), viewing its memory: `owner` (the Python
/// object that holds `m`) is kept alive by it. Read-only unless `writeable`.
py::array view(const Eigen::MatrixXd& m, py::handle owner, bool writeable = false);
py::array view(const Eigen::VectorXd& v, py::handle owner, bool writeable = false);

/// A new numpy array holding a copy (for small results assembled from several matrices).
py::array_t<double> to_numpy(const std::vector<double>& values);

/// A sequence of numbers (a float, a list, a numpy array) as doubles.
std::vector<double> numbers(const py::handle& values, const std::string& argument);
/// A sequence of integers (an int or a list).
std::vector<int> integers(const py::handle& values, const std::string& argument);
/// A sequence of strings (a str or a list).
std::vector<std::string> strings(const py::handle& values, const std::string& argument);

// ---------------------------------------------------------------------------------------------
// The checks of arguments: the CLI's (cli/common.hpp) with the keyword named instead of the
// option.

/// harmonics: at least one, each >= `lowest` and once, not 0 alone (io::check_harmonics).
void check_harmonics(const std::vector<int>& harmonics, int lowest);
/// balance_harmonics K from `lowest` to 200; `why` says where the lowest comes from.
void check_balance_harmonics(int harmonics, int lowest, const std::string& why = "");
/// amplitude: at least one, each finite and > 0.
void check_amplitudes(const std::vector<double>& amplitudes);

// ---------------------------------------------------------------------------------------------
// Tests (records and stepped-sine rows).

/// One sine test as Python holds it: a time record (Record) or a stepped-sine row
/// (SteppedSineRow), shared by the arrays that view its samples.
struct Test {
  identify::SineTest test;
  std::vector<std::string> comments; ///< a record's comment lines (simulated: how it was made)
  std::vector<std::string> warnings; ///< from its simulation
};
using TestPtr = std::shared_ptr<Test>;
struct Record : Test {};
struct SteppedSineRow : Test {};

/// A str or an os.PathLike.
bool is_path(const py::handle& item);

/// Records, stepped-sine rows and paths of files holding them (CSV records and tables,
/// universal files) in a list, as the tests they are. Paths are read as `jointid identify`
/// reads its TESTS (io::read_tests: a file given twice is refused).
std::vector<TestPtr> tests_of(const py::handle& items);

/// A test as its Python class (Record or SteppedSineRow, as its content says).
py::object to_python(const TestPtr& test);

/// The tests reduced to harmonics (identify::measure), without copying their samples.
std::vector<identify::Measurement> measure(const std::vector<TestPtr>& tests,
                                           const identify::MeasureOptions& options);

// The parts of the module, one file each.
void bind_model(py::module_& m);
void bind_records(py::module_& m);
void bind_identify(py::module_& m);
void bind_discover(py::module_& m);
void bind_response(py::module_& m);
void bind_modal_fit(py::module_& m);

} // namespace jointid::python

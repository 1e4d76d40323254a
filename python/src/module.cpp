// The module jointid._jointid: the bindings, one file per area (docs/python.md); the package
// jointid (python/jointid/__init__.py) re-exports them.
#include "common.hpp"

#include <exception>
#include <stdexcept>

namespace py = pybind11;

PYBIND11_MODULE(_jointid, m) {
  using namespace jointid::python;
  m.doc() = "jointid: identify non-linear joints of structures from vibration tests (the C++ "
            "library's objects; see docs/python.md).";
  m.attr("__version__") = JOINTID_VERSION;
  // Bad input (a file, a key, an argument): the message the CLI prints, naming file, line, key
  // or argument and what was expected. A ValueError, so that `except ValueError` takes it too.
  static auto& error = py::register_exception<jointid::io::Error>(m, "Error", PyExc_ValueError);
  // The library refusing its input (a record that cannot give the harmonics asked, a joint no
  // test measures): bad input as well, with the words the CLI prints.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const std::invalid_argument& e) {
      error(e.what());
    }
  });
  bind_model(m);
  bind_records(m);
  bind_identify(m);
  bind_discover(m);
  bind_response(m);
  bind_modal_fit(m);
}

// The module jointid._jointid: the bindings, one file per area (docs/python.md); the package
// jointid (python/jointid/__init__.py) re-exports them.
#include "common.hpp"

namespace py = pybind11;

PYBIND11_MODULE(_jointid, m) {
  using namespace jointid::python;
  m.doc() = "jointid: identify non-linear joints of structures from vibration tests (the C++ "
            "library's objects; see docs/python.md).";
  m.attr("__version__") = JOINTID_VERSION;
  // Bad input (a file, a key, an argument): the message the CLI prints, naming file, line, key
  // or argument and what was expected. A ValueError, so that `except ValueError` takes it too.
  py::register_exception<jointid::io::Error>(m, "Error", PyExc_ValueError);
  bind_model(m);
  bind_records(m);
  bind_identify(m);
  bind_discover(m);
  bind_response(m);
}

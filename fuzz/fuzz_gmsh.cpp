// libFuzzer target: the Gmsh mesh reader, io::read_gmsh, then the named groups' queries.
// Contract: a result or io::Error; anything else escaping is a finding.
#include "fuzz_input.hpp"
#include "io/files.hpp"
#include "io/gmsh.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size > 64 * 1024) return -1;
  const auto path = jointid::fuzz::input_file("mesh.msh", data, size);
  try {
    const auto mesh = jointid::io::read_gmsh(path);
    for (const auto& [key, name] : mesh.names) {
      try {
        (void)mesh.nodes_in(name);
        if (key.first == 1) (void)mesh.elements_in(name);
      } catch (const jointid::io::Error&) {
      }
    }
  } catch (const jointid::io::Error&) {
  }
  return 0;
}

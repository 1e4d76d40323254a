#pragma once
/// A model file written from another: the starting model of `jointid discover` with the joints
/// it ended at, so that `simulate`, `compare`, `response` and another `discover` read the
/// discovered model directly (docs/commands/discover.md, "Outputs").
#include "joints/joint.hpp"

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace jointid::io {

/// The text of the model file `start` with each of its own [[joints]] given the terms and
/// values of the joint of that name in `joints`, and the substructure's damping scaled by
/// `damping_scale`, to be written at `target`:
/// - every other table is copied (keys in TOML's order; comments are not kept), and a relative
///   path in it (a Gmsh mesh, matrices, FRF files, other model files) is rewritten to start from
///   `target`'s directory;
/// - a joint keeps its name, nodes and DOF; every value of `joints` is written (as given);
///   `fixed` lists what `joints` hold fixed;
/// - a joint that comes from a part ([[substructures]]) must be unchanged: it cannot be written
///   without rewriting that part's file;
/// - the damping scale multiplies [damping] modal or rayleigh, or [modal] damping; a scale other
///   than 1 on [[substructures]] or [frf] cannot be written;
/// - `header` becomes the file's first comment lines.
/// The text is read back (io::read_model, paths from `target`'s directory) and its joints
/// compared with `joints` before it is returned; `target`'s directory must exist. Throws
/// io::Error saying what cannot be written.
std::string model_with_joints(const std::filesystem::path& start,
                              const std::vector<joints::Joint>& joints, double damping_scale,
                              const std::filesystem::path& target, std::string_view header);

} // namespace jointid::io

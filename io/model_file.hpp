#pragma once
/// The model file (TOML, DESIGN.md's contract): the linear substructure and its joints.
#include "fem/model.hpp"
#include "joints/joint.hpp"

#include <filesystem>
#include <vector>

namespace jointid::io {

struct ModelFile {
  fem::Model model;
  std::vector<joints::Joint> joints;
  std::filesystem::path path; ///< the file it was read from, for messages
};

/// Reads and checks a model file: every key known and of the right type, every reference
/// resolved, every element in exactly one element set, the model valid (fem::Model::validate)
/// and the joints on free DOFs (joints::validate_joints). Extension to the contract: a joint's
/// `fixed = ["k"]` lists terms whose `values` are known and held during identification.
/// Throws io::Error naming the file, line, key and what was expected.
ModelFile read_model(const std::filesystem::path& path);

} // namespace jointid::io

#pragma once
/// A model given as a TOML document in memory instead of a file (e.g. built from Python's
/// dicts, python/): the same contract and checks as io::read_model (io/model_file.hpp). Apart
/// from io/model_file.hpp because it brings in toml++.
#include "io/model_file.hpp"

#include <toml++/toml.h>

#include <filesystem>

namespace jointid::io {

/// Reads and checks `document` as read_model(path) reads a file's: `path` names it in messages
/// (which have no line numbers when the document was built rather than parsed) and relative
/// paths in it (a Gmsh mesh, matrices, FRF files, other model files) start from its directory.
/// Throws io::Error as read_model does.
ModelFile read_model(const toml::table& document, const std::filesystem::path& path);

} // namespace jointid::io

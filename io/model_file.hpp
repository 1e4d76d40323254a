#pragma once
/// The model file (TOML, DESIGN.md's contract): the linear substructure and its joints.
#include "fem/dof.hpp"
#include "fem/model.hpp"
#include "frf/modal_model.hpp"
#include "frf/substructure.hpp"
#include "io/gmsh.hpp"
#include "joints/joint.hpp"

#include <filesystem>
#include <optional>
#include <string_view>
#include <vector>

namespace jointid::io {

struct ModelFile {
  fem::Model model; ///< the finite element model (left empty with [modal])
  std::vector<joints::Joint> joints;
  std::vector<int> joint_lines;         ///< each joint's line in `path` (0: from a part's file)
  std::filesystem::path path;           ///< the file it was read from, for messages
  std::optional<GmshMesh> mesh;         ///< the mesh it references, if any (its named groups)
  std::optional<frf::ModalModel> modal; ///< the substructure given by its modes ([modal])
  /// The substructure given by K and M ([matrices]: MatrixMarket files and a DOF table).
  std::optional<fem::Assembled> matrices;
  /// The substructure given by measured FRFs ([frf]: universal files or CSV tables).
  std::optional<frf::MeasuredFrf> measured;
  /// Several substructures side by side ([[substructures]]): the model files, and the offset
  /// added to each one's node ids. `joints` holds the parts' joints too (nodes offset).
  std::vector<ModelFile> parts;
  std::vector<int> node_offsets;

  /// The substructure's DOFs without assembling it: equation e as substructure().dofs().
  fem::DofMap dof_map() const;

  /// The linear substructure: the modal model, the matrices or the FRFs if given, else the finite
  /// element model (validated and assembled on each call).
  frf::Substructure substructure() const;
};

/// Reads and checks a model file: every key known and of the right type, every reference
/// resolved, every element in exactly one element set, the model valid (fem::Model::validate)
/// and the joints on free DOFs (joints::validate_joints). Extension to the contract: a joint's
/// `fixed = ["k"]` lists terms whose `values` are known and held during identification.
/// With [modal] (a substructure given by its modes, DESIGN.md) the finite element tables are
/// errors, [model] is optional (dimension = 2 allows only ux, uy, rz) and the joints must be on
/// the listed DOFs (fem::DofMap::from_dofs). With [matrices] (K = "k.mtx", M = "m.mtx", dofs =
/// "dofs.txt" or a list; paths relative to the model file) the same holds, [damping] is allowed,
/// and the matrices are checked (sizes against the DOF table, symmetry, masses). With [frf]
/// (files = ["h.uff", "h.csv"], io/measured_frf_file.hpp) the DOFs are those the FRFs measure,
/// [damping] is an error, and joints must be on them. With [[substructures]] (file = "a.toml",
/// node_offset = 1000; any model file but another composite) the parts are read, their nodes
/// offset (a node in two parts is an error naming both), their joints taken along, and the
/// file's joints may join them.
/// Throws io::Error naming the file, line, key and what was expected.
ModelFile read_model(const std::filesystem::path& path);

/// "NODE:DOF" of the model, e.g. "7:uy", where NODE is a node id or, with a Gmsh mesh, the
/// name of a physical group holding exactly one node ("tip:uy"). The DOF is not checked
/// against the model (fem::DofMap::equation does that). Throws std::invalid_argument saying
/// what is wrong (no colon, unknown group and the groups there are, a group of several nodes).
fem::NodeDof resolve_node_dof(const ModelFile& file, std::string_view text);

} // namespace jointid::io

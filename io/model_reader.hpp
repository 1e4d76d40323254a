#pragma once
/// Internal to jointid_io: what the readers of the model file's sections share. A Table checks
/// one TOML table's keys and converts its values, reporting file, line and key; a ModelReading
/// holds the file being read, what its sections have given so far (the lines of nodes,
/// elements and joints for the checks that come after reading, the names of materials and
/// sections, the mesh) and which kind of substructure it is. One reader per section:
///   io/model_file.cpp            read_model: the file's tables and the kind of substructure
///   io/model_elements.cpp        [model], [[materials]], [[sections]], [mesh], [[element_sets]]
///   io/model_supports.cpp        [[supports]], [[masses]], [[springs]], [damping], [options]
///   io/model_joints.cpp          [[joints]], and the joints checked on the DOFs
///   io/model_modal.cpp           [modal]
///   io/model_substructures.cpp   [matrices], [frf], [[substructures]]
#include "io/model_file.hpp"

#include <toml++/toml.h>

#include <filesystem>
#include <initializer_list>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace jointid::io::detail {

int line_of(const toml::node& n);
/// A value as the user wrote it, for "got ..." in messages.
std::string shown(const toml::node& n);
/// "a, b, c".
std::string joined(const std::vector<std::string>& items);
/// "1, 2, 3" (the first 10, then "and N more").
std::string id_list(const std::vector<int>& ids);

/// The model file, for messages: "<file>:<line>: <what>" (line 0: no line).
struct File {
  std::string name;
  [[noreturn]] void fail(int line, const std::string& what) const;
};

/// One TOML table and its place in the file ("[[joints]] 'tip'"): checks its keys against the
/// allowed ones and converts values, reporting file, line, key and the expected type.
class Table {
public:
  Table(const File& file, const toml::table& table, std::string where,
        std::initializer_list<std::string_view> keys);

  const std::string& where() const { return where_; }
  int line() const { return line_of(table_); }
  bool has(std::string_view key) const { return table_.contains(key); }
  const toml::node* get(std::string_view key) const { return table_.get(key); }

  // The document itself (no label) has no line of its own: what is missing from it is not at
  // line 1.
  [[noreturn]] void fail(const std::string& what) const;
  [[noreturn]] void fail_at(const toml::node& n, const std::string& label,
                            const std::string& what) const;

  const toml::node& need(std::string_view key, std::string_view expected) const;

  // Conversions of any node; `label` says where it is ("key 'E'", "key 'nodes', entry 3").
  double to_number(const toml::node& n, const std::string& label) const;
  int to_integer(const toml::node& n, const std::string& label) const;
  std::string to_string(const toml::node& n, const std::string& label) const;
  const toml::array& to_array(const toml::node& n, const std::string& label,
                              std::string_view of) const;
  fem::Dof to_dof(const toml::node& n, const std::string& label) const;
  Eigen::Vector3d to_vector3(const toml::node& n, const std::string& label) const;

  static std::string key_label(std::string_view key);

  // Typed access by key.
  double number(std::string_view key) const;
  std::optional<double> optional_number(std::string_view key) const;
  double positive(std::string_view key, std::string_view unit) const;
  double non_negative(const toml::node& n, std::string_view key, std::string_view unit) const;
  int integer(std::string_view key) const;
  std::string string(std::string_view key) const;
  fem::Dof dof(std::string_view key) const;
  std::optional<bool> optional_boolean(std::string_view key) const;

private:
  std::string prefix() const { return where_.empty() ? "" : where_ + ": "; }
  const File& file_;
  const toml::table& table_;
  std::string where_;
};

/// The tables of an array of tables ([[joints]]), or none when the key is absent.
std::vector<const toml::table*> tables(const Table& root, std::string_view key);
/// The table [key], or nullptr when the key is absent.
const toml::table* table(const Table& root, std::string_view key);
/// "[[joints]] 'tip'" or "[[supports]] node 1" when the table has that key, else
/// "[[joints]] #2".
std::string item_label(const toml::table& t, std::string_view array, std::size_t index,
                       std::string_view key);

/// A model file being read: the file for messages, the result so far, and what the section
/// readers leave for the ones after them and for the checks at the end.
struct ModelReading {
  explicit ModelReading(const std::filesystem::path& path)
      : file{path.string()}, directory(path.parent_path()) {}

  File file;
  std::filesystem::path directory; ///< relative paths in the file start here
  ModelFile out;
  fem::Model& model() { return out.model; }

  std::optional<GmshMesh> mesh;
  std::map<int, int> node_lines, element_lines, element_position;
  std::map<int, std::string> element_origin; ///< "mesh.msh:LINE" of elements read from Gmsh
  int elements_line = 0;
  std::map<std::string, int> material_index, section_index;
  std::vector<int> joint_lines;
  int iwan_sliders = joints::default_iwan_sliders; ///< [options] iwan_sliders
  std::optional<frf::ModalModel> modal;            ///< [modal], while it is read
  int modal_line = 0;                              ///< [modal]'s line
  std::optional<fem::Assembled> matrices;          ///< [matrices], while it is read
  bool reading_frf = false;                        ///< [frf], while it is read

  /// A node id of the model, or the name of a Gmsh group of exactly one node; with
  /// `zero_is_ground`, 0 is the ground.
  int node_id(const Table& t, const toml::node& n, const std::string& label,
              bool zero_is_ground = false) const;
  int node_key(const Table& t, std::string_view key) const;
  /// The nodes of a named Gmsh physical group (points, or every node of a group of lines).
  std::vector<int> group_nodes(const Table& t, const toml::node& n, const std::string& label) const;
};

// The finite element model (io/model_elements.cpp, io/model_supports.cpp).
void read_model_table(ModelReading& ctx, const Table& root);
void read_materials(ModelReading& ctx, const Table& root);
void read_sections(ModelReading& ctx, const Table& root);
void read_mesh(ModelReading& ctx, const Table& root);
void read_element_sets(ModelReading& ctx, const Table& root);
/// The library's own checks of the finite element model and its joints, reported with the
/// file (and the line where it is known).
void check_finite_elements(ModelReading& ctx);
void read_supports(ModelReading& ctx, const Table& root);
void read_masses(ModelReading& ctx, const Table& root);
void read_springs(ModelReading& ctx, const Table& root);
void read_damping(ModelReading& ctx, const Table& root);
void read_options(ModelReading& ctx, const Table& root);

// The joints (io/model_joints.cpp).
void read_joints(ModelReading& ctx, const Table& root);
/// Joints on free DOFs, each reported at its line; then the checks across joints.
void check_joints(const ModelReading& ctx, const fem::DofMap& dofs);

// The substructures given otherwise than by a mesh (io/model_modal.cpp,
// io/model_substructures.cpp): each reads its whole file.
/// The finite element tables in a file that gives the substructure otherwise are errors
/// (`why` says how it is given); [damping] too unless allowed.
void reject_finite_element_keys(const Table& root, bool damping_allowed, std::string_view why);
ModelFile read_modal_file(ModelReading& ctx, const Table& root);
ModelFile read_matrices_file(ModelReading& ctx, const Table& root);
ModelFile read_frf_file(ModelReading& ctx, const Table& root);
ModelFile read_composite_file(ModelReading& ctx, const Table& root);

} // namespace jointid::io::detail

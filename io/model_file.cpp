#include "io/model_file.hpp"

#include "fem/dof_map.hpp"
#include "fem/elements.hpp"
#include "io/files.hpp"
#include "io/gmsh.hpp"
#include "io/matrix_market.hpp"
#include "io/measured_frf_file.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <initializer_list>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

namespace jointid::io {

namespace {

int line_of(const toml::node& n) {
  return static_cast<int>(n.source().begin.line);
}

// A value as the user wrote it, for "got ..." in messages.
std::string shown(const toml::node& n) {
  switch (n.type()) {
  case toml::node_type::string:
    return "\"" + std::string(n.as_string()->get()) + "\"";
  case toml::node_type::integer:
    return std::to_string(n.as_integer()->get());
  case toml::node_type::floating_point:
    return fmt::format("{}", n.as_floating_point()->get());
  case toml::node_type::boolean:
    return n.as_boolean()->get() ? "true" : "false";
  case toml::node_type::array:
    return "an array";
  case toml::node_type::table:
    return "a table";
  default:
    return "a date/time";
  }
}

std::string joined(const std::vector<std::string>& items) {
  std::string out;
  for (const auto& s : items)
    out += (out.empty() ? "" : ", ") + s;
  return out;
}

std::string id_list(const std::vector<int>& ids) {
  std::string out;
  const std::size_t shown_max = 10;
  for (std::size_t i = 0; i < ids.size() && i < shown_max; ++i)
    out += (i ? ", " : "") + std::to_string(ids[i]);
  if (ids.size() > shown_max) out += fmt::format(" and {} more", ids.size() - shown_max);
  return out;
}

struct File {
  std::string name;
  [[noreturn]] void fail(int line, const std::string& what) const {
    throw Error(line > 0 ? fmt::format("{}:{}: {}", name, line, what)
                         : fmt::format("{}: {}", name, what));
  }
};

// One TOML table and its place in the file ("[[joints]] 'tip'"): checks its keys against the
// allowed ones and converts values, reporting file, line, key and the expected type.
class Table {
public:
  Table(const File& file, const toml::table& table, std::string where,
        std::initializer_list<std::string_view> keys)
      : file_(file), table_(table), where_(std::move(where)) {
    // Report the first unknown key in the file (the table iterates in key order).
    const toml::key* unknown = nullptr;
    int unknown_line = 0;
    for (auto&& [key, value] : table_) {
      bool known = false;
      for (std::string_view k : keys)
        known = known || key.str() == k;
      if (known) continue;
      const int line =
          key.source().begin.line > 0 ? static_cast<int>(key.source().begin.line) : line_of(value);
      if (!unknown || line < unknown_line) unknown = &key, unknown_line = line;
    }
    if (unknown) {
      const std::vector<std::string> names(keys.begin(), keys.end());
      file_.fail(unknown_line, prefix() + "unknown key '" + std::string(unknown->str()) +
                                   "' (expected one of: " + joined(names) + ")");
    }
  }

  const std::string& where() const { return where_; }
  int line() const { return line_of(table_); }
  bool has(std::string_view key) const { return table_.contains(key); }
  const toml::node* get(std::string_view key) const { return table_.get(key); }

  // The document itself (no label) has no line of its own: what is missing from it is not at
  // line 1.
  [[noreturn]] void fail(const std::string& what) const {
    file_.fail(where_.empty() ? 0 : line(), prefix() + what);
  }
  [[noreturn]] void fail_at(const toml::node& n, const std::string& label,
                            const std::string& what) const {
    file_.fail(line_of(n) > 0 ? line_of(n) : line(), prefix() + label + ": " + what);
  }

  const toml::node& need(std::string_view key, std::string_view expected) const {
    const toml::node* n = table_.get(key);
    if (!n) fail(fmt::format("missing key '{}' (expected {})", key, expected));
    return *n;
  }

  // Conversions of any node; `label` says where it is ("key 'E'", "key 'nodes', entry 3").
  double to_number(const toml::node& n, const std::string& label) const {
    std::optional<double> v;
    if (const auto* i = n.as_integer()) v = static_cast<double>(i->get());
    if (const auto* f = n.as_floating_point()) v = f->get();
    if (!v) fail_at(n, label, "expected a number, got " + shown(n));
    if (!std::isfinite(*v)) fail_at(n, label, "expected a finite number, got " + shown(n));
    return *v;
  }
  int to_integer(const toml::node& n, const std::string& label) const {
    const auto* i = n.as_integer();
    if (!i) fail_at(n, label, "expected an integer, got " + shown(n));
    if (i->get() < std::numeric_limits<int>::min() || i->get() > std::numeric_limits<int>::max())
      fail_at(n, label, "expected an integer of at most 9 digits, got " + shown(n));
    return static_cast<int>(i->get());
  }
  std::string to_string(const toml::node& n, const std::string& label) const {
    const auto* s = n.as_string();
    if (!s) fail_at(n, label, "expected a string, got " + shown(n));
    return s->get();
  }
  const toml::array& to_array(const toml::node& n, const std::string& label,
                              std::string_view of) const {
    const auto* a = n.as_array();
    if (!a) fail_at(n, label, fmt::format("expected an array of {}, got {}", of, shown(n)));
    return *a;
  }
  fem::Dof to_dof(const toml::node& n, const std::string& label) const {
    const std::string text = to_string(n, label);
    try {
      return fem::parse_dof(text);
    } catch (const std::invalid_argument&) {
      fail_at(n, label, "expected one of ux, uy, uz, rx, ry, rz, got " + shown(n));
    }
  }
  Eigen::Vector3d to_vector3(const toml::node& n, const std::string& label) const {
    const toml::array& a = to_array(n, label, "3 numbers");
    if (a.size() != 3) fail_at(n, label, fmt::format("expected 3 numbers, got {}", a.size()));
    return {to_number(a[0], label), to_number(a[1], label), to_number(a[2], label)};
  }

  static std::string key_label(std::string_view key) { return fmt::format("key '{}'", key); }

  // Typed access by key.
  double number(std::string_view key) const {
    return to_number(need(key, "a number"), key_label(key));
  }
  std::optional<double> optional_number(std::string_view key) const {
    if (const auto* n = get(key)) return to_number(*n, key_label(key));
    return std::nullopt;
  }
  double positive(std::string_view key, std::string_view unit) const {
    const double v = number(key);
    if (!(v > 0.0))
      fail_at(*get(key), key_label(key), fmt::format("expected a value > 0 {}, got {}", unit, v));
    return v;
  }
  double non_negative(const toml::node& n, std::string_view key, std::string_view unit) const {
    const double v = to_number(n, key_label(key));
    if (!(v >= 0.0))
      fail_at(n, key_label(key), fmt::format("expected a value >= 0 {}, got {}", unit, v));
    return v;
  }
  int integer(std::string_view key) const {
    return to_integer(need(key, "an integer"), key_label(key));
  }
  std::string string(std::string_view key) const {
    return to_string(need(key, "a string"), key_label(key));
  }
  fem::Dof dof(std::string_view key) const {
    return to_dof(need(key, "one of ux, uy, uz, rx, ry, rz"), key_label(key));
  }
  std::optional<bool> optional_boolean(std::string_view key) const {
    const auto* n = get(key);
    if (!n) return std::nullopt;
    const auto* b = n->as_boolean();
    if (!b) fail_at(*n, key_label(key), "expected true or false, got " + shown(*n));
    return b->get();
  }

private:
  std::string prefix() const { return where_.empty() ? "" : where_ + ": "; }
  const File& file_;
  const toml::table& table_;
  std::string where_;
};

// The tables of an array of tables ([[joints]]), or none when the key is absent.
std::vector<const toml::table*> tables(const Table& root, std::string_view key) {
  std::vector<const toml::table*> out;
  const toml::node* n = root.get(key);
  if (!n) return out;
  const std::string label = Table::key_label(key);
  const toml::array& a = root.to_array(*n, label, fmt::format("tables (write [[{}]])", key));
  for (const auto& entry : a) {
    const auto* t = entry.as_table();
    if (!t)
      root.fail_at(entry, label,
                   fmt::format("expected a table (write [[{}]]), got {}", key, shown(entry)));
    out.push_back(t);
  }
  return out;
}

const toml::table* table(const Table& root, std::string_view key) {
  const toml::node* n = root.get(key);
  if (!n) return nullptr;
  const auto* t = n->as_table();
  if (!t)
    root.fail_at(*n, Table::key_label(key),
                 fmt::format("expected a table (write [{}]), got {}", key, shown(*n)));
  return t;
}

// "[[joints]] 'tip'" or "[[supports]] node 1" when the table has that key, else "[[joints]] #2".
std::string item_label(const toml::table& t, std::string_view array, std::size_t index,
                       std::string_view key) {
  if (const auto* n = t.get(key)) {
    if (const auto* s = n->as_string()) return fmt::format("[[{}]] '{}'", array, s->get());
    if (const auto* i = n->as_integer()) return fmt::format("[[{}]] {} {}", array, key, i->get());
  }
  return fmt::format("[[{}]] #{}", array, index + 1);
}

fem::ElementType parse_element_type(const Table& t) {
  const toml::node& n = t.need("type", "one of beam, frame2d, frame3d");
  const std::string type = t.to_string(n, "key 'type'");
  if (type == "beam") return fem::ElementType::beam;
  if (type == "frame2d") return fem::ElementType::frame2d;
  if (type == "frame3d") return fem::ElementType::frame3d;
  t.fail_at(n, "key 'type'", "expected one of beam, frame2d, frame3d, got " + shown(n));
}

// Reads the whole file into a Model and joints, remembering the lines of nodes, elements and
// joints for the checks that come after reading.
class ModelReader {
public:
  ModelReader(const std::filesystem::path& path, const toml::table& root)
      : file_{path.string()}, root_(root), directory_(path.parent_path()) {}

  ModelFile read() {
    Table root(file_, root_, "",
               {"model", "materials", "sections", "mesh", "element_sets", "supports", "masses",
                "springs", "damping", "options", "joints", "modal", "matrices", "frf",
                "substructures"});
    {
      const toml::node* second = nullptr;
      std::vector<std::string> given;
      for (const char* key : {"modal", "matrices", "frf", "substructures"})
        if (const toml::node* n = root.get(key)) {
          given.push_back(std::string("[") + key + "]");
          if (given.size() == 2) second = n;
        }
      if (second)
        root.fail_at(*second, given[1],
                     "give the substructure one way only: by its modes ([modal]), its matrices "
                     "([matrices]), measured FRFs ([frf]) or as several ([[substructures]]); this "
                     "file has " +
                         given[0] + " and " + given[1]);
    }
    if (root.has("modal")) return read_modal_file(root);
    if (root.has("matrices")) return read_matrices_file(root);
    if (root.has("frf")) return read_frf_file(root);
    if (root.has("substructures")) return read_composite_file(root);
    read_model_table(root);
    read_materials(root);
    read_sections(root);
    read_mesh(root);
    read_element_sets(root);
    read_supports(root);
    read_masses(root);
    read_springs(root);
    read_damping(root);
    read_options(root);
    read_joints(root);
    check();
    out_.mesh = std::move(mesh_);
    return std::move(out_);
  }

private:
  fem::Model& model() { return out_.model; }

  int node_id(const Table& t, const toml::node& n, const std::string& label,
              bool zero_is_ground = false) {
    if (n.is_string()) { // a Gmsh physical group with exactly one node
      const std::vector<int> ids = group_nodes(t, n, label);
      if (ids.size() != 1)
        t.fail_at(n, label,
                  fmt::format("group {} holds {} nodes ({}); expected exactly one", shown(n),
                              ids.size(), id_list(ids)));
      return ids.front();
    }
    const int id = t.to_integer(n, label);
    if (zero_is_ground && id == 0) return 0;
    if (!node_lines_.count(id))
      t.fail_at(n, label,
                modal_      ? fmt::format("node {} is not among the [modal] dofs", id)
                : matrices_ ? fmt::format("node {} is not in the [matrices] DOF table", id)
                : frf_      ? fmt::format("node {} has no measured FRF in [frf]", id)
                            : fmt::format("node {} does not exist in [mesh] nodes", id));
    return id;
  }
  int node_key(const Table& t, std::string_view key) {
    return node_id(t, t.need(key, "a node id or a Gmsh group name"), Table::key_label(key));
  }
  // The nodes of a named Gmsh physical group (points, or every node of a group of lines).
  std::vector<int> group_nodes(const Table& t, const toml::node& n, const std::string& label) {
    const std::string name = t.to_string(n, label);
    if (modal_ || matrices_ || frf_)
      t.fail_at(n, label,
                std::string("expected a node id; a substructure given by ") +
                    (modal_      ? "its modes ([modal])"
                     : matrices_ ? "its matrices ([matrices])"
                                 : "measured FRFs ([frf])") +
                    " has no groups such as " + shown(n));
    if (!mesh_)
      t.fail_at(n, label,
                "expected a node id; group names such as " + shown(n) +
                    " need a Gmsh mesh ([mesh] file = \"x.msh\")");
    try {
      return mesh_->nodes_in(name);
    } catch (const Error& e) {
      t.fail_at(n, label, e.what());
    }
  }

  // A substructure given by its modes: [modal], an optional [model] and the joints; the finite
  // element tables are errors.
  ModelFile read_modal_file(const Table& root) {
    reject_finite_element_keys(root);
    if (root.has("model")) read_model_table(root);
    read_modal(root);
    read_joints(root);
    check_modal();
    return std::move(out_);
  }

  void reject_finite_element_keys(const Table& root, bool damping_allowed = false,
                                  std::string_view why = "[modal]: the substructure is given by "
                                                         "its modes") {
    const toml::node* first = nullptr;
    std::string_view first_key;
    for (std::string_view key : {"mesh", "element_sets", "materials", "sections", "supports",
                                 "masses", "springs", "damping", "options"}) {
      if (damping_allowed && key == "damping") continue;
      const toml::node* n = root.get(key);
      if (!n) continue;
      // An array of tables ([[supports]]) is reported at its first table.
      if (const auto* a = n->as_array(); a && !a->empty() && line_of((*a)[0]) > 0) n = &(*a)[0];
      if (!first || line_of(*n) < line_of(*first)) first = n, first_key = key;
    }
    if (first)
      root.fail_at(*first, Table::key_label(first_key), "not used with " + std::string(why));
  }

  // A substructure given by its stiffness and mass matrices (MatrixMarket files exported by
  // another program) and a DOF table naming their rows: [matrices], an optional [model] and
  // [damping], and the joints; the other finite element tables are errors.
  ModelFile read_matrices_file(const Table& root) {
    reject_finite_element_keys(root, true,
                               "[matrices]: the substructure is given by its K and M matrices");
    if (root.has("model")) read_model_table(root);
    Table t(file_, *table(root, "matrices"), "[matrices]", {"K", "M", "dofs"});
    const int line = t.line();
    auto file_key = [&](std::string_view key, std::string_view what) {
      const toml::node& n = t.need(key, what);
      return directory_ / t.to_string(n, Table::key_label(key));
    };
    const auto K_path = file_key("K", "the stiffness matrix, a MatrixMarket file (\"k.mtx\")");
    const auto M_path = file_key("M", "the mass matrix, a MatrixMarket file (\"m.mtx\")");
    const toml::node& d = t.need("dofs", "the DOF table: a file with one NODE:DOF per line, or a "
                                         "list such as [\"1:uy\", \"1:rz\"]");
    std::vector<fem::NodeDof> dofs;
    if (d.is_string()) {
      dofs = read_dof_table(directory_ / t.to_string(d, "key 'dofs'"));
    } else {
      const toml::array& list =
          t.to_array(d, "key 'dofs'", "\"<node>:<dof>\" strings such as \"4:uy\"");
      for (std::size_t i = 0; i < list.size(); ++i) {
        const std::string label = fmt::format("key 'dofs', entry {}", i + 1);
        const std::string text = t.to_string(list[i], label);
        fem::NodeDof nd;
        try {
          nd = fem::parse_node_dof(text);
        } catch (const std::invalid_argument&) {
          t.fail_at(list[i], label,
                    "expected \"<node>:<dof>\" such as \"4:uy\", got " + shown(list[i]));
        }
        if (nd.node <= 0)
          t.fail_at(list[i], label, "node ids must be > 0 (0 means ground), got " + shown(list[i]));
        if (std::find(dofs.begin(), dofs.end(), nd) != dofs.end())
          t.fail_at(list[i], label, shown(list[i]) + " is listed twice");
        dofs.push_back(nd);
      }
      if (dofs.empty()) t.fail_at(d, "key 'dofs'", "expected at least one DOF");
    }
    if (root.has("model") && model().dimension == 2)
      for (const fem::NodeDof& nd : dofs)
        if (nd.dof != fem::Dof::ux && nd.dof != fem::Dof::uy && nd.dof != fem::Dof::rz)
          file_.fail(line, "[matrices]: a planar model (dimension = 2) has only ux, uy and rz, "
                           "the DOF table has " +
                               fem::to_string(nd));
    fem::Assembled& system = matrices_.emplace();
    system.dofs = fem::DofMap::from_dofs(dofs);
    system.K = read_matrix_market(K_path); // their errors name the .mtx file and line
    system.M = read_matrix_market(M_path);
    for (const fem::NodeDof& nd : dofs)
      node_lines_.emplace(nd.node, line);
    read_damping(root);
    try {
      (void)frf::Substructure(system, model().damping); // sizes, symmetry, masses
    } catch (const std::invalid_argument& e) {
      file_.fail(line, fmt::format("[matrices] ({}, {}, {} DOFs): {}", K_path.filename().string(),
                                   M_path.filename().string(), dofs.size(), e.what()));
    }
    read_joints(root);
    check_joints(system.dofs);
    out_.matrices = std::move(matrices_);
    return std::move(out_);
  }

  // A substructure given by measured FRFs: [frf] files = [...] (universal files or CSV tables,
  // relative to the model file), an optional [model] and the joints; the finite element tables
  // and [damping] are errors (the damping is in the measurement).
  ModelFile read_frf_file(const Table& root) {
    reject_finite_element_keys(root, false, "[frf]: the substructure is given by measured FRFs");
    if (root.has("model")) read_model_table(root);
    Table t(file_, *table(root, "frf"), "[frf]", {"files"});
    frf_ = true;
    const int line = t.line();
    const toml::node& n = t.need("files", "the FRF files: a list such as [\"drive_7uy.uff\", "
                                          "\"drive_4uy.csv\"] (universal files or CSV tables)");
    std::vector<std::filesystem::path> files;
    if (n.is_string()) {
      files.push_back(directory_ / t.to_string(n, "key 'files'"));
    } else {
      const toml::array& list = t.to_array(n, "key 'files'", "file names");
      for (std::size_t i = 0; i < list.size(); ++i)
        files.push_back(directory_ /
                        t.to_string(list[i], fmt::format("key 'files', entry {}", i + 1)));
      if (files.empty()) t.fail_at(n, "key 'files'", "expected at least one file");
    }
    frf::MeasuredFrf frf = read_measured_frf(files); // its errors name the data file and line
    if (root.has("model") && model().dimension == 2)
      for (const fem::NodeDof& nd : frf.dofs)
        if (nd.dof != fem::Dof::ux && nd.dof != fem::Dof::uy && nd.dof != fem::Dof::rz)
          file_.fail(line, "[frf]: a planar model (dimension = 2) has only ux, uy and rz, the "
                           "FRFs have " +
                               fem::to_string(nd));
    try {
      frf.validate();
    } catch (const std::invalid_argument& e) {
      file_.fail(line, std::string("[frf]: ") + e.what());
    }
    for (const fem::NodeDof& nd : frf.dofs)
      node_lines_.emplace(nd.node, line);
    read_joints(root);
    check_joints(fem::DofMap::from_dofs(frf.dofs));
    out_.measured = std::move(frf);
    return std::move(out_);
  }

  // Several substructures side by side: [[substructures]] file = "part.toml" (any model file
  // but another composite), node_offset = N (added to its node ids and its joints' nodes), an
  // optional [model], and the joints between them. The parts' own joints come along.
  ModelFile read_composite_file(const Table& root) {
    // A part that lists substructures itself (or the file itself, read again as its own part)
    // is refused here, before its parts are read: no recursion.
    static thread_local int depth = 0;
    if (depth > 0)
      root.fail_at(*root.get("substructures"), "[[substructures]]",
                   "this file is a part of a model made of substructures and may not list "
                   "substructures itself: list its parts in that model instead");
    struct Depth {
      Depth() { ++depth; }
      ~Depth() { --depth; }
    } const inside;
    reject_finite_element_keys(root, false,
                               "[[substructures]]: the substructure is made of the files it lists");
    if (root.has("model")) read_model_table(root);
    const auto list = tables(root, "substructures");
    if (list.empty()) root.fail("[[substructures]]: expected at least one substructure");
    std::vector<fem::NodeDof> dofs;
    std::map<int, std::size_t> node_part;
    std::vector<int> part_lines;
    for (std::size_t i = 0; i < list.size(); ++i) {
      Table t(file_, *list[i], fmt::format("[[substructures]] entry {}", i + 1),
              {"file", "node_offset"});
      const std::filesystem::path path = directory_ / t.string("file");
      int offset = 0;
      if (const toml::node* n = t.get("node_offset")) {
        offset = t.to_integer(*n, "key 'node_offset'");
        if (offset < 0)
          t.fail_at(*n, "key 'node_offset'",
                    fmt::format("expected an integer >= 0, got {}", offset));
      }
      ModelFile part = read_model(path); // its errors name its own file and line
      const fem::DofMap map = part.dof_map();
      for (int e = 0; e < map.num_equations(); ++e) {
        fem::NodeDof nd = map.node_dof(e);
        nd.node += offset;
        const auto [at, fresh] = node_part.emplace(nd.node, i);
        if (!fresh && at->second != i)
          t.fail_at(*t.get("file"), "key 'file'",
                    fmt::format("node {} of {} (node {} + node_offset {}) is also a node of "
                                "substructure {} ({}): give one of them a node_offset",
                                nd.node, path.filename().string(), nd.node - offset, offset,
                                at->second + 1, out_.parts[at->second].path.filename().string()));
        node_lines_.emplace(nd.node, t.line());
        dofs.push_back(nd);
      }
      part_lines.push_back(t.line());
      out_.parts.push_back(std::move(part));
      out_.node_offsets.push_back(offset);
    }
    read_joints(root);
    check_joints(fem::DofMap::from_dofs(dofs));
    // The parts' own joints, their nodes moved by the offset; names stay unique.
    for (std::size_t p = 0; p < out_.parts.size(); ++p)
      for (joints::Joint j : out_.parts[p].joints) {
        j.node += out_.node_offsets[p];
        if (j.node_b != 0) j.node_b += out_.node_offsets[p];
        for (const joints::Joint& other : out_.joints)
          if (other.name == j.name)
            file_.fail(part_lines[p],
                       fmt::format("[[substructures]] entry {}: joint '{}' of {} has the name of "
                                   "another joint; rename one of them",
                                   p + 1, j.name, out_.parts[p].path.filename().string()));
        out_.joints.push_back(std::move(j));
      }
    return std::move(out_);
  }

  // [modal]: dofs, frequencies_hz, damping, shapes and the optional residual_flexibility.
  void read_modal(const Table& root) {
    Table t(file_, *table(root, "modal"), "[modal]",
            {"dofs", "frequencies_hz", "damping", "shapes", "residual_flexibility"});
    modal_line_ = t.line();
    frf::ModalModel& modal = modal_.emplace();

    const toml::node& dofs_node =
        t.need("dofs", "a list of \"<node>:<dof>\" such as [\"1:uy\", \"4:uy\"]");
    const toml::array& dofs =
        t.to_array(dofs_node, "key 'dofs'", "\"<node>:<dof>\" strings such as \"4:uy\"");
    if (dofs.empty()) t.fail_at(dofs_node, "key 'dofs'", "expected at least one DOF");
    const bool planar = root.has("model") && model().dimension == 2;
    for (std::size_t i = 0; i < dofs.size(); ++i) {
      const std::string label = fmt::format("key 'dofs', entry {}", i + 1);
      const std::string text = t.to_string(dofs[i], label);
      fem::NodeDof nd;
      try {
        nd = fem::parse_node_dof(text);
      } catch (const std::invalid_argument&) {
        t.fail_at(dofs[i], label,
                  "expected \"<node>:<dof>\" with a node id and one of ux, uy, uz, rx, ry, rz "
                  "(e.g. \"4:uy\"), got " +
                      shown(dofs[i]));
      }
      if (nd.node <= 0)
        t.fail_at(dofs[i], label,
                  fmt::format("node ids must be > 0 (0 means ground), got {}", shown(dofs[i])));
      for (std::size_t k = 0; k < i; ++k)
        if (modal.dofs[k] == nd)
          t.fail_at(dofs[i], label, fmt::format("{} is already entry {}", shown(dofs[i]), k + 1));
      if (planar && nd.dof != fem::Dof::ux && nd.dof != fem::Dof::uy && nd.dof != fem::Dof::rz)
        t.fail_at(dofs[i], label,
                  "a planar model (dimension = 2) has only ux, uy and rz, got " + shown(dofs[i]));
      modal.dofs.push_back(nd);
      node_lines_.emplace(nd.node, line_of(dofs[i]) > 0 ? line_of(dofs[i]) : t.line());
    }
    const std::size_t n = modal.dofs.size();

    const toml::node& f_node = t.need("frequencies_hz", "a list of natural frequencies in Hz");
    const toml::array& f = t.to_array(f_node, "key 'frequencies_hz'", "frequencies in Hz");
    if (f.empty()) t.fail_at(f_node, "key 'frequencies_hz'", "expected at least one mode");
    const std::size_t m = f.size();
    modal.frequencies_hz.resize(static_cast<Eigen::Index>(m));
    for (std::size_t r = 0; r < m; ++r) {
      const std::string label = fmt::format("key 'frequencies_hz', entry {}", r + 1);
      const double value = t.to_number(f[r], label);
      if (!(value >= 0.0))
        t.fail_at(f[r], label, fmt::format("expected a frequency >= 0 Hz, got {}", value));
      modal.frequencies_hz(static_cast<Eigen::Index>(r)) = value;
    }

    const toml::node& d_node = t.need("damping", "a list of modal damping ratios, one per mode");
    const toml::array& d = t.to_array(d_node, "key 'damping'", "damping ratios");
    if (d.size() != m)
      t.fail_at(d_node, "key 'damping'",
                fmt::format("expected {} damping ratio{} (one per entry of frequencies_hz), got {}",
                            m, m > 1 ? "s" : "", d.size()));
    modal.damping.resize(static_cast<Eigen::Index>(m));
    for (std::size_t r = 0; r < m; ++r) {
      const std::string label = fmt::format("key 'damping', entry {}", r + 1);
      const double value = t.to_number(d[r], label);
      if (!(value >= 0.0))
        t.fail_at(d[r], label, fmt::format("expected a damping ratio >= 0, got {}", value));
      modal.damping(static_cast<Eigen::Index>(r)) = value;
    }

    modal.shapes = matrix(t, "shapes", m, n, "one row per mode (as frequencies_hz)",
                          "one column per entry of dofs");
    if (t.has("residual_flexibility")) {
      const Eigen::MatrixXd R = matrix(t, "residual_flexibility", n, n, "one row per entry of dofs",
                                       "one column per entry of dofs");
      const double tolerance = 1e-9 * R.cwiseAbs().maxCoeff();
      const toml::array& rows = *t.get("residual_flexibility")->as_array();
      for (std::size_t i = 0; i < n; ++i)
        for (std::size_t j = i + 1; j < n; ++j) {
          const auto a = static_cast<Eigen::Index>(i), b = static_cast<Eigen::Index>(j);
          if (std::abs(R(a, b) - R(b, a)) > tolerance)
            t.fail_at((*rows[j].as_array())[i],
                      fmt::format("key 'residual_flexibility', row {}", j + 1),
                      fmt::format("expected a symmetric matrix (m/N): entry {} of row {} is {}, "
                                  "entry {} of row {} is {}",
                                  i + 1, j + 1, R(b, a), j + 1, i + 1, R(a, b)));
        }
      modal.residual_flexibility = R;
    }
  }

  // A rows × cols matrix written as a list of rows of numbers.
  Eigen::MatrixXd matrix(const Table& t, std::string_view key, std::size_t rows, std::size_t cols,
                         std::string_view row_meaning, std::string_view col_meaning) {
    const std::string label = Table::key_label(key);
    const std::string expected =
        fmt::format("{} rows of {} numbers ({}, {})", rows, cols, row_meaning, col_meaning);
    const toml::node& node = t.need(key, expected);
    const toml::array& list = t.to_array(node, label, "rows of numbers");
    if (list.size() != rows)
      t.fail_at(node, label, fmt::format("expected {}, got {} rows", expected, list.size()));
    Eigen::MatrixXd out(static_cast<Eigen::Index>(rows), static_cast<Eigen::Index>(cols));
    for (std::size_t i = 0; i < rows; ++i) {
      const std::string row_label = fmt::format("key '{}', row {}", key, i + 1);
      const auto* row = list[i].as_array();
      if (!row || row->size() != cols)
        t.fail_at(list[i], row_label,
                  fmt::format("expected {} numbers ({}), got {}", cols, col_meaning,
                              row ? fmt::format("{} numbers", row->size()) : shown(list[i])));
      for (std::size_t j = 0; j < cols; ++j)
        out(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) =
            t.to_number((*row)[j], row_label);
    }
    return out;
  }

  void check_modal() {
    try {
      modal_->validate();
    } catch (const std::invalid_argument& e) {
      file_.fail(modal_line_, std::string("[modal]: ") + e.what());
    }
    check_joints(fem::DofMap::from_dofs(modal_->dofs));
    out_.modal = std::move(modal_);
  }

  void read_model_table(const Table& root) {
    const toml::table* m = table(root, "model");
    if (!m) root.fail("missing table [model] (expected [model] with dimension = 2 or 3)");
    Table t(file_, *m, "[model]", {"dimension"});
    const toml::node& n = t.need("dimension", "2 or 3");
    model().dimension = t.to_integer(n, "key 'dimension'");
    if (model().dimension != 2 && model().dimension != 3)
      t.fail_at(n, "key 'dimension'", "expected 2 (planar) or 3 (spatial), got " + shown(n));
  }

  void read_materials(const Table& root) {
    const auto list = tables(root, "materials");
    if (list.empty())
      root.fail("missing [[materials]] (expected at least one, with name, E, rho, nu)");
    for (std::size_t i = 0; i < list.size(); ++i) {
      Table t(file_, *list[i], item_label(*list[i], "materials", i, "name"),
              {"name", "E", "rho", "nu"});
      fem::Material m;
      m.name = t.string("name");
      if (material_index_.count(m.name))
        t.fail("name '" + m.name + "' is used by another material");
      m.E = t.positive("E", "Pa");
      m.rho = t.non_negative(t.need("rho", "a number"), "rho", "kg/m^3");
      if (const auto nu = t.optional_number("nu")) {
        m.nu = *nu;
        if (!(m.nu > -1.0 && m.nu < 0.5))
          t.fail_at(*t.get("nu"), "key 'nu'", fmt::format("expected -1 < nu < 0.5, got {}", m.nu));
      }
      material_index_[m.name] = static_cast<int>(model().materials.size());
      model().materials.push_back(m);
    }
  }

  void read_sections(const Table& root) {
    const auto list = tables(root, "sections");
    if (list.empty()) root.fail("missing [[sections]] (expected at least one, with name, A, Iz)");
    for (std::size_t i = 0; i < list.size(); ++i) {
      Table t(file_, *list[i], item_label(*list[i], "sections", i, "name"),
              {"name", "A", "Iz", "Iy", "J"});
      fem::Section s;
      s.name = t.string("name");
      if (section_index_.count(s.name)) t.fail("name '" + s.name + "' is used by another section");
      s.A = t.positive("A", "m^2");
      s.Iz = t.positive("Iz", "m^4");
      if (t.has("Iy")) s.Iy = t.positive("Iy", "m^4");
      if (t.has("J")) s.J = t.positive("J", "m^4");
      section_index_[s.name] = static_cast<int>(model().sections.size());
      model().sections.push_back(s);
    }
  }

  void read_mesh(const Table& root) {
    const toml::table* m = table(root, "mesh");
    if (!m)
      root.fail("missing table [mesh] (expected nodes = [[id, x, y], ...] and elements = [[id, a, "
                "b], ...])");
    Table t(file_, *m, "[mesh]", {"nodes", "elements", "file"});
    if (const auto* f = t.get("file")) {
      read_gmsh_mesh(t, *f);
      return;
    }
    const bool planar = model().dimension == 2;
    const std::string coords = planar ? "[id, x, y] or [id, x, y, z]" : "[id, x, y, z]";
    const toml::node& nodes_node = t.need("nodes", "an array of " + coords);
    const toml::array& nodes = t.to_array(nodes_node, "key 'nodes'", coords);
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      const std::string label = fmt::format("key 'nodes', entry {}", i + 1);
      const auto* a = nodes[i].as_array();
      if (!a || a->size() < (planar ? 3u : 4u) || a->size() > 4)
        t.fail_at(nodes[i], label,
                  "expected " + coords + ", got " +
                      (a ? fmt::format("{} values", a->size()) : shown(nodes[i])));
      fem::Node node;
      node.id = t.to_integer((*a)[0], label);
      if (node.id <= 0)
        t.fail_at(nodes[i], label,
                  fmt::format("node ids must be > 0 (0 means ground), got {}", node.id));
      if (const auto it = node_lines_.find(node.id); it != node_lines_.end())
        t.fail_at(nodes[i], label,
                  fmt::format("node id {} is already used at line {}", node.id, it->second));
      for (std::size_t c = 1; c < a->size(); ++c)
        node.x(c - 1) = t.to_number((*a)[c], label);
      if (planar && node.x.z() != 0.0)
        t.fail_at(nodes[i], label,
                  fmt::format("node {}: a planar model (dimension = 2) needs z = 0, got {}",
                              node.id, node.x.z()));
      node_lines_[node.id] = line_of(nodes[i]) > 0 ? line_of(nodes[i]) : line_of(nodes_node);
      model().nodes.push_back(node);
    }

    const toml::node& elements_node = t.need("elements", "an array of [id, node a, node b]");
    elements_line_ = line_of(elements_node);
    const toml::array& elements =
        t.to_array(elements_node, "key 'elements'", "[id, node a, node b]");
    for (std::size_t i = 0; i < elements.size(); ++i) {
      const std::string label = fmt::format("key 'elements', entry {}", i + 1);
      const auto* a = elements[i].as_array();
      if (!a || a->size() != 3)
        t.fail_at(elements[i], label,
                  "expected [id, node a, node b], got " +
                      (a ? fmt::format("{} values", a->size()) : shown(elements[i])));
      fem::Element e;
      e.id = t.to_integer((*a)[0], label);
      if (const auto it = element_lines_.find(e.id); it != element_lines_.end())
        t.fail_at(elements[i], label,
                  fmt::format("element id {} is already used at line {}", e.id, it->second));
      e.node_a = node_id(t, (*a)[1], label);
      e.node_b = node_id(t, (*a)[2], label);
      if (e.node_a == e.node_b)
        t.fail_at(elements[i], label,
                  fmt::format("element {} connects node {} to itself", e.id, e.node_a));
      element_lines_[e.id] = line_of(elements[i]) > 0 ? line_of(elements[i]) : elements_line_;
      element_position_[e.id] = static_cast<int>(model().elements.size());
      model().elements.push_back(e);
    }
  }

  // [mesh] file = "frame.msh": nodes and 2-node lines from Gmsh (path relative to this file).
  void read_gmsh_mesh(const Table& t, const toml::node& f) {
    if (t.has("nodes") || t.has("elements"))
      t.fail_at(f, "key 'file'", "give either file = \"x.msh\" or nodes and elements, not both");
    const std::filesystem::path msh = directory_ / t.to_string(f, "key 'file'");
    mesh_ = read_gmsh(msh); // its errors name the .msh file and line
    elements_line_ = line_of(f);
    for (const auto& node : mesh_->nodes) {
      if (node.id <= 0)
        throw Error(fmt::format("{}: node ids must be > 0 (0 means ground), got {}", msh.string(),
                                node.id));
      if (model().dimension == 2 && node.x.z() != 0.0)
        throw Error(fmt::format("{}: node {} has z = {}, but {} declares a planar model "
                                "(dimension = 2)",
                                msh.string(), node.id, node.x.z(), file_.name));
      node_lines_[node.id] = 0;
      model().nodes.push_back(node);
    }
    for (const auto& line : mesh_->lines) {
      fem::Element e;
      e.id = line.id;
      e.node_a = line.node_a;
      e.node_b = line.node_b;
      element_lines_[e.id] = 0;
      element_origin_[e.id] = fmt::format("{}:{}", msh.string(), line.source_line);
      element_position_[e.id] = static_cast<int>(model().elements.size());
      model().elements.push_back(e);
    }
  }

  // Names of the Gmsh physical groups of lines an element belongs to, for messages.
  std::string groups_of(const std::vector<int>& ids) const {
    if (!mesh_) return {};
    std::set<std::string> names;
    for (const auto& line : mesh_->lines)
      if (std::find(ids.begin(), ids.end(), line.id) != ids.end())
        for (int g : line.groups)
          if (const auto it = mesh_->names.find({1, g}); it != mesh_->names.end())
            names.insert("'" + it->second + "'");
    if (names.empty()) return " (in no physical group)";
    return " (physical group " + joined({names.begin(), names.end()}) + ")";
  }

  void read_element_sets(const Table& root) {
    const auto list = tables(root, "element_sets");
    std::vector<int> set_line(model().elements.size(), 0); // line of the set covering each element
    for (std::size_t i = 0; i < list.size(); ++i) {
      Table t(file_, *list[i], fmt::format("[[element_sets]] #{}", i + 1),
              {"elements", "type", "material", "section", "up"});
      const fem::ElementType type = parse_element_type(t);
      const int material = lookup(t, "material", material_index_);
      const int section = lookup(t, "section", section_index_);
      std::optional<Eigen::Vector3d> up; // not given: fem::frame3d_default_up
      if (const auto* n = t.get("up")) {
        if (type != fem::ElementType::frame3d)
          t.fail_at(*n, "key 'up'", "only frame3d elements have an up vector");
        up = t.to_vector3(*n, "key 'up'");
        if (!(up->norm() > 0.0)) t.fail_at(*n, "key 'up'", "expected a non-zero vector");
      }
      // The elements it covers: "all" or a list of ids.
      const toml::node& which = t.need("elements", "\"all\" or a list of element ids");
      std::vector<int> members;
      if (which.is_string() && which.as_string()->get() == "all") {
        for (const auto& e : model().elements)
          members.push_back(e.id);
      } else if (which.is_string()) {
        if (!mesh_)
          t.fail_at(which, "key 'elements'",
                    "expected \"all\" or a list of element ids, got " + shown(which) +
                        " (group names need a Gmsh mesh: [mesh] file = \"x.msh\")");
        try {
          members = mesh_->elements_in(which.as_string()->get());
        } catch (const Error& e) {
          t.fail_at(which, "key 'elements'", e.what());
        }
        if (members.empty())
          t.fail_at(which, "key 'elements'",
                    "the physical group " + shown(which) + " has no lines");
      } else {
        const toml::array& ids = t.to_array(which, "key 'elements'", "element ids (or \"all\")");
        for (const auto& n : ids) {
          const int id = t.to_integer(n, "key 'elements'");
          if (!element_position_.count(id))
            t.fail_at(n, "key 'elements'",
                      fmt::format("element {} does not exist in [mesh] elements", id));
          members.push_back(id);
        }
      }
      std::vector<int> twice;
      std::set<int> other_lines;
      for (int id : members) {
        const int p = element_position_.at(id);
        if (set_line[p] != 0) {
          twice.push_back(id);
          other_lines.insert(set_line[p]);
          continue;
        }
        set_line[p] = t.line();
        fem::Element& e = model().elements[p];
        e.type = type;
        e.material = material;
        e.section = section;
        e.up = up;
      }
      if (!twice.empty()) {
        std::vector<std::string> lines;
        for (int l : other_lines)
          lines.push_back(std::to_string(l));
        t.fail_at(which, "key 'elements'",
                  fmt::format("element{} {} already in the element set at line {} (each element "
                              "belongs to exactly one set)",
                              twice.size() > 1 ? "s" : "",
                              id_list(twice) + (twice.size() > 1 ? " are" : " is"), joined(lines)));
      }
    }
    std::vector<int> uncovered;
    for (std::size_t p = 0; p < model().elements.size(); ++p)
      if (set_line[p] == 0) uncovered.push_back(model().elements[p].id);
    if (!uncovered.empty())
      file_.fail(elements_line_,
                 fmt::format("[mesh]: element{} {}{} in no [[element_sets]] (each element belongs "
                             "to exactly one set, which gives its type, material and section)",
                             uncovered.size() > 1 ? "s" : "", id_list(uncovered),
                             groups_of(uncovered) + (uncovered.size() > 1 ? " are" : " is")));
  }

  int lookup(const Table& t, std::string_view key, const std::map<std::string, int>& index) {
    const toml::node& n = t.need(key, "a name");
    const std::string name = t.to_string(n, Table::key_label(key));
    const auto it = index.find(name);
    if (it == index.end()) {
      std::vector<std::string> names;
      for (const auto& [k, v] : index)
        names.push_back("\"" + k + "\"");
      t.fail_at(n, Table::key_label(key),
                fmt::format("expected one of the [[{}s]] names ({}), got \"{}\"", key,
                            joined(names), name));
    }
    return it->second;
  }

  void read_supports(const Table& root) {
    const auto list = tables(root, "supports");
    for (std::size_t i = 0; i < list.size(); ++i) {
      Table t(file_, *list[i], item_label(*list[i], "supports", i, "node"),
              {"node", "nodes", "fix"});
      // node = id (or a one-node group); nodes = [ids] or a Gmsh group name.
      std::vector<int> nodes;
      const auto* one = t.get("node");
      const auto* many = t.get("nodes");
      if (one && many) t.fail("give either node or nodes, not both");
      if (!one && !many) t.fail("missing key 'node' (a node id) or 'nodes' (ids or a Gmsh group)");
      if (one) nodes.push_back(node_key(t, "node"));
      if (many && many->is_string())
        nodes = group_nodes(t, *many, "key 'nodes'");
      else if (many)
        for (const auto& n : t.to_array(*many, "key 'nodes'", "node ids or a Gmsh group name"))
          nodes.push_back(node_id(t, n, "key 'nodes'"));
      if (nodes.empty()) t.fail("the support holds no nodes");
      const toml::node& fix = t.need("fix", "a list of DOFs such as [\"ux\", \"uy\", \"rz\"]");
      const toml::array& dofs = t.to_array(fix, "key 'fix'", "DOF names (ux, uy, uz, rx, ry, rz)");
      if (dofs.empty()) t.fail_at(fix, "key 'fix'", "expected at least one DOF");
      fem::Support s;
      for (const auto& d : dofs)
        s.fixed.push_back(t.to_dof(d, "key 'fix'"));
      for (int node : nodes) {
        s.node = node;
        model().supports.push_back(s);
      }
    }
  }

  void read_masses(const Table& root) {
    const auto list = tables(root, "masses");
    for (std::size_t i = 0; i < list.size(); ++i) {
      Table t(file_, *list[i], item_label(*list[i], "masses", i, "node"),
              {"node", "mass", "inertia"});
      fem::PointMass m;
      m.node = node_key(t, "node");
      m.mass = t.non_negative(t.need("mass", "a number (kg)"), "mass", "kg");
      if (const auto* n = t.get("inertia")) {
        m.inertia = t.to_vector3(*n, "key 'inertia'");
        if (!(m.inertia.minCoeff() >= 0.0))
          t.fail_at(*n, "key 'inertia'", "expected [Ix, Iy, Iz] >= 0 kg m^2");
      }
      model().masses.push_back(m);
    }
  }

  void read_springs(const Table& root) {
    const auto list = tables(root, "springs");
    for (std::size_t i = 0; i < list.size(); ++i) {
      Table t(file_, *list[i], item_label(*list[i], "springs", i, "node"),
              {"node", "node_b", "dof", "stiffness"});
      fem::Spring s;
      s.node = node_key(t, "node");
      if (const auto* n = t.get("node_b")) s.node_b = node_id(t, *n, "key 'node_b'", true);
      if (s.node_b == s.node)
        t.fail_at(*t.get("node_b"), "key 'node_b'", "a spring cannot connect a node to itself");
      s.dof = t.dof("dof");
      s.stiffness =
          t.non_negative(t.need("stiffness", "a number (N/m or N m/rad)"), "stiffness", "N/m");
      model().springs.push_back(s);
    }
  }

  void read_damping(const Table& root) {
    const toml::table* d = table(root, "damping");
    if (!d) return;
    Table t(file_, *d, "[damping]", {"modal", "rayleigh"});
    const auto* modal = t.get("modal");
    const auto* rayleigh = t.get("rayleigh");
    if (modal && rayleigh)
      t.fail("give either modal = ratio or rayleigh = [alpha, beta], not both");
    if (!modal && !rayleigh) t.fail("expected modal = ratio or rayleigh = [alpha, beta]");
    fem::Damping& damping = model().damping;
    if (modal) {
      damping.kind = fem::Damping::Kind::modal;
      damping.modal_ratio = t.to_number(*modal, "key 'modal'");
      if (!(damping.modal_ratio >= 0.0 && damping.modal_ratio < 1.0))
        t.fail_at(*modal, "key 'modal'",
                  fmt::format("expected a damping ratio in [0, 1), got {}", damping.modal_ratio));
    } else {
      const toml::array& a = t.to_array(*rayleigh, "key 'rayleigh'", "two numbers [alpha, beta]");
      if (a.size() != 2)
        t.fail_at(*rayleigh, "key 'rayleigh'",
                  fmt::format("expected [alpha, beta], got {} values", a.size()));
      damping.kind = fem::Damping::Kind::rayleigh;
      damping.alpha = t.to_number(a[0], "key 'rayleigh'");
      damping.beta = t.to_number(a[1], "key 'rayleigh'");
      if (!(damping.alpha >= 0.0 && damping.beta >= 0.0))
        t.fail_at(*rayleigh, "key 'rayleigh'", "expected alpha >= 0 (1/s) and beta >= 0 (s)");
    }
  }

  void read_options(const Table& root) {
    const toml::table* o = table(root, "options");
    if (!o) return;
    Table t(file_, *o, "[options]", {"lumped_mass"});
    if (const auto lumped = t.optional_boolean("lumped_mass"))
      model().mass_options.lumped = *lumped;
  }

  void read_joints(const Table& root) {
    const auto list = tables(root, "joints");
    std::map<std::string, int> name_lines;
    for (std::size_t i = 0; i < list.size(); ++i) {
      Table t(file_, *list[i], item_label(*list[i], "joints", i, "name"),
              {"name", "node", "node_b", "dof", "terms", "values", "fixed"});
      joints::Joint j;
      j.name = t.string("name");
      if (j.name.empty()) t.fail_at(*t.get("name"), "key 'name'", "expected a non-empty name");
      if (const auto it = name_lines.find(j.name); it != name_lines.end())
        t.fail_at(*t.get("name"), "key 'name'",
                  fmt::format("the name is already used by the joint at line {}", it->second));
      name_lines[j.name] = t.line();
      j.node = node_key(t, "node");
      if (const auto* n = t.get("node_b")) j.node_b = node_id(t, *n, "key 'node_b'", true);
      if (j.node_b == j.node)
        t.fail_at(*t.get("node_b"), "key 'node_b'", "a joint cannot connect a node to itself");
      j.dof = t.dof("dof");

      const toml::node& terms_node =
          t.need("terms", "a list of terms such as [\"k\", \"c\", \"k3\"]");
      const toml::array& terms =
          t.to_array(terms_node, "key 'terms'", "term names (" + joints::term_names() + ")");
      if (terms.empty()) t.fail_at(terms_node, "key 'terms'", "expected at least one term");
      for (const auto& n : terms) {
        const std::string name = t.to_string(n, "key 'terms'");
        try {
          j.terms.push_back(joints::parse_term(name));
        } catch (const std::invalid_argument&) {
          t.fail_at(n, "key 'terms'",
                    "expected one of " + joints::term_names() + ", got " + shown(n));
        }
        if (j.term_index(j.terms.back()) != static_cast<int>(j.terms.size()) - 1)
          t.fail_at(n, "key 'terms'", "term '" + name + "' is listed twice");
      }
      const std::string listed = listed_terms(j);
      j.values.assign(j.terms.size(), 0.0); // a term without a value starts at 0
      j.fixed.assign(j.terms.size(), false);
      std::vector<bool> has_value(j.terms.size(), false);
      if (const auto* n = t.get("values")) {
        const auto* values = n->as_table();
        if (!values)
          t.fail_at(*n, "key 'values'",
                    "expected a table such as { k = 4800.0, c = 20.0 }, got " + shown(*n));
        for (auto&& [key, value] : *values) {
          const std::string label = "key 'values." + std::string(key.str()) + "'";
          const int index = term_position(j, key.str());
          if (index < 0)
            t.fail_at(value, label,
                      "'" + std::string(key.str()) + "' is not among the joint's terms (" + listed +
                          ")");
          j.values[index] = t.to_number(value, label);
          has_value[index] = true;
        }
      }
      if (const auto* n = t.get("fixed")) {
        const toml::array& fixed = t.to_array(*n, "key 'fixed'", "term names");
        for (const auto& f : fixed) {
          const std::string name = t.to_string(f, "key 'fixed'");
          const int index = term_position(j, name);
          if (index < 0)
            t.fail_at(f, "key 'fixed'",
                      "'" + name + "' is not among the joint's terms (" + listed + ")");
          if (!has_value[index])
            t.fail_at(f, "key 'fixed'",
                      "term '" + name + "' is held fixed but has no value in 'values'");
          j.fixed[index] = true;
        }
      }
      j.given = has_value;
      joint_lines_.push_back(t.line());
      out_.joints.push_back(std::move(j));
    }
  }

  static std::string listed_terms(const joints::Joint& j) {
    std::vector<std::string> names;
    for (joints::Term term : j.terms)
      names.emplace_back(joints::term_name(term));
    return joined(names);
  }
  static int term_position(const joints::Joint& j, std::string_view name) {
    for (std::size_t i = 0; i < j.terms.size(); ++i)
      if (joints::term_name(j.terms[i]) == name) return static_cast<int>(i);
    return -1;
  }

  // The library's own checks, reported with the file (and the line where it is known).
  void check() {
    try {
      model().validate();
    } catch (const std::invalid_argument& e) {
      file_.fail(0, e.what());
    }
    const auto index = model().node_positions();
    for (const auto& e : model().elements) {
      try {
        fem::element_matrices(model(), e, model().nodes[index.at(e.node_a)].x,
                              model().nodes[index.at(e.node_b)].x);
      } catch (const std::exception& err) {
        if (const auto it = element_origin_.find(e.id); it != element_origin_.end())
          throw Error(it->second + ": " + err.what());
        file_.fail(element_lines_.at(e.id), err.what());
      }
    }
    fem::DofMap dofs;
    try {
      dofs = fem::DofMap(model());
    } catch (const std::exception& e) {
      file_.fail(0, e.what());
    }
    check_joints(dofs);
  }

  // Joints on free DOFs, each reported at its line; then the checks across joints.
  void check_joints(const fem::DofMap& dofs) {
    for (std::size_t i = 0; i < out_.joints.size(); ++i) {
      try {
        joints::validate_joints({out_.joints[i]}, dofs);
      } catch (const std::invalid_argument& e) {
        file_.fail(joint_lines_[i], e.what());
      }
    }
    try {
      joints::validate_joints(out_.joints, dofs);
    } catch (const std::invalid_argument& e) {
      file_.fail(0, e.what());
    }
  }

  File file_;
  const toml::table& root_;
  ModelFile out_;
  std::filesystem::path directory_;
  std::optional<fem::Assembled> matrices_; // [matrices]
  std::optional<GmshMesh> mesh_;
  std::map<int, int> node_lines_, element_lines_, element_position_;
  std::map<int, std::string> element_origin_; // "mesh.msh:LINE" of elements read from Gmsh
  int elements_line_ = 0;
  std::map<std::string, int> material_index_, section_index_;
  std::vector<int> joint_lines_;
  std::optional<frf::ModalModel> modal_; // [modal], while it is read
  int modal_line_ = 0;
  bool frf_ = false; // [frf], while it is read
};

} // namespace

ModelFile read_model(const std::filesystem::path& path) {
  const std::string text = read_file(path);
  toml::table root;
  try {
    root = toml::parse(std::string_view(text), path.string());
  } catch (const toml::parse_error& e) {
    throw Error(fmt::format("{}:{}:{}: {}", path.string(), e.source().begin.line,
                            e.source().begin.column, e.description()));
  }
  ModelFile out = ModelReader(path, root).read();
  out.path = path;
  return out;
}

fem::DofMap ModelFile::dof_map() const {
  if (modal) return fem::DofMap::from_dofs(modal->dofs);
  if (matrices) return matrices->dofs;
  if (measured) return fem::DofMap::from_dofs(measured->dofs);
  if (!parts.empty()) {
    std::vector<fem::NodeDof> dofs;
    for (std::size_t p = 0; p < parts.size(); ++p) {
      const fem::DofMap map = parts[p].dof_map();
      for (int e = 0; e < map.num_equations(); ++e) {
        fem::NodeDof nd = map.node_dof(e);
        nd.node += node_offsets[p];
        dofs.push_back(nd);
      }
    }
    return fem::DofMap::from_dofs(dofs);
  }
  return fem::DofMap(model);
}

frf::Substructure ModelFile::substructure() const {
  if (!parts.empty()) {
    std::vector<frf::Substructure> subs;
    for (const ModelFile& part : parts)
      subs.push_back(part.substructure());
    return frf::Substructure(std::move(subs), node_offsets);
  }
  if (modal) return frf::Substructure(*modal);
  if (matrices) return frf::Substructure(*matrices, model.damping);
  if (measured) return frf::Substructure(*measured);
  return frf::Substructure(model);
}

fem::NodeDof resolve_node_dof(const ModelFile& file, std::string_view text) {
  const auto colon = text.rfind(':');
  if (colon == std::string_view::npos || colon == 0)
    throw std::invalid_argument("'" + std::string(text) +
                                "' is not NODE:DOF (expected e.g. 7:uy, or a one-node group "
                                "name such as tip:uy)");
  const std::string node(text.substr(0, colon));
  const bool is_id =
      node.find_first_not_of("0123456789", node[0] == '-' ? 1 : 0) == std::string::npos &&
      node != "-";
  if (is_id) return fem::parse_node_dof(text); // negative ids are rejected by the model
  fem::NodeDof nd;
  nd.dof = fem::parse_dof(text.substr(colon + 1));
  if (!file.mesh)
    throw std::invalid_argument("'" + node + "' is not a node id, and " + file.path.string() +
                                " has no Gmsh mesh whose groups could name a node");
  std::vector<int> ids;
  try {
    ids = file.mesh->nodes_in(node);
  } catch (const Error& e) {
    std::vector<std::string> names;
    for (const auto& [key, name] : file.mesh->names)
      if (key.first <= 1) names.push_back("\"" + name + "\""); // groups of points or lines
    throw std::invalid_argument(std::string(e.what()) + " (groups: " + joined(names) + ")");
  }
  if (ids.size() != 1)
    throw std::invalid_argument("the group '" + node + "' of " + file.mesh->path.string() +
                                " holds " + std::to_string(ids.size()) +
                                " nodes; a force or response point needs a group of one node");
  nd.node = ids.front();
  return nd;
}

} // namespace jointid::io

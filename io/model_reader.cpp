// The tables of a model file (Table) and the nodes its sections name (ModelReading).
#include "io/model_reader.hpp"

#include "io/files.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

namespace jointid::io::detail {

int line_of(const toml::node& n) {
  return static_cast<int>(n.source().begin.line);
}

// A value as the user wrote it, for "got ..." in messages.
std::string shown(const toml::node& n) {
  switch (n.type()) {
  case toml::node_type::string:
    return fmt::format("\"{}\"", n.as_string()->get());
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

void File::fail(int line, const std::string& what) const {
  throw Error(line > 0 ? fmt::format("{}:{}: {}", name, line, what)
                       : fmt::format("{}: {}", name, what));
}

Table::Table(const File& file, const toml::table& table, std::string where,
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

void Table::fail(const std::string& what) const {
  file_.fail(where_.empty() ? 0 : line(), prefix() + what);
}

void Table::fail_at(const toml::node& n, const std::string& label, const std::string& what) const {
  file_.fail(line_of(n) > 0 ? line_of(n) : line(), prefix() + label + ": " + what);
}

const toml::node& Table::need(std::string_view key, std::string_view expected) const {
  const toml::node* n = table_.get(key);
  if (!n) fail(fmt::format("missing key '{}' (expected {})", key, expected));
  return *n;
}

// Conversions of any node; `label` says where it is ("key 'E'", "key 'nodes', entry 3").
double Table::to_number(const toml::node& n, const std::string& label) const {
  std::optional<double> v;
  if (const auto* i = n.as_integer()) v = static_cast<double>(i->get());
  if (const auto* f = n.as_floating_point()) v = f->get();
  if (!v) fail_at(n, label, "expected a number, got " + shown(n));
  if (!std::isfinite(*v)) fail_at(n, label, "expected a finite number, got " + shown(n));
  return *v;
}

int Table::to_integer(const toml::node& n, const std::string& label) const {
  const auto* i = n.as_integer();
  if (!i) fail_at(n, label, "expected an integer, got " + shown(n));
  if (i->get() < std::numeric_limits<int>::min() || i->get() > std::numeric_limits<int>::max())
    fail_at(n, label, "expected an integer of at most 9 digits, got " + shown(n));
  return static_cast<int>(i->get());
}

std::string Table::to_string(const toml::node& n, const std::string& label) const {
  const auto* s = n.as_string();
  if (!s) fail_at(n, label, "expected a string, got " + shown(n));
  return s->get();
}

const toml::array& Table::to_array(const toml::node& n, const std::string& label,
                                   std::string_view of) const {
  const auto* a = n.as_array();
  if (!a) fail_at(n, label, fmt::format("expected an array of {}, got {}", of, shown(n)));
  return *a;
}

fem::Dof Table::to_dof(const toml::node& n, const std::string& label) const {
  const std::string text = to_string(n, label);
  try {
    return fem::parse_dof(text);
  } catch (const std::invalid_argument&) {
    fail_at(n, label, "expected one of ux, uy, uz, rx, ry, rz, got " + shown(n));
  }
}

Eigen::Vector3d Table::to_vector3(const toml::node& n, const std::string& label) const {
  const toml::array& a = to_array(n, label, "3 numbers");
  if (a.size() != 3) fail_at(n, label, fmt::format("expected 3 numbers, got {}", a.size()));
  return {to_number(a[0], label), to_number(a[1], label), to_number(a[2], label)};
}

std::string Table::key_label(std::string_view key) {
  return fmt::format("key '{}'", key);
}

// Typed access by key.
double Table::number(std::string_view key) const {
  return to_number(need(key, "a number"), key_label(key));
}

std::optional<double> Table::optional_number(std::string_view key) const {
  if (const auto* n = get(key)) return to_number(*n, key_label(key));
  return std::nullopt;
}

double Table::positive(std::string_view key, std::string_view unit) const {
  const double v = number(key);
  if (!(v > 0.0))
    fail_at(*get(key), key_label(key), fmt::format("expected a value > 0 {}, got {}", unit, v));
  return v;
}

double Table::non_negative(const toml::node& n, std::string_view key, std::string_view unit) const {
  const double v = to_number(n, key_label(key));
  if (!(v >= 0.0))
    fail_at(n, key_label(key), fmt::format("expected a value >= 0 {}, got {}", unit, v));
  return v;
}

int Table::integer(std::string_view key) const {
  return to_integer(need(key, "an integer"), key_label(key));
}

std::string Table::string(std::string_view key) const {
  return to_string(need(key, "a string"), key_label(key));
}

fem::Dof Table::dof(std::string_view key) const {
  return to_dof(need(key, "one of ux, uy, uz, rx, ry, rz"), key_label(key));
}

std::optional<bool> Table::optional_boolean(std::string_view key) const {
  const auto* n = get(key);
  if (!n) return std::nullopt;
  const auto* b = n->as_boolean();
  if (!b) fail_at(*n, key_label(key), "expected true or false, got " + shown(*n));
  return b->get();
}

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

int ModelReading::node_id(const Table& t, const toml::node& n, const std::string& label,
                          bool zero_is_ground) const {
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
  if (!node_lines.count(id))
    t.fail_at(n, label,
              modal         ? fmt::format("node {} is not among the [modal] dofs", id)
              : matrices    ? fmt::format("node {} is not in the [matrices] DOF table", id)
              : reading_frf ? fmt::format("node {} has no measured FRF in [frf]", id)
                            : fmt::format("node {} does not exist in [mesh] nodes", id));
  return id;
}

int ModelReading::node_key(const Table& t, std::string_view key) const {
  return node_id(t, t.need(key, "a node id or a Gmsh group name"), Table::key_label(key));
}

std::vector<int> ModelReading::group_nodes(const Table& t, const toml::node& n,
                                           const std::string& label) const {
  const std::string name = t.to_string(n, label);
  if (modal || matrices || reading_frf)
    t.fail_at(n, label,
              std::string("expected a node id; a substructure given by ") +
                  (modal      ? "its modes ([modal])"
                   : matrices ? "its matrices ([matrices])"
                              : "measured FRFs ([frf])") +
                  " has no groups such as " + shown(n));
  if (!mesh)
    t.fail_at(n, label,
              "expected a node id; group names such as " + shown(n) +
                  " need a Gmsh mesh ([mesh] file = \"x.msh\")");
  try {
    return mesh->nodes_in(name);
  } catch (const Error& e) {
    t.fail_at(n, label, e.what());
  }
}

} // namespace jointid::io::detail

// The finite element model's sections: [model], [[materials]], [[sections]], [mesh] (inline or
// a Gmsh file) and [[element_sets]]; then the library's checks of the model read.
#include "io/model_reader.hpp"

#include "fem/dof_map.hpp"
#include "fem/elements.hpp"
#include "io/files.hpp"
#include "io/gmsh.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <optional>
#include <set>

namespace jointid::io::detail {

namespace {

fem::ElementType parse_element_type(const Table& t) {
  const toml::node& n = t.need("type", "one of beam, frame2d, frame3d");
  const std::string type = t.to_string(n, "key 'type'");
  if (type == "beam") return fem::ElementType::beam;
  if (type == "frame2d") return fem::ElementType::frame2d;
  if (type == "frame3d") return fem::ElementType::frame3d;
  t.fail_at(n, "key 'type'", "expected one of beam, frame2d, frame3d, got " + shown(n));
}

// [mesh] file = "frame.msh": nodes and 2-node lines from Gmsh (path relative to this file).
void read_gmsh_mesh(ModelReading& ctx, const Table& t, const toml::node& f) {
  if (t.has("nodes") || t.has("elements"))
    t.fail_at(f, "key 'file'", "give either file = \"x.msh\" or nodes and elements, not both");
  const std::filesystem::path msh = ctx.directory / t.to_string(f, "key 'file'");
  ctx.mesh = read_gmsh(msh); // its errors name the .msh file and line
  ctx.elements_line = line_of(f);
  for (const auto& node : ctx.mesh->nodes) {
    if (node.id <= 0)
      throw Error(
          fmt::format("{}: node ids must be > 0 (0 means ground), got {}", msh.string(), node.id));
    if (ctx.model().dimension == 2 && node.x.z() != 0.0)
      throw Error(fmt::format("{}: node {} has z = {}, but {} declares a planar model "
                              "(dimension = 2)",
                              msh.string(), node.id, node.x.z(), ctx.file.name));
    ctx.node_lines[node.id] = 0;
    ctx.model().nodes.push_back(node);
  }
  for (const auto& line : ctx.mesh->lines) {
    fem::Element e;
    e.id = line.id;
    e.node_a = line.node_a;
    e.node_b = line.node_b;
    ctx.element_lines[e.id] = 0;
    ctx.element_origin[e.id] = fmt::format("{}:{}", msh.string(), line.source_line);
    ctx.element_position[e.id] = static_cast<int>(ctx.model().elements.size());
    ctx.model().elements.push_back(e);
  }
}

// Names of the Gmsh physical groups of lines an element belongs to, for messages.
std::string groups_of(const ModelReading& ctx, const std::vector<int>& ids) {
  if (!ctx.mesh) return {};
  std::set<std::string> names;
  for (const auto& line : ctx.mesh->lines)
    if (std::find(ids.begin(), ids.end(), line.id) != ids.end())
      for (int g : line.groups)
        if (const auto it = ctx.mesh->names.find({1, g}); it != ctx.mesh->names.end())
          names.insert("'" + it->second + "'");
  if (names.empty()) return " (in no physical group)";
  return " (physical group " + joined({names.begin(), names.end()}) + ")";
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
              fmt::format("expected one of the [[{}s]] names ({}), got \"{}\"", key, joined(names),
                          name));
  }
  return it->second;
}

} // namespace

void read_model_table(ModelReading& ctx, const Table& root) {
  const toml::table* m = table(root, "model");
  if (!m) root.fail("missing table [model] (expected [model] with dimension = 2 or 3)");
  Table t(ctx.file, *m, "[model]", {"dimension"});
  const toml::node& n = t.need("dimension", "2 or 3");
  ctx.model().dimension = t.to_integer(n, "key 'dimension'");
  if (ctx.model().dimension != 2 && ctx.model().dimension != 3)
    t.fail_at(n, "key 'dimension'", "expected 2 (planar) or 3 (spatial), got " + shown(n));
}

void read_materials(ModelReading& ctx, const Table& root) {
  const auto list = tables(root, "materials");
  if (list.empty())
    root.fail("missing [[materials]] (expected at least one, with name, E, rho, nu)");
  for (std::size_t i = 0; i < list.size(); ++i) {
    Table t(ctx.file, *list[i], item_label(*list[i], "materials", i, "name"),
            {"name", "E", "rho", "nu"});
    fem::Material m;
    m.name = t.string("name");
    if (ctx.material_index.count(m.name))
      t.fail("name '" + m.name + "' is used by another material");
    m.E = t.positive("E", "Pa");
    m.rho = t.non_negative(t.need("rho", "a number"), "rho", "kg/m^3");
    if (const auto nu = t.optional_number("nu")) {
      m.nu = *nu;
      if (!(m.nu > -1.0 && m.nu < 0.5))
        t.fail_at(*t.get("nu"), "key 'nu'", fmt::format("expected -1 < nu < 0.5, got {}", m.nu));
    }
    ctx.material_index[m.name] = static_cast<int>(ctx.model().materials.size());
    ctx.model().materials.push_back(m);
  }
}

void read_sections(ModelReading& ctx, const Table& root) {
  const auto list = tables(root, "sections");
  if (list.empty()) root.fail("missing [[sections]] (expected at least one, with name, A, Iz)");
  for (std::size_t i = 0; i < list.size(); ++i) {
    Table t(ctx.file, *list[i], item_label(*list[i], "sections", i, "name"),
            {"name", "A", "Iz", "Iy", "J"});
    fem::Section s;
    s.name = t.string("name");
    if (ctx.section_index.count(s.name)) t.fail("name '" + s.name + "' is used by another section");
    s.A = t.positive("A", "m^2");
    s.Iz = t.positive("Iz", "m^4");
    if (t.has("Iy")) s.Iy = t.positive("Iy", "m^4");
    if (t.has("J")) s.J = t.positive("J", "m^4");
    ctx.section_index[s.name] = static_cast<int>(ctx.model().sections.size());
    ctx.model().sections.push_back(s);
  }
}

void read_mesh(ModelReading& ctx, const Table& root) {
  const toml::table* m = table(root, "mesh");
  if (!m)
    root.fail("missing table [mesh] (expected nodes = [[id, x, y], ...] and elements = [[id, a, "
              "b], ...])");
  Table t(ctx.file, *m, "[mesh]", {"nodes", "elements", "file"});
  if (const auto* f = t.get("file")) {
    read_gmsh_mesh(ctx, t, *f);
    return;
  }
  const bool planar = ctx.model().dimension == 2;
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
    if (const auto it = ctx.node_lines.find(node.id); it != ctx.node_lines.end())
      t.fail_at(nodes[i], label,
                fmt::format("node id {} is already used at line {}", node.id, it->second));
    for (std::size_t c = 1; c < a->size(); ++c)
      node.x(c - 1) = t.to_number((*a)[c], label);
    if (planar && node.x.z() != 0.0)
      t.fail_at(nodes[i], label,
                fmt::format("node {}: a planar model (dimension = 2) needs z = 0, got {}", node.id,
                            node.x.z()));
    ctx.node_lines[node.id] = line_of(nodes[i]) > 0 ? line_of(nodes[i]) : line_of(nodes_node);
    ctx.model().nodes.push_back(node);
  }

  const toml::node& elements_node = t.need("elements", "an array of [id, node a, node b]");
  ctx.elements_line = line_of(elements_node);
  const toml::array& elements = t.to_array(elements_node, "key 'elements'", "[id, node a, node b]");
  for (std::size_t i = 0; i < elements.size(); ++i) {
    const std::string label = fmt::format("key 'elements', entry {}", i + 1);
    const auto* a = elements[i].as_array();
    if (!a || a->size() != 3)
      t.fail_at(elements[i], label,
                "expected [id, node a, node b], got " +
                    (a ? fmt::format("{} values", a->size()) : shown(elements[i])));
    fem::Element e;
    e.id = t.to_integer((*a)[0], label);
    if (const auto it = ctx.element_lines.find(e.id); it != ctx.element_lines.end())
      t.fail_at(elements[i], label,
                fmt::format("element id {} is already used at line {}", e.id, it->second));
    e.node_a = ctx.node_id(t, (*a)[1], label);
    e.node_b = ctx.node_id(t, (*a)[2], label);
    if (e.node_a == e.node_b)
      t.fail_at(elements[i], label,
                fmt::format("element {} connects node {} to itself", e.id, e.node_a));
    ctx.element_lines[e.id] = line_of(elements[i]) > 0 ? line_of(elements[i]) : ctx.elements_line;
    ctx.element_position[e.id] = static_cast<int>(ctx.model().elements.size());
    ctx.model().elements.push_back(e);
  }
}

void read_element_sets(ModelReading& ctx, const Table& root) {
  const auto list = tables(root, "element_sets");
  // The set covering each element (-1: none yet), and each set's line for messages (0 in a
  // document built in memory, io/model_toml.hpp).
  std::vector<int> set_of(ctx.model().elements.size(), -1);
  std::vector<int> set_line;
  for (std::size_t i = 0; i < list.size(); ++i) {
    Table t(ctx.file, *list[i], fmt::format("[[element_sets]] #{}", i + 1),
            {"elements", "type", "material", "section", "up"});
    set_line.push_back(t.line());
    const fem::ElementType type = parse_element_type(t);
    const int material = lookup(t, "material", ctx.material_index);
    const int section = lookup(t, "section", ctx.section_index);
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
      for (const auto& e : ctx.model().elements)
        members.push_back(e.id);
    } else if (which.is_string()) {
      if (!ctx.mesh)
        t.fail_at(which, "key 'elements'",
                  "expected \"all\" or a list of element ids, got " + shown(which) +
                      " (group names need a Gmsh mesh: [mesh] file = \"x.msh\")");
      try {
        members = ctx.mesh->elements_in(which.as_string()->get());
      } catch (const Error& e) {
        t.fail_at(which, "key 'elements'", e.what());
      }
      if (members.empty())
        t.fail_at(which, "key 'elements'", "the physical group " + shown(which) + " has no lines");
    } else {
      const toml::array& ids = t.to_array(which, "key 'elements'", "element ids (or \"all\")");
      for (const auto& n : ids) {
        const int id = t.to_integer(n, "key 'elements'");
        if (!ctx.element_position.count(id))
          t.fail_at(n, "key 'elements'",
                    fmt::format("element {} does not exist in [mesh] elements", id));
        members.push_back(id);
      }
    }
    std::vector<int> twice;
    std::set<int> other_sets;
    for (int id : members) {
      const int p = ctx.element_position.at(id);
      if (set_of[p] >= 0) {
        twice.push_back(id);
        other_sets.insert(set_of[p]);
        continue;
      }
      set_of[p] = static_cast<int>(i);
      fem::Element& e = ctx.model().elements[p];
      e.type = type;
      e.material = material;
      e.section = section;
      e.up = up;
    }
    if (!twice.empty()) {
      std::vector<std::string> lines, numbers;
      for (int o : other_sets) {
        lines.push_back(std::to_string(set_line[o]));
        numbers.push_back(fmt::format("#{}", o + 1));
      }
      const bool by_line = set_line[*other_sets.begin()] > 0;
      t.fail_at(which, "key 'elements'",
                fmt::format("element{} {} already in the element set {} (each element "
                            "belongs to exactly one set)",
                            twice.size() > 1 ? "s" : "",
                            id_list(twice) + (twice.size() > 1 ? " are" : " is"),
                            by_line ? "at line " + joined(lines) : joined(numbers)));
    }
  }
  std::vector<int> uncovered;
  for (std::size_t p = 0; p < ctx.model().elements.size(); ++p)
    if (set_of[p] < 0) uncovered.push_back(ctx.model().elements[p].id);
  if (!uncovered.empty())
    ctx.file.fail(ctx.elements_line,
                  fmt::format("[mesh]: element{} {}{} in no [[element_sets]] (each element belongs "
                              "to exactly one set, which gives its type, material and section)",
                              uncovered.size() > 1 ? "s" : "", id_list(uncovered),
                              groups_of(ctx, uncovered) + (uncovered.size() > 1 ? " are" : " is")));
}

// The library's own checks, reported with the file (and the line where it is known).
void check_finite_elements(ModelReading& ctx) {
  try {
    ctx.model().validate();
  } catch (const std::invalid_argument& e) {
    ctx.file.fail(0, e.what());
  }
  const auto index = ctx.model().node_positions();
  for (const auto& e : ctx.model().elements) {
    try {
      fem::element_matrices(ctx.model(), e, ctx.model().nodes[index.at(e.node_a)].x,
                            ctx.model().nodes[index.at(e.node_b)].x);
    } catch (const std::exception& err) {
      if (const auto it = ctx.element_origin.find(e.id); it != ctx.element_origin.end())
        throw Error(it->second + ": " + err.what());
      ctx.file.fail(ctx.element_lines.at(e.id), err.what());
    }
  }
  fem::DofMap dofs;
  try {
    dofs = fem::DofMap(ctx.model());
  } catch (const std::exception& e) {
    ctx.file.fail(0, e.what());
  }
  check_joints(ctx, dofs);
}

} // namespace jointid::io::detail

// [[joints]]: name, nodes, DOF, terms and their values; then each joint checked on the DOFs.
#include "io/model_reader.hpp"

#include <fmt/format.h>

namespace jointid::io::detail {

namespace {

std::string listed_terms(const joints::Joint& j) {
  std::vector<std::string> names;
  for (joints::Term term : j.terms)
    names.emplace_back(joints::term_name(term));
  return joined(names);
}
int term_position(const joints::Joint& j, std::string_view name) {
  for (std::size_t i = 0; i < j.terms.size(); ++i)
    if (joints::term_name(j.terms[i]) == name) return static_cast<int>(i);
  return -1;
}

} // namespace

void read_joints(ModelReading& ctx, const Table& root) {
  const auto list = tables(root, "joints");
  std::map<std::string, int> name_lines;
  for (std::size_t i = 0; i < list.size(); ++i) {
    Table t(ctx.file, *list[i], item_label(*list[i], "joints", i, "name"),
            {"name", "node", "node_b", "dof", "terms", "values", "fixed"});
    joints::Joint j;
    j.name = t.string("name");
    if (j.name.empty()) t.fail_at(*t.get("name"), "key 'name'", "expected a non-empty name");
    if (const auto it = name_lines.find(j.name); it != name_lines.end())
      t.fail_at(*t.get("name"), "key 'name'",
                fmt::format("the name is already used by the joint at line {}", it->second));
    name_lines[j.name] = t.line();
    j.node = ctx.node_key(t, "node");
    if (const auto* n = t.get("node_b")) j.node_b = ctx.node_id(t, *n, "key 'node_b'", true);
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
    ctx.joint_lines.push_back(t.line());
    ctx.out.joints.push_back(std::move(j));
  }
}

// Joints on free DOFs, each reported at its line; then the checks across joints.
void check_joints(const ModelReading& ctx, const fem::DofMap& dofs) {
  for (std::size_t i = 0; i < ctx.out.joints.size(); ++i) {
    try {
      joints::validate_joints({ctx.out.joints[i]}, dofs);
    } catch (const std::invalid_argument& e) {
      ctx.file.fail(ctx.joint_lines[i], e.what());
    }
  }
  try {
    joints::validate_joints(ctx.out.joints, dofs);
  } catch (const std::invalid_argument& e) {
    ctx.file.fail(0, e.what());
  }
}

} // namespace jointid::io::detail

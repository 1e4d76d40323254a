// [[joints]]: name, nodes, DOF, terms and their values; then each joint checked on the DOFs.
#include "io/model_reader.hpp"

#include <fmt/format.h>

#include <algorithm>

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
    j.iwan_sliders = ctx.iwan_sliders;
    std::vector<bool> has_value(j.terms.size(), false);
    // A parametric term (jenkins, iwan, gap) holds its force whole (coefficient 1) and has its
    // named parameters, "<term>.<parameter>" in values.
    bool parametric = false;
    for (std::size_t k = 0; k < j.terms.size(); ++k)
      if (joints::has_parameters(j.terms[k])) {
        parametric = true;
        j.values[k] = 1.0;
      }
    if (parametric) {
      j.parameters.resize(j.terms.size());
      for (std::size_t k = 0; k < j.terms.size(); ++k)
        j.parameters[k].resize(joints::term_info(j.terms[k]).parameters.size());
    }
    // "<term>.<parameter>" (a quoted key, or the dotted key's table): its index pair or fails.
    auto parameter_at = [&](const toml::node& at, const std::string& label, std::string_view term,
                            std::string_view name) {
      const int index = term_position(j, term);
      if (index < 0)
        t.fail_at(at, label,
                  "'" + std::string(term) + "' is not among the joint's terms (" + listed + ")");
      const joints::Term tt = j.terms[static_cast<std::size_t>(index)];
      const int p = joints::parameter_index(tt, name);
      if (!joints::has_parameters(tt))
        t.fail_at(at, label,
                  "term '" + std::string(term) +
                      "' has no named parameters (its value is written " + std::string(term) +
                      " = ...)");
      if (p < 0)
        t.fail_at(at, label,
                  "'" + std::string(name) + "' is not a parameter of '" + std::string(term) +
                      "': expected one of " + joints::parameter_names(tt));
      return std::pair<std::size_t, std::size_t>(index, p);
    };
    auto read_parameter = [&](const toml::node& value, const std::string& label,
                              std::string_view term, std::string_view name) {
      const auto [k, p] = parameter_at(value, label, term, name);
      const joints::ParameterInfo& info = joints::term_info(j.terms[k]).parameters[p];
      const double v = t.to_number(value, label);
      if (!joints::in_range(info, v))
        t.fail_at(value, label,
                  "expected " + joints::range_text(info) + " (" + std::string(info.meaning) + ", " +
                      std::string(info.unit) + "), got " + shown(value));
      j.parameters[k][p].value = v;
      j.parameters[k][p].given = true;
    };
    if (const auto* n = t.get("values")) {
      const auto* values = n->as_table();
      if (!values)
        t.fail_at(*n, "key 'values'",
                  "expected a table such as { k = 4800.0, c = 20.0 }, got " + shown(*n));
      for (auto&& [key, value] : *values) {
        const std::string name(key.str());
        const std::string label = "key 'values." + name + "'";
        if (const auto dot = name.find('.'); dot != std::string::npos) {
          read_parameter(value, label, std::string_view(name).substr(0, dot),
                         std::string_view(name).substr(dot + 1));
          continue;
        }
        const int index = term_position(j, name);
        if (index < 0)
          t.fail_at(value, label, "'" + name + "' is not among the joint's terms (" + listed + ")");
        const joints::Term term = j.terms[static_cast<std::size_t>(index)];
        if (joints::has_parameters(term)) {
          // values = { iwan.fs = 3.0 } (a dotted key) is the table iwan = { fs = 3.0 }
          const auto* sub = value.as_table();
          if (!sub)
            t.fail_at(value, label,
                      "term '" + name + "' has named parameters: write \"" + name + "." +
                          std::string(joints::term_info(term).parameters[0].name) +
                          "\" = ... for each of " + joints::parameter_names(term));
          for (auto&& [inner, v] : *sub)
            read_parameter(v, "key 'values." + name + "." + std::string(inner.str()) + "'", name,
                           inner.str());
          continue;
        }
        j.values[static_cast<std::size_t>(index)] = t.to_number(value, label);
        has_value[static_cast<std::size_t>(index)] = true;
      }
    }
    for (std::size_t k = 0; k < j.terms.size(); ++k)
      if (joints::has_parameters(j.terms[k]))
        has_value[k] = std::all_of(j.parameters[k].begin(), j.parameters[k].end(),
                                   [](const joints::Parameter& p) { return p.given; });
    if (const auto* n = t.get("fixed")) {
      const toml::array& fixed = t.to_array(*n, "key 'fixed'", "term names");
      for (const auto& f : fixed) {
        const std::string name = t.to_string(f, "key 'fixed'");
        if (const auto dot = name.find('.'); dot != std::string::npos) {
          const auto [k, p] = parameter_at(f, "key 'fixed'", std::string_view(name).substr(0, dot),
                                           std::string_view(name).substr(dot + 1));
          if (!j.parameters[k][p].given)
            t.fail_at(f, "key 'fixed'",
                      "'" + name + "' is held fixed but has no value in 'values'");
          j.parameters[k][p].fixed = true;
          continue;
        }
        const int index = term_position(j, name);
        if (index < 0)
          t.fail_at(f, "key 'fixed'",
                    "'" + name + "' is not among the joint's terms (" + listed + ")");
        if (!has_value[index])
          t.fail_at(f, "key 'fixed'",
                    joints::has_parameters(j.terms[static_cast<std::size_t>(index)])
                        ? "term '" + name + "' is held fixed but not all of its parameters (" +
                              joints::parameter_names(j.terms[static_cast<std::size_t>(index)]) +
                              ") have a value in 'values'"
                        : "term '" + name + "' is held fixed but has no value in 'values'");
        j.fixed[index] = true;
        if (joints::has_parameters(j.terms[static_cast<std::size_t>(index)]))
          for (joints::Parameter& p : j.parameters[static_cast<std::size_t>(index)])
            p.fixed = true;
      }
    }
    for (std::size_t k = 0; k < j.terms.size(); ++k)
      if (joints::has_parameters(j.terms[k]))
        j.fixed[k] = std::all_of(j.parameters[k].begin(), j.parameters[k].end(),
                                 [](const joints::Parameter& p) { return p.fixed; });
    j.given = has_value;
    ctx.joint_lines.push_back(t.line());
    ctx.out.joint_lines.push_back(t.line());
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

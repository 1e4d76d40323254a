// A model file written from another with new joint values (io/model_write.hpp).
#include "io/model_write.hpp"
#include "io/files.hpp"
#include "io/model_file.hpp"
#include "io/model_toml.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <sstream>

namespace jointid::io {

namespace {

namespace fs = std::filesystem;

// `path` as written in `from`'s directory, rewritten to start from `to` (absolute when no
// relative path joins them, e.g. another drive).
std::string moved_path(const std::string& path, const fs::path& from, const fs::path& to) {
  const fs::path p(path);
  if (p.is_absolute()) return path;
  const fs::path target = fs::weakly_canonical(fs::absolute(from / p));
  const fs::path relative = target.lexically_relative(fs::weakly_canonical(fs::absolute(to)));
  return relative.empty() ? target.generic_string() : relative.generic_string();
}

void move_string(toml::node* n, const fs::path& from, const fs::path& to) {
  if (n == nullptr) return;
  if (auto* s = n->as_string()) {
    *s = moved_path(s->get(), from, to);
  } else if (auto* a = n->as_array()) {
    for (auto& item : *a)
      if (auto* si = item.as_string()) *si = moved_path(si->get(), from, to);
  }
}

// Every relative path of the model file's contract: [mesh] file, [matrices] K, M and dofs (a
// file, or a list of DOFs), [frf] files, [[substructures]] file.
void move_paths(toml::table& root, const fs::path& from, const fs::path& to) {
  if (auto* mesh = root["mesh"].as_table()) move_string(mesh->get("file"), from, to);
  if (auto* m = root["matrices"].as_table()) {
    move_string(m->get("K"), from, to);
    move_string(m->get("M"), from, to);
    if (auto* d = m->get("dofs"); d != nullptr && d->is_string()) move_string(d, from, to);
  }
  if (auto* f = root["frf"].as_table()) move_string(f->get("files"), from, to);
  if (auto* parts = root["substructures"].as_array())
    for (auto& part : *parts)
      if (auto* t = part.as_table()) move_string(t->get("file"), from, to);
}

// Multiplies a number or every number of an array by `factor` (an integer becomes a float).
void scale(toml::table& t, std::string_view key, double factor) {
  toml::node* n = t.get(key);
  auto times = [&](const toml::node& v) -> double {
    if (const auto* d = v.as_floating_point()) return d->get() * factor;
    return static_cast<double>(v.as_integer()->get()) * factor;
  };
  if (n->is_number()) {
    t.insert_or_assign(key, times(*n));
  } else if (auto* a = n->as_array()) {
    toml::array out;
    for (const auto& v : *a)
      out.push_back(times(v));
    t.insert_or_assign(key, std::move(out));
  }
}

void scale_damping(toml::table& root, double factor, const fs::path& start) {
  if (std::abs(factor - 1.0) <= 1e-12) return;
  if (auto* modal = root["modal"].as_table(); modal && modal->contains("damping")) {
    scale(*modal, "damping", factor);
  } else if (auto* d = root["damping"].as_table()) {
    for (const char* key : {"modal", "rayleigh"})
      if (d->contains(key)) scale(*d, key, factor);
  } else if (root.contains("substructures") || root.contains("frf")) {
    throw Error(fmt::format(
        "{}: the substructure's damping scaled by {:.6g} cannot be written into a model of {}: "
        "scale the damping in its own files",
        start.string(), factor,
        root.contains("frf") ? "measured FRFs ([frf])" : "several parts ([[substructures]])"));
  } // no damping at all: there is nothing to scale
}

// values = { k = 1.0, "jenkins.kt" = 4e4, ... } (every value: all are known once discovered) and
// fixed = [...] of a joint.
void write_terms(toml::table& t, const joints::Joint& j) {
  toml::array terms, fixed;
  toml::table values;
  for (std::size_t k = 0; k < j.terms.size(); ++k) {
    const std::string name(joints::term_name(j.terms[k]));
    terms.push_back(name);
    if (!joints::has_parameters(j.terms[k])) {
      values.insert_or_assign(name, j.values[k]);
      if (k < j.fixed.size() && j.fixed[k]) fixed.push_back(name);
      continue;
    }
    const auto& info = joints::term_info(j.terms[k]).parameters;
    const auto params = j.parameters_of(k);
    const bool all_fixed = std::all_of(params.begin(), params.end(),
                                       [](const joints::Parameter& p) { return p.fixed; });
    if (all_fixed) fixed.push_back(name);
    for (std::size_t p = 0; p < params.size(); ++p) {
      const std::string key = name + "." + std::string(info[p].name);
      values.insert_or_assign(key, params[p].value);
      if (!all_fixed && params[p].fixed) fixed.push_back(key);
    }
  }
  values.is_inline(true);
  t.insert_or_assign("terms", std::move(terms));
  t.insert_or_assign("values", std::move(values));
  if (fixed.empty())
    t.erase("fixed");
  else
    t.insert_or_assign("fixed", std::move(fixed));
}

bool same_terms(const joints::Joint& a, const joints::Joint& b) {
  if (a.terms != b.terms) return false;
  for (std::size_t k = 0; k < a.terms.size(); ++k) {
    if (!joints::has_parameters(a.terms[k])) {
      if (a.values[k] != b.values[k]) return false;
      continue;
    }
    const auto pa = a.parameters_of(k), pb = b.parameters_of(k);
    if (pa.size() != pb.size()) return false;
    for (std::size_t p = 0; p < pa.size(); ++p)
      if (pa[p].value != pb[p].value) return false;
  }
  return true;
}

} // namespace

std::string model_with_joints(const fs::path& start, const std::vector<joints::Joint>& joints,
                              double damping_scale, const fs::path& target,
                              std::string_view header) {
  if (!fs::is_directory(target.parent_path().empty() ? fs::path(".") : target.parent_path()))
    throw Error(fmt::format("{}: its directory does not exist (the model's paths are checked "
                            "from it)",
                            target.string()));
  const ModelFile original = read_model(start);
  toml::table root;
  try {
    const std::string text = read_file(start);
    root = toml::parse(std::string_view(text), start.string());
  } catch (const toml::parse_error& e) {
    throw Error(fmt::format("{}: {}", start.string(), e.description()));
  }
  auto find = [&](const std::vector<joints::Joint>& list, const std::string& name) {
    const auto it = std::find_if(list.begin(), list.end(),
                                 [&](const joints::Joint& j) { return j.name == name; });
    return it == list.end() ? nullptr : &*it;
  };

  // The file's own joints take the new terms; a part's joint must be unchanged.
  std::vector<std::string> own;
  if (auto* list = root["joints"].as_array()) {
    for (auto& item : *list) {
      auto* t = item.as_table();
      const std::string name = t->get_as<std::string>("name")->get();
      const joints::Joint* j = find(joints, name);
      if (j == nullptr)
        throw Error(fmt::format("{}: joint '{}' of the starting model is not among the joints "
                                "to write",
                                start.string(), name));
      write_terms(*t, *j);
      own.push_back(name);
    }
  }
  for (const joints::Joint& j : joints) {
    if (std::find(own.begin(), own.end(), j.name) != own.end()) continue;
    const joints::Joint* before = find(original.joints, j.name);
    if (before == nullptr)
      throw Error(
          fmt::format("{}: joint '{}' is not a joint of this model", start.string(), j.name));
    if (!same_terms(*before, j))
      throw Error(fmt::format("{}: joint '{}' is given by one of the model's parts "
                              "([[substructures]]), whose file would have to be rewritten: "
                              "give the joint in the model file itself to have it written",
                              start.string(), j.name));
  }
  scale_damping(root, damping_scale, start);
  move_paths(root, start.parent_path(), target.parent_path());

  std::ostringstream text;
  for (std::string_view rest = header; !rest.empty();) {
    const auto end = rest.find('\n');
    text << "# " << rest.substr(0, end) << '\n';
    rest = end == std::string_view::npos ? std::string_view() : rest.substr(end + 1);
  }
  text << toml::toml_formatter(root, toml::toml_formatter::default_flags &
                                         ~toml::format_flags::allow_literal_strings)
       << '\n';

  // Read back as it will be read at `target`: the same checks, and the joints as given.
  toml::table written;
  try {
    written = toml::parse(text.str(), target.string());
  } catch (const toml::parse_error& e) {
    throw Error(
        fmt::format("{}: the model written does not parse: {}", target.string(), e.description()));
  }
  const ModelFile back = read_model(written, target);
  for (const joints::Joint& j : joints) {
    const joints::Joint* b = find(back.joints, j.name);
    if (b == nullptr || !same_terms(*b, j) || b->node != j.node || b->node_b != j.node_b ||
        b->dof != j.dof)
      throw Error(
          fmt::format("{}: joint '{}' does not read back as written", target.string(), j.name));
  }
  return text.str();
}

} // namespace jointid::io

#include "io/model_file.hpp"

#include "fem/dof_map.hpp"
#include "io/files.hpp"
#include "io/model_reader.hpp"
#include "io/model_toml.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <string>
#include <vector>

namespace jointid::io {

using namespace detail;

namespace {

// [modal], [matrices], [frf] and [[substructures]] each give the whole substructure: at most
// one of them.
void check_one_kind(const Table& root) {
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

// The file's tables, read by the readers of its sections.
ModelFile read_tables(ModelReading& ctx, const toml::table& document) {
  Table root(ctx.file, document, "",
             {"model", "materials", "sections", "mesh", "element_sets", "supports", "masses",
              "springs", "damping", "options", "joints", "modal", "matrices", "frf",
              "substructures"});
  check_one_kind(root);
  if (root.has("modal")) return read_modal_file(ctx, root);
  if (root.has("matrices")) return read_matrices_file(ctx, root);
  if (root.has("frf")) return read_frf_file(ctx, root);
  if (root.has("substructures")) return read_composite_file(ctx, root);
  read_model_table(ctx, root);
  read_materials(ctx, root);
  read_sections(ctx, root);
  read_mesh(ctx, root);
  read_element_sets(ctx, root);
  read_supports(ctx, root);
  read_masses(ctx, root);
  read_springs(ctx, root);
  read_damping(ctx, root);
  read_options(ctx, root);
  read_joints(ctx, root);
  check_finite_elements(ctx);
  ctx.out.mesh = std::move(ctx.mesh);
  return std::move(ctx.out);
}

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
  return read_model(root, path);
}

ModelFile read_model(const toml::table& document, const std::filesystem::path& path) {
  ModelReading reading(path);
  ModelFile out = read_tables(reading, document);
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

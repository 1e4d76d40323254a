// Substructures given otherwise than by a mesh or modes: [matrices] (K and M from MatrixMarket
// files), [frf] (measured FRFs) and [[substructures]] (other model files side by side).
#include "io/model_reader.hpp"

#include "fem/dof_map.hpp"
#include "io/files.hpp"
#include "io/matrix_market.hpp"
#include "io/measured_frf_file.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <limits>
#include <map>
#include <optional>
#include <utility>

namespace jointid::io::detail {

void reject_finite_element_keys(const Table& root, bool damping_allowed, std::string_view why) {
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
  if (first) root.fail_at(*first, Table::key_label(first_key), "not used with " + std::string(why));
}

// A substructure given by its stiffness and mass matrices (MatrixMarket files exported by
// another program) and a DOF table naming their rows: [matrices], an optional [model] and
// [damping], and the joints; the other finite element tables are errors.
ModelFile read_matrices_file(ModelReading& ctx, const Table& root) {
  reject_finite_element_keys(root, true,
                             "[matrices]: the substructure is given by its K and M matrices");
  if (root.has("model")) read_model_table(ctx, root);
  Table t(ctx.file, *table(root, "matrices"), "[matrices]", {"K", "M", "dofs"});
  const int line = t.line();
  auto file_key = [&](std::string_view key, std::string_view what) {
    const toml::node& n = t.need(key, what);
    return ctx.directory / t.to_string(n, Table::key_label(key));
  };
  const auto K_path = file_key("K", "the stiffness matrix, a MatrixMarket file (\"k.mtx\")");
  const auto M_path = file_key("M", "the mass matrix, a MatrixMarket file (\"m.mtx\")");
  const toml::node& d = t.need("dofs", "the DOF table: a file with one NODE:DOF per line, or a "
                                       "list such as [\"1:uy\", \"1:rz\"]");
  std::vector<fem::NodeDof> dofs;
  if (d.is_string()) {
    dofs = read_dof_table(ctx.directory / t.to_string(d, "key 'dofs'"));
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
  if (root.has("model") && ctx.model().dimension == 2)
    for (const fem::NodeDof& nd : dofs)
      if (nd.dof != fem::Dof::ux && nd.dof != fem::Dof::uy && nd.dof != fem::Dof::rz)
        ctx.file.fail(line, "[matrices]: a planar model (dimension = 2) has only ux, uy and rz, "
                            "the DOF table has " +
                                fem::to_string(nd));
  fem::Assembled& system = ctx.matrices.emplace();
  system.dofs = fem::DofMap::from_dofs(dofs);
  system.K = read_matrix_market(K_path); // their errors name the .mtx file and line
  system.M = read_matrix_market(M_path);
  for (const fem::NodeDof& nd : dofs)
    ctx.node_lines.emplace(nd.node, line);
  read_damping(ctx, root);
  try {
    (void)frf::Substructure(system, ctx.model().damping); // sizes, symmetry, masses
  } catch (const std::invalid_argument& e) {
    ctx.file.fail(line, fmt::format("[matrices] ({}, {}, {} DOFs): {}", K_path.filename().string(),
                                    M_path.filename().string(), dofs.size(), e.what()));
  }
  read_joints(ctx, root);
  check_joints(ctx, system.dofs);
  ctx.out.matrices = std::move(ctx.matrices);
  return std::move(ctx.out);
}

// A substructure given by measured FRFs: [frf] files = [...] (universal files or CSV tables,
// relative to the model file), an optional [model] and the joints; the finite element tables
// and [damping] are errors (the damping is in the measurement).
ModelFile read_frf_file(ModelReading& ctx, const Table& root) {
  reject_finite_element_keys(root, false, "[frf]: the substructure is given by measured FRFs");
  if (root.has("model")) read_model_table(ctx, root);
  Table t(ctx.file, *table(root, "frf"), "[frf]", {"files"});
  ctx.reading_frf = true;
  const int line = t.line();
  const toml::node& n = t.need("files", "the FRF files: a list such as [\"drive_7uy.uff\", "
                                        "\"drive_4uy.csv\"] (universal files or CSV tables)");
  std::vector<std::filesystem::path> files;
  if (n.is_string()) {
    files.push_back(ctx.directory / t.to_string(n, "key 'files'"));
  } else {
    const toml::array& list = t.to_array(n, "key 'files'", "file names");
    for (std::size_t i = 0; i < list.size(); ++i)
      files.push_back(ctx.directory /
                      t.to_string(list[i], fmt::format("key 'files', entry {}", i + 1)));
    if (files.empty()) t.fail_at(n, "key 'files'", "expected at least one file");
  }
  frf::MeasuredFrf frf = read_measured_frf(files); // its errors name the data file and line
  if (root.has("model") && ctx.model().dimension == 2)
    for (const fem::NodeDof& nd : frf.dofs)
      if (nd.dof != fem::Dof::ux && nd.dof != fem::Dof::uy && nd.dof != fem::Dof::rz)
        ctx.file.fail(line, "[frf]: a planar model (dimension = 2) has only ux, uy and rz, the "
                            "FRFs have " +
                                fem::to_string(nd));
  try {
    frf.validate();
  } catch (const std::invalid_argument& e) {
    ctx.file.fail(line, std::string("[frf]: ") + e.what());
  }
  for (const fem::NodeDof& nd : frf.dofs)
    ctx.node_lines.emplace(nd.node, line);
  read_joints(ctx, root);
  check_joints(ctx, fem::DofMap::from_dofs(frf.dofs));
  ctx.out.measured = std::move(frf);
  return std::move(ctx.out);
}

// Several substructures side by side: [[substructures]] file = "part.toml" (any model file
// but another composite), node_offset = N (added to its node ids and its joints' nodes), an
// optional [model], and the joints between them. The parts' own joints come along.
ModelFile read_composite_file(ModelReading& ctx, const Table& root) {
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
  if (root.has("model")) read_model_table(ctx, root);
  const auto list = tables(root, "substructures");
  if (list.empty()) root.fail("[[substructures]]: expected at least one substructure");
  std::vector<fem::NodeDof> dofs;
  std::map<int, std::size_t> node_part;
  std::vector<int> part_lines;
  // The dimension the parts must share, and where it comes from (list.size(): the whole's
  // [model]); a planar whole admits only ux, uy and rz.
  std::optional<std::pair<int, std::size_t>> dimension;
  if (root.has("model")) dimension = std::pair{ctx.model().dimension, list.size()};
  for (std::size_t i = 0; i < list.size(); ++i) {
    Table t(ctx.file, *list[i], fmt::format("[[substructures]] entry {}", i + 1),
            {"file", "node_offset"});
    const std::filesystem::path path = ctx.directory / t.string("file");
    int offset = 0;
    if (const toml::node* n = t.get("node_offset")) {
      offset = t.to_integer(*n, "key 'node_offset'");
      if (offset < 0)
        t.fail_at(*n, "key 'node_offset'", fmt::format("expected an integer >= 0, got {}", offset));
    }
    ModelFile part = read_model(path); // its errors name its own file and line
    const std::string name = path.filename().string();
    // Every part against the whole: a finite element part of another dimension than the
    // whole's [model] (or than the other finite element parts), a DOF a planar whole lacks, a
    // node id the offset would carry past the largest integer.
    if (!part.model.nodes.empty()) {
      if (!dimension) dimension = std::pair{part.model.dimension, i};
      if (dimension->first != part.model.dimension)
        t.fail_at(*t.get("file"), "key 'file'",
                  fmt::format(
                      "{} is a {} model (dimension = {}), but {} is {} (dimension = {}): "
                      "the parts of a model share its dimension",
                      name, part.model.dimension == 2 ? "planar" : "spatial", part.model.dimension,
                      dimension->second == list.size()
                          ? std::string("the whole ([model])")
                          : fmt::format("substructure {} ({})", dimension->second + 1,
                                        ctx.out.parts[dimension->second].path.filename().string()),
                      dimension->first == 2 ? "planar" : "spatial", dimension->first));
    }
    const fem::DofMap map = part.dof_map();
    for (int e = 0; e < map.num_equations(); ++e) {
      fem::NodeDof nd = map.node_dof(e);
      if (nd.node > std::numeric_limits<int>::max() - offset)
        t.fail_at(*t.get("file"), "key 'file'",
                  fmt::format("node {} of {} + node_offset {} is above the largest node id ({})",
                              nd.node, name, offset, std::numeric_limits<int>::max()));
      nd.node += offset;
      const auto [at, fresh] = node_part.emplace(nd.node, i);
      if (!fresh && at->second != i)
        t.fail_at(*t.get("file"), "key 'file'",
                  fmt::format("node {} of {} (node {} + node_offset {}) is also a node of "
                              "substructure {} ({}): give one of them a node_offset",
                              nd.node, path.filename().string(), nd.node - offset, offset,
                              at->second + 1, ctx.out.parts[at->second].path.filename().string()));
      ctx.node_lines.emplace(nd.node, t.line());
      dofs.push_back(nd);
    }
    part_lines.push_back(t.line());
    ctx.out.parts.push_back(std::move(part));
    ctx.out.node_offsets.push_back(offset);
  }
  // A planar whole (its [model], or its finite element parts) has only ux, uy and rz: a part's
  // DOF beyond them (a [modal], [matrices] or [frf] part lists any) is refused.
  if (dimension && dimension->first == 2)
    for (const fem::NodeDof& nd : dofs)
      if (nd.dof != fem::Dof::ux && nd.dof != fem::Dof::uy && nd.dof != fem::Dof::rz) {
        const std::size_t p = node_part.at(nd.node);
        ctx.file.fail(part_lines[p],
                      fmt::format("[[substructures]] entry {}: {} has the DOF {} (node {} + "
                                  "node_offset {}), but the model is planar (dimension = 2: {}), "
                                  "which has only ux, uy and rz",
                                  p + 1, ctx.out.parts[p].path.filename().string(),
                                  fem::to_string(nd), nd.node - ctx.out.node_offsets[p],
                                  ctx.out.node_offsets[p],
                                  dimension->second == list.size()
                                      ? std::string("its [model]")
                                      : fmt::format("substructure {}", dimension->second + 1)));
      }
  read_joints(ctx, root);
  check_joints(ctx, fem::DofMap::from_dofs(dofs));
  // The parts' own joints, their nodes moved by the offset; names stay unique.
  for (std::size_t p = 0; p < ctx.out.parts.size(); ++p)
    for (joints::Joint j : ctx.out.parts[p].joints) {
      j.node += ctx.out.node_offsets[p];
      if (j.node_b != 0) j.node_b += ctx.out.node_offsets[p];
      for (const joints::Joint& other : ctx.out.joints)
        if (other.name == j.name)
          ctx.file.fail(part_lines[p],
                        fmt::format("[[substructures]] entry {}: joint '{}' of {} has the name of "
                                    "another joint; rename one of them",
                                    p + 1, j.name, ctx.out.parts[p].path.filename().string()));
      ctx.out.joints.push_back(std::move(j));
    }
  return std::move(ctx.out);
}

} // namespace jointid::io::detail

// A substructure given by its modes: [modal], an optional [model] and the joints.
#include "io/model_reader.hpp"

#include "fem/dof_map.hpp"

#include <fmt/format.h>

#include <cmath>

namespace jointid::io::detail {

namespace {

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

// [modal]: dofs, frequencies_hz, damping, shapes and the optional residual_flexibility.
void read_modal(ModelReading& ctx, const Table& root) {
  Table t(ctx.file, *table(root, "modal"), "[modal]",
          {"dofs", "frequencies_hz", "damping", "shapes", "residual_flexibility"});
  ctx.modal_line = t.line();
  frf::ModalModel& modal = ctx.modal.emplace();

  const toml::node& dofs_node =
      t.need("dofs", "a list of \"<node>:<dof>\" such as [\"1:uy\", \"4:uy\"]");
  const toml::array& dofs =
      t.to_array(dofs_node, "key 'dofs'", "\"<node>:<dof>\" strings such as \"4:uy\"");
  if (dofs.empty()) t.fail_at(dofs_node, "key 'dofs'", "expected at least one DOF");
  const bool planar = root.has("model") && ctx.model().dimension == 2;
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
    ctx.node_lines.emplace(nd.node, line_of(dofs[i]) > 0 ? line_of(dofs[i]) : t.line());
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

void check_modal(ModelReading& ctx) {
  try {
    ctx.modal->validate();
  } catch (const std::invalid_argument& e) {
    ctx.file.fail(ctx.modal_line, std::string("[modal]: ") + e.what());
  }
  check_joints(ctx, fem::DofMap::from_dofs(ctx.modal->dofs));
  ctx.out.modal = std::move(ctx.modal);
}

} // namespace

// A substructure given by its modes: [modal], an optional [model] and the joints; the finite
// element tables are errors.
ModelFile read_modal_file(ModelReading& ctx, const Table& root) {
  reject_finite_element_keys(root, false, "[modal]: the substructure is given by its modes");
  if (root.has("model")) read_model_table(ctx, root);
  read_modal(ctx, root);
  read_joints(ctx, root);
  check_modal(ctx);
  return std::move(ctx.out);
}

} // namespace jointid::io::detail

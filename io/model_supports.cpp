// What the finite element model holds besides its elements: [[supports]], [[masses]],
// [[springs]], [damping] and [options].
#include "io/model_reader.hpp"

#include <fmt/format.h>

namespace jointid::io::detail {

void read_supports(ModelReading& ctx, const Table& root) {
  const auto list = tables(root, "supports");
  for (std::size_t i = 0; i < list.size(); ++i) {
    Table t(ctx.file, *list[i], item_label(*list[i], "supports", i, "node"),
            {"node", "nodes", "fix"});
    // node = id (or a one-node group); nodes = [ids] or a Gmsh group name.
    std::vector<int> nodes;
    const auto* one = t.get("node");
    const auto* many = t.get("nodes");
    if (one && many) t.fail("give either node or nodes, not both");
    if (!one && !many) t.fail("missing key 'node' (a node id) or 'nodes' (ids or a Gmsh group)");
    if (one) nodes.push_back(ctx.node_key(t, "node"));
    if (many && many->is_string())
      nodes = ctx.group_nodes(t, *many, "key 'nodes'");
    else if (many)
      for (const auto& n : t.to_array(*many, "key 'nodes'", "node ids or a Gmsh group name"))
        nodes.push_back(ctx.node_id(t, n, "key 'nodes'"));
    if (nodes.empty()) t.fail("the support holds no nodes");
    const toml::node& fix = t.need("fix", "a list of DOFs such as [\"ux\", \"uy\", \"rz\"]");
    const toml::array& dofs = t.to_array(fix, "key 'fix'", "DOF names (ux, uy, uz, rx, ry, rz)");
    if (dofs.empty()) t.fail_at(fix, "key 'fix'", "expected at least one DOF");
    fem::Support s;
    for (const auto& d : dofs)
      s.fixed.push_back(t.to_dof(d, "key 'fix'"));
    for (int node : nodes) {
      s.node = node;
      ctx.model().supports.push_back(s);
    }
  }
}

void read_masses(ModelReading& ctx, const Table& root) {
  const auto list = tables(root, "masses");
  for (std::size_t i = 0; i < list.size(); ++i) {
    Table t(ctx.file, *list[i], item_label(*list[i], "masses", i, "node"),
            {"node", "mass", "inertia"});
    fem::PointMass m;
    m.node = ctx.node_key(t, "node");
    m.mass = t.non_negative(t.need("mass", "a number (kg)"), "mass", "kg");
    if (const auto* n = t.get("inertia")) {
      m.inertia = t.to_vector3(*n, "key 'inertia'");
      if (!(m.inertia.minCoeff() >= 0.0))
        t.fail_at(*n, "key 'inertia'", "expected [Ix, Iy, Iz] >= 0 kg m^2");
    }
    ctx.model().masses.push_back(m);
  }
}

void read_springs(ModelReading& ctx, const Table& root) {
  const auto list = tables(root, "springs");
  for (std::size_t i = 0; i < list.size(); ++i) {
    Table t(ctx.file, *list[i], item_label(*list[i], "springs", i, "node"),
            {"node", "node_b", "dof", "stiffness"});
    fem::Spring s;
    s.node = ctx.node_key(t, "node");
    if (const auto* n = t.get("node_b")) s.node_b = ctx.node_id(t, *n, "key 'node_b'", true);
    if (s.node_b == s.node)
      t.fail_at(*t.get("node_b"), "key 'node_b'", "a spring cannot connect a node to itself");
    s.dof = t.dof("dof");
    s.stiffness =
        t.non_negative(t.need("stiffness", "a number (N/m or N m/rad)"), "stiffness", "N/m");
    ctx.model().springs.push_back(s);
  }
}

void read_damping(ModelReading& ctx, const Table& root) {
  const toml::table* d = table(root, "damping");
  if (!d) return;
  Table t(ctx.file, *d, "[damping]", {"modal", "rayleigh"});
  const auto* modal = t.get("modal");
  const auto* rayleigh = t.get("rayleigh");
  if (modal && rayleigh) t.fail("give either modal = ratio or rayleigh = [alpha, beta], not both");
  if (!modal && !rayleigh) t.fail("expected modal = ratio or rayleigh = [alpha, beta]");
  fem::Damping& damping = ctx.model().damping;
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

void read_options(ModelReading& ctx, const Table& root) {
  const toml::table* o = table(root, "options");
  if (!o) return;
  Table t(ctx.file, *o, "[options]", {"lumped_mass", "iwan_sliders"});
  if (const auto lumped = t.optional_boolean("lumped_mass"))
    ctx.model().mass_options.lumped = *lumped;
  if (const auto* n = t.get("iwan_sliders")) {
    const int sliders = t.to_integer(*n, "key 'iwan_sliders'");
    if (sliders < 2 || sliders > 100000)
      t.fail_at(*n, "key 'iwan_sliders'",
                "expected the number of Jenkins elements of an iwan's quadrature, from 2 to "
                "100000, got " +
                    shown(*n));
    ctx.iwan_sliders = sliders;
  }
}

} // namespace jointid::io::detail

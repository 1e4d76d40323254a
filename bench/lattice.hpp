#pragma once
/// Large 3D frame lattices for scale benchmarks: nodes on an nx × ny × nz grid with spacing
/// `spacing` (m), a frame3d member between every pair of grid neighbours along x, y and z, and
/// the base (z = 0) nodes fixed in all six DOFs. Free DOFs: 6 · nx · ny · (nz − 1).
/// SI units (m, kg, Pa).
#include "fem/model.hpp"

#include <stdexcept>
#include <string>

namespace jointid::bench {

struct LatticeSize {
  int nodes = 0;
  int elements = 0;
  int free_dofs = 0;
};

/// Counts of frame_lattice(nx, ny, nz, ·) without building it.
inline LatticeSize lattice_size(int nx, int ny, int nz) {
  return {nx * ny * nz, (nx - 1) * ny * nz + nx * (ny - 1) * nz + nx * ny * (nz - 1),
          6 * nx * ny * (nz - 1)};
}

/// Node id of grid point (i, j, k), 1-based, x fastest.
inline int lattice_node_id(int nx, int ny, int i, int j, int k) {
  return 1 + i + nx * (j + ny * k);
}

/// Steel (E 210 GPa, ρ 7850 kg/m³, ν 0.3) members of one hollow-ish section (A 1e-3 m²,
/// Iy = Iz 1e-6 m⁴, J 2e-6 m⁴), consistent mass.
inline fem::Model frame_lattice(int nx, int ny, int nz, double spacing) {
  if (nx < 1 || ny < 1 || nz < 2 || nx * ny < 2 || !(spacing > 0.0))
    throw std::invalid_argument("frame_lattice: need nx, ny >= 1 with nx*ny >= 2, nz >= 2 and "
                                "spacing > 0 (got " +
                                std::to_string(nx) + " x " + std::to_string(ny) + " x " +
                                std::to_string(nz) + ", spacing " + std::to_string(spacing) + ")");
  const LatticeSize size = lattice_size(nx, ny, nz);
  fem::Model model;
  model.dimension = 3;
  model.materials.push_back({"steel", 210e9, 7850.0, 0.3});
  model.sections.push_back({"tube", 1e-3, 1e-6, 1e-6, 2e-6});
  model.nodes.reserve(size.nodes);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i)
        model.nodes.push_back({lattice_node_id(nx, ny, i, j, k),
                               Eigen::Vector3d(i * spacing, j * spacing, k * spacing)});

  model.elements.reserve(size.elements);
  int next_id = 1;
  // x and y members lie in horizontal planes, so UnitZ is never parallel to them; z members
  // take UnitX.
  auto member = [&](int a, int b, const Eigen::Vector3d& up) {
    fem::Element e;
    e.id = next_id++;
    e.node_a = a;
    e.node_b = b;
    e.type = fem::ElementType::frame3d;
    e.material = 0;
    e.section = 0;
    e.up = up;
    model.elements.push_back(e);
  };
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < ny; ++j)
      for (int i = 0; i < nx; ++i) {
        const int here = lattice_node_id(nx, ny, i, j, k);
        if (i + 1 < nx)
          member(here, lattice_node_id(nx, ny, i + 1, j, k), Eigen::Vector3d::UnitZ());
        if (j + 1 < ny)
          member(here, lattice_node_id(nx, ny, i, j + 1, k), Eigen::Vector3d::UnitZ());
        if (k + 1 < nz)
          member(here, lattice_node_id(nx, ny, i, j, k + 1), Eigen::Vector3d::UnitX());
      }

  const std::vector<fem::Dof> all(fem::all_dofs.begin(), fem::all_dofs.end());
  model.supports.reserve(static_cast<std::size_t>(nx) * ny);
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      model.supports.push_back({lattice_node_id(nx, ny, i, j, 0), all});
  return model;
}

} // namespace jointid::bench

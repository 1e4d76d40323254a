#pragma once
// The paper's cantilever (METHOD.md, as test::cantilever(6): 6 beam elements, first mode
// 3.0 Hz) with 1 % modal damping and its receptance by modal synthesis with every mode kept (so
// exact for the FE model): the fixture of the harmonic-balance and continuation tests.
#include "fem/modal.hpp"
#include "frf/receptance.hpp"
#include "support/beam_models.hpp"

namespace jointid::test {

struct SynthesisedCantilever {
  fem::Model model = [] {
    fem::Model m = cantilever(6, {});
    m.damping.kind = fem::Damping::Kind::modal;
    m.damping.modal_ratio = 0.01;
    return m;
  }();
  fem::Assembled system = fem::assemble(model);
  fem::Modes modes =
      fem::modal_analysis(system, {.num_modes = 0, .engine = fem::ModalEngine::dense});
  frf::ModalSynthesis H{system, modes, model.damping, all_equations(system)};
  /// The equation of node `node`'s uy.
  int eq(int node) const { return system.dofs.equation({node, fem::Dof::uy}); }
};

} // namespace jointid::test

// Which DOFs the picture of `jointid response` can show: those the response curves hold.
#include "report/response_figure.hpp"

#include <gtest/gtest.h>

#include <vector>

using namespace jointid;
using fem::Dof;

namespace {

// The curves hold every joint DOF (both nodes of a joint between two) and the force DOF.
TEST(ResponseFigure, ShowsTheForceDofAndTheJointsDofs) {
  const std::vector<joints::Joint> joints{
      {"ground", 7, 0, Dof::uy, {joints::Term::k}, {1.0}, {false}, {}},
      {"link", 2, 3, Dof::ux, {joints::Term::k}, {1.0}, {false}, {}}};
  const fem::NodeDof force{5, Dof::uy};
  for (const fem::NodeDof dof : {fem::NodeDof{5, Dof::uy}, fem::NodeDof{7, Dof::uy},
                                 fem::NodeDof{2, Dof::ux}, fem::NodeDof{3, Dof::ux}})
    EXPECT_TRUE(report::response_figure_can_show(joints, force, dof)) << fem::to_string(dof);
  for (const fem::NodeDof dof : {fem::NodeDof{4, Dof::uy}, fem::NodeDof{7, Dof::ux},
                                 fem::NodeDof{3, Dof::uy}, fem::NodeDof{5, Dof::ux}})
    EXPECT_FALSE(report::response_figure_can_show(joints, force, dof)) << fem::to_string(dof);
  EXPECT_TRUE(report::response_figure_can_show({}, force, force));
}

} // namespace

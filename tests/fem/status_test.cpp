// The status vocabulary every folder passes up (DESIGN.md: a numerical outcome is a status with
// its reason).
#include "fem/status.hpp"

#include <gtest/gtest.h>

using jointid::fem::Status;

TEST(Status, DefaultIsOkWithoutReason) {
  const Status s;
  EXPECT_TRUE(s.ok());
  EXPECT_EQ(s.code, Status::Code::ok);
  EXPECT_TRUE(s.reason.empty());
}

TEST(Status, AFailureKeepsItsCodeAndReasonAndTakesContextInFront) {
  const Status s = Status::failure(Status::Code::not_converging, "60 iterations");
  EXPECT_FALSE(s.ok());
  const Status named = s.within("test 3: ");
  EXPECT_EQ(named.code, Status::Code::not_converging);
  EXPECT_EQ(named.reason, "test 3: 60 iterations");
  EXPECT_EQ(s.reason, "60 iterations"); // the original is unchanged
  // ok stays ok, without a reason to prefix.
  EXPECT_TRUE(Status{}.within("test 3: ").reason.empty());
}

TEST(Status, CodeNamesAreTheJsonResultsWords) {
  using jointid::fem::code_name;
  EXPECT_EQ(code_name(Status::Code::ok), "ok");
  EXPECT_EQ(code_name(Status::Code::not_converging), "not_converging");
  EXPECT_EQ(code_name(Status::Code::not_periodic), "not_periodic");
  EXPECT_EQ(code_name(Status::Code::numerical_issue), "numerical_issue");
  EXPECT_EQ(code_name(Status::Code::not_separable), "not_separable");
}

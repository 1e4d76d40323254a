#pragma once
/// Small statistics helpers for the identification's uncertainty.

namespace jointid::identify {

/// Regularised incomplete beta function I_x(a, b).
double incomplete_beta(double a, double b, double x);
/// Student's t cumulative distribution with `dof` degrees of freedom.
double student_t_cdf(double t, double dof);
/// The p-quantile of Student's t (0 < p < 1), e.g. p = 0.975 for a two-sided 95 % interval.
double student_t_quantile(double p, double dof);

} // namespace jointid::identify

#pragma once
// Order statistics shared by the modules (the campaign's batch statistics and super-element fit,
// metrology's robust outliers) and the distributions the uncertainties' coverage factors come from.
#include <vector>

namespace piezobench::core {

// The median of `values`: the middle value, or the mean of the two middle values for an even
// count; NaN for no values. NaN entries are not allowed (they have no order).
double median(std::vector<double> values);

// The regularized incomplete beta function I_x(a, b) (DLMF 8.17.2) for a, b > 0 and x in [0, 1]
// (else InputError), from its continued fraction (DLMF 8.17.22, modified Lentz evaluation) on the
// side of the symmetry I_x(a, b) = 1 - I_{1-x}(b, a) where it converges fast; ~1e-14 relative.
[[nodiscard]] double incomplete_beta(double a, double b, double x);

// The p-quantile of Student's t distribution with `dof` > 0 degrees of freedom (real: Welch's
// effective averages give fractional ones) for p in (0, 1) (else InputError): the t with
// P(T <= t) = p, from P(|T| > t) = I_{dof / (dof + t^2)}(dof / 2, 1 / 2) solved by bisection to a
// relative 1e-14. It tends to the Gaussian's quantile as dof grows (1.959966 at p = 0.975, dof = 1e6).
[[nodiscard]] double student_t_quantile(double p, double dof);

}  // namespace piezobench::core

#pragma once
// Derivatives by central differences with Richardson extrapolation, exactly as R's
// numDeriv computes them (method "Richardson": first step d |x|, plus 1e-4 when x is
// near 0; four steps, each half the last, extrapolated): lmerTest's Satterthwaite degrees
// of freedom rest on numDeriv's jacobian (d = 1e-4) and hessian (genD's stencil, d =
// 0.1), and a flat likelihood makes the result depend on the scheme, so the same scheme
// is what gives the same answers.
#include <Eigen/Dense>
#include <functional>

namespace lucent::analysis::mixed {

// numDeriv::jacobian: rows are outputs, columns inputs.
Eigen::MatrixXd richardson_jacobian(
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
    const Eigen::VectorXd& x);

// numDeriv::hessian (genD): symmetric.
Eigen::MatrixXd richardson_hessian(const std::function<double(const Eigen::VectorXd&)>& f,
                                   const Eigen::VectorXd& x);

}  // namespace lucent::analysis::mixed

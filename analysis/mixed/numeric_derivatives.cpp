#include "analysis/mixed/numeric_derivatives.h"

#include <cmath>
#include <vector>

namespace lucent::analysis::mixed {
namespace {

constexpr int kSteps = 4;  // numDeriv's r (and v = 2: each step half the last)
constexpr double kNearZeroStep = 1e-4;  // numDeriv's eps
// numDeriv's zero.tol: sqrt(.Machine$double.eps / 7e-7).
const double kZeroTolerance = std::sqrt(2.220446049250313e-16 / 7e-7);

Eigen::VectorXd first_steps(const Eigen::VectorXd& x, double d) {
    Eigen::VectorXd h(x.size());
    for (Eigen::Index i = 0; i < x.size(); ++i)
        h[i] =
            std::abs(d * x[i]) + (std::abs(x[i]) < kZeroTolerance ? kNearZeroStep : 0.0);
    return h;
}

// Richardson's extrapolation of estimates whose error is a series in h^2, the step
// halving from one to the next.
template <typename Value>
Value extrapolate(std::vector<Value> estimates) {
    double factor = 4.0;
    for (int level = 1; level < kSteps; ++level, factor *= 4.0)
        for (int k = 0; k + level < kSteps; ++k)
            estimates[std::size_t(k)] =
                (estimates[std::size_t(k + 1)] * factor - estimates[std::size_t(k)]) /
                (factor - 1.0);
    return estimates[0];
}

}  // namespace

Eigen::MatrixXd richardson_jacobian(
    const std::function<Eigen::VectorXd(const Eigen::VectorXd&)>& f,
    const Eigen::VectorXd& x) {
    const Eigen::VectorXd at = f(x);
    const Eigen::VectorXd steps = first_steps(x, 1e-4);
    Eigen::MatrixXd jacobian(at.size(), x.size());
    for (Eigen::Index i = 0; i < x.size(); ++i) {
        std::vector<Eigen::VectorXd> estimates;
        double h = steps[i];
        for (int k = 0; k < kSteps; ++k, h /= 2.0) {
            Eigen::VectorXd up = x, down = x;
            up[i] += h;
            down[i] -= h;
            estimates.push_back((f(up) - f(down)) / (2.0 * h));
        }
        jacobian.col(i) = extrapolate(std::move(estimates));
    }
    return jacobian;
}

Eigen::MatrixXd richardson_hessian(const std::function<double(const Eigen::VectorXd&)>& f,
                                   const Eigen::VectorXd& x) {
    const Eigen::Index n = x.size();
    const double at = f(x);
    const Eigen::VectorXd steps = first_steps(x, 0.1);
    Eigen::MatrixXd hessian(n, n);
    // The diagonal first, from f(x +- h e_i); genD's off-diagonal stencil then steps
    // along e_i + e_j and subtracts the diagonal terms.
    for (Eigen::Index i = 0; i < n; ++i) {
        std::vector<double> estimates;
        double h = steps[i];
        for (int k = 0; k < kSteps; ++k, h /= 2.0) {
            Eigen::VectorXd up = x, down = x;
            up[i] += h;
            down[i] -= h;
            estimates.push_back((f(up) - 2.0 * at + f(down)) / (h * h));
        }
        hessian(i, i) = extrapolate(std::move(estimates));
    }
    for (Eigen::Index i = 0; i < n; ++i)
        for (Eigen::Index j = 0; j < i; ++j) {
            std::vector<double> estimates;
            double hi = steps[i], hj = steps[j];
            for (int k = 0; k < kSteps; ++k, hi /= 2.0, hj /= 2.0) {
                Eigen::VectorXd up = x, down = x;
                up[i] += hi;
                up[j] += hj;
                down[i] -= hi;
                down[j] -= hj;
                estimates.push_back((f(up) - 2.0 * at + f(down) -
                                     hessian(i, i) * hi * hi - hessian(j, j) * hj * hj) /
                                    (2.0 * hi * hj));
            }
            hessian(i, j) = hessian(j, i) = extrapolate(std::move(estimates));
        }
    return hessian;
}

}  // namespace lucent::analysis::mixed

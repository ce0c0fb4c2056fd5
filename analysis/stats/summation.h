#pragma once
// Compensated (Neumaier) summation: the error of each addition is carried separately, so
// a sum of n terms is accurate to about one rounding regardless of n or cancellation.
#include <cmath>

namespace lucent::analysis {

class CompensatedSum {
public:
    void add(double x) {
        const double t = sum_ + x;
        // The larger operand keeps its digits; recover what the smaller one lost.
        compensation_ += std::fabs(sum_) >= std::fabs(x) ? (sum_ - t) + x : (x - t) + sum_;
        sum_ = t;
    }
    double value() const { return sum_ + compensation_; }

private:
    double sum_ = 0.0;
    double compensation_ = 0.0;
};

}  // namespace lucent::analysis

#pragma once
// Exact decimal arithmetic on number texts, so that an origin can be subtracted before a
// value is rounded to double (1000000000000.4 parsed as a double is already off by 2e-5).
#include <string>
#include <string_view>

namespace lucent::analysis {

// (value - origin) computed exactly in 100-digit decimal, then rounded once to double.
// Both texts must be valid numbers (common::parse_finite_number). A difference beyond the
// double range (1e308 - -1e308) is an infinity of its sign, never an exception: the
// caller refuses it naming the row.
double exact_difference(std::string_view value, std::string_view origin);

}  // namespace lucent::analysis

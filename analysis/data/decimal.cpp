#include "analysis/data/decimal.h"

#include <algorithm>
#include <boost/multiprecision/cpp_dec_float.hpp>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>

namespace lucent::analysis {
namespace {

std::string_view trim(std::string_view text) {
    while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front())))
        text.remove_prefix(1);
    while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back())))
        text.remove_suffix(1);
    return text;
}

// A plain decimal ([-]digits[.digits], no exponent) of at most 17 digits as an integer
// and its count of fraction digits: value = integer / 10^fraction_digits, exactly.
struct ScaledInteger {
    std::int64_t integer = 0;
    int fraction_digits = 0, digits = 0;
};

std::optional<ScaledInteger> plain_decimal(std::string_view text) {
    ScaledInteger r;
    bool negative = false, point = false;
    std::size_t i = 0;
    if (i < text.size() && (text[i] == '-' || text[i] == '+'))
        negative = text[i++] == '-';
    if (i == text.size()) return std::nullopt;
    for (; i < text.size(); ++i) {
        const char c = text[i];
        if (c == '.' && !point) {
            point = true;
        } else if (c >= '0' && c <= '9') {
            if (++r.digits > 17) return std::nullopt;
            r.integer = r.integer * 10 + (c - '0');
            if (point) ++r.fraction_digits;
        } else {
            return std::nullopt;
        }
    }
    if (r.digits == 0) return std::nullopt;
    if (negative) r.integer = -r.integer;
    return r;
}

}  // namespace

double exact_difference(std::string_view value, std::string_view origin) {
    // Fast path (every Likert rating): both texts are short plain decimals, so the
    // difference is an exact integer over 10^d, and one IEEE division by the exact
    // double 10^d (d <= 22) rounds it once, as the decimal path below does.
    const auto a = plain_decimal(trim(value)), b = plain_decimal(trim(origin));
    if (a && b) {
        const int d = std::max(a->fraction_digits, b->fraction_digits);
        const int a_shift = d - a->fraction_digits, b_shift = d - b->fraction_digits;
        if (a->digits + a_shift <= 17 && b->digits + b_shift <= 17) {
            static constexpr double kPowers[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,
                                                 1e6,  1e7,  1e8,  1e9,  1e10, 1e11,
                                                 1e12, 1e13, 1e14, 1e15, 1e16, 1e17};
            std::int64_t ai = a->integer, bi = b->integer;
            for (int i = 0; i < a_shift; ++i) ai *= 10;
            for (int i = 0; i < b_shift; ++i) bi *= 10;
            const std::int64_t difference = ai - bi;  // |.| < 2e17: no overflow
            constexpr std::int64_t kExactInDouble = std::int64_t{1} << 53;
            if (difference >= -kExactInDouble && difference <= kExactInDouble)
                return static_cast<double>(difference) / kPowers[d];
        }
    }
    using Decimal = boost::multiprecision::cpp_dec_float_100;
    auto to_decimal = [](std::string_view text) {
        text = trim(text);
        if (!text.empty() && text.front() == '+') text.remove_prefix(1);
        return Decimal(std::string(text));
    };
    const Decimal difference = to_decimal(value) - to_decimal(origin);
    // Round once: through the shortest exact decimal text, parsed correctly rounded.
    // A difference beyond the double range (ratings of 1e308 and -1e308) is returned as
    // an infinity of its sign, for the caller to refuse naming the row (never an
    // exception without a location, as std::stod's "stod" was).
    const std::string text = difference.str(40, std::ios_base::scientific);
    double rounded = 0.0;
    const auto [end, error] =
        std::from_chars(text.data(), text.data() + text.size(), rounded);
    if (error == std::errc::result_out_of_range) {
        if (abs(difference) < 1) return 0.0;  // below the smallest subnormal
        return difference < 0 ? -std::numeric_limits<double>::infinity()
                              : std::numeric_limits<double>::infinity();
    }
    if (error != std::errc() || end != text.data() + text.size())
        return std::numeric_limits<double>::quiet_NaN();  // not reached: the text is ours
    return rounded;
}

}  // namespace lucent::analysis

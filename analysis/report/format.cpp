#include "analysis/report/format.h"

#include <cmath>
#include <cstdio>
#include <functional>

#include "common/number_text.h"

namespace lucent::analysis {
namespace {

std::string format_with(const Statistic& value,
                        const std::function<std::string(double)>& text) {
    if (!value || std::isnan(*value)) return "undefined";
    if (std::isinf(*value)) return *value > 0 ? "inf" : "-inf";
    return text(*value);
}

std::string format_with(const Statistic& value, const char* pattern) {
    return format_with(value, [pattern](double v) {
        char buffer[64];
        std::snprintf(buffer, sizeof buffer, pattern, v);
        return std::string(buffer);
    });
}

}  // namespace

std::string format_full(const Statistic& value) {
    return format_with(value, common::full_precision_text);
}
std::string format_short(const Statistic& value) { return format_with(value, "%.4g"); }

std::string format_p_full(const Statistic& p) {
    if (p && *p < kSmallestReportedP) return "< 1e-300";
    return format_full(p);
}

std::string format_p_short(const Statistic& p) {
    if (p && *p < kSmallestReportedP) return "< 1e-300";
    if (p && *p < 1e-4) return format_with(p, "%.2e");
    return format_short(p);
}

}  // namespace lucent::analysis

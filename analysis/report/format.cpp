#include "analysis/report/format.h"

#include <cmath>
#include <cstdio>

namespace lucent::analysis {
namespace {

std::string format_with(const Statistic& value, const char* pattern) {
    if (!value || std::isnan(*value)) return "undefined";
    if (std::isinf(*value)) return *value > 0 ? "inf" : "-inf";
    char buffer[64];
    std::snprintf(buffer, sizeof buffer, pattern, *value);
    return buffer;
}

}  // namespace

std::string format_full(const Statistic& value) { return format_with(value, "%.17g"); }
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

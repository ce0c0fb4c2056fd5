#include "renderer/core/stimulus.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace lucent {

double KnobMotion::value_at(double t_s) const {
    if (!std::isfinite(t_s))
        throw std::invalid_argument("motion of '" + knob + "': time is not finite");
    // fmod keeps the phase exact for any finite t (t / period would lose it for large t).
    double cycle = std::fmod(t_s, period_s);
    if (cycle < 0) cycle += period_s;
    const double phase = std::clamp(cycle / period_s, 0.0, 1.0);
    const double along = shape == Shape::loop ? phase : 1.0 - std::abs(2.0 * phase - 1.0);
    const double value = from + (to - from) * along;
    return std::clamp(value, std::min(from, to), std::max(from, to));
}

std::map<std::string, std::string> Stimulus::columns() const {
    std::map<std::string, std::string> out = parameters;
    out.insert(factors.begin(), factors.end());
    return out;
}

KnobValues Stimulus::values_at(double t_s) const {
    KnobValues out = values;
    for (const KnobMotion& m : motion) out.set(m.knob, m.value_at(t_s));
    return out;
}

}  // namespace lucent

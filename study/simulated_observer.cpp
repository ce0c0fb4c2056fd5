#include "study/simulated_observer.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

#include "common/number_text.h"

namespace lucent::study {

namespace {

// The comma-separated numbers of an observer's option, 2 or 3 of them as `form` says
// ("EXPONENT,SIGMA[,LAPSE]"); std::invalid_argument naming the bad part.
std::vector<double> observer_numbers(const std::string& text, const std::string& form) {
    std::vector<double> parts;
    std::istringstream in(text);
    for (std::string item; std::getline(in, item, ',');) {
        const std::optional<double> v = common::parse_finite(item);
        if (!v)
            throw std::invalid_argument("observer '" + text + "': '" + item +
                                        "' is not a number (expected " + form + ")");
        parts.push_back(*v);
    }
    if (parts.size() < 2 || parts.size() > 3)
        throw std::invalid_argument("observer '" + text + "': expected " + form);
    return parts;
}

// The share of trials on which a detection observer sees `delta`.
double seen_probability(const DetectionObserver& o, double delta) {
    return 0.5 *
           std::erfc(-(std::abs(delta) - o.threshold) / (o.spread * std::sqrt(2.0)));
}

}  // namespace

ObserverModel ObserverModel::parse(const std::string& text) {
    ObserverModel m;
    const std::vector<double> parts = observer_numbers(text, "EXPONENT,SIGMA[,LAPSE]");
    m.exponent = parts[0];
    m.sigma = parts[1];
    m.lapse = parts.size() == 3 ? parts[2] : 0.0;
    if (!(m.exponent > 0 && m.exponent <= 10))
        throw std::invalid_argument("observer '" + text +
                                    "': EXPONENT must be in (0, 10]");
    if (!(m.sigma >= 0 && m.sigma <= 10))
        throw std::invalid_argument("observer '" + text + "': SIGMA must be in [0, 10]");
    if (!(m.lapse >= 0 && m.lapse <= 1))
        throw std::invalid_argument("observer '" + text + "': LAPSE must be in [0, 1]");
    return m;
}

std::string ObserverModel::describe() const {
    std::ostringstream out;
    out << "psi = x^" << exponent << ", sigma " << sigma << ", lapse " << lapse;
    return out.str();
}

double ObserverModel::scale(double value, double lo, double hi) const {
    if (!(hi > lo)) return 0.0;
    const double x = std::clamp((value - lo) / (hi - lo), 0.0, 1.0);
    return std::pow(x, exponent);
}

ChoiceStimuli choice_stimuli(const Protocol& protocol, const std::string& block,
                             const std::vector<std::string>& shown) {
    ChoiceStimuli out;
    const Block* b = protocol.find_block(block);
    if (!b) return out;
    out.task = b->task;
    if (b->series.empty()) return out;
    auto value_of = [&](const std::string& id) {
        return protocol.numeric_parameter(id, b->series);
    };
    std::vector<double> values;
    for (const std::string& id : shown) {
        const std::optional<double> v = value_of(id);
        if (!v) return out;
        values.push_back(*v);
    }
    std::optional<double> lo, hi;
    for (const std::string& id : b->stimuli)
        if (const std::optional<double> v = value_of(id)) {
            lo = lo ? std::min(*lo, *v) : *v;
            hi = hi ? std::max(*hi, *v) : *v;
        }
    if (!lo || !hi) return out;
    if (b->obvious_catch.size() == 2) {
        const std::optional<double> less = value_of(b->obvious_catch[0]);
        const std::optional<double> more = value_of(b->obvious_catch[1]);
        out.more_is_lower = less && more && *more < *less;
    }
    out.values = std::move(values);
    out.lo = *lo;
    out.hi = *hi;
    return out;
}

int simulated_choice(const ObserverModel& observer, const ChoiceStimuli& trial,
                     std::mt19937_64& rng) {
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    std::normal_distribution<double> noise(0.0, observer.sigma);
    const bool lapse = observer.lapse > 0 && uniform(rng) < observer.lapse;
    const size_t needed = static_cast<size_t>(pictures_per_trial(trial.task));
    if (lapse || trial.values.size() != needed) return uniform(rng) < 0.5 ? 1 : 2;
    std::vector<double> psi;
    for (double v : trial.values) psi.push_back(observer.scale(v, trial.lo, trial.hi));
    const double e = observer.sigma > 0 ? noise(rng) : 0.0;
    if (trial.task == Task::pair) {
        // Each picture its own noise: the difference has variance 2 sigma^2.
        const double e2 = observer.sigma > 0 ? noise(rng) : 0.0;
        const double sign = trial.more_is_lower ? -1.0 : 1.0;
        return sign * psi[0] + e >= sign * psi[1] + e2 ? 1 : 2;
    }
    if (trial.task == Task::triad)
        return std::abs(psi[1] - psi[0]) - std::abs(psi[2] - psi[1]) + e >= 0 ? 1 : 2;
    if (trial.task == Task::quadruple)
        return std::abs(psi[1] - psi[0]) - std::abs(psi[3] - psi[2]) + e >= 0 ? 1 : 2;
    throw std::logic_error(std::string("simulated_choice: '") + task_name(trial.task) +
                           "' is not a forced choice the scaling reads");
}

DetectionObserver DetectionObserver::parse(const std::string& text) {
    const std::vector<double> parts = observer_numbers(text, "THRESHOLD,SPREAD[,LAPSE]");
    DetectionObserver o{parts[0], parts[1], parts.size() == 3 ? parts[2] : 0.0};
    if (!(o.threshold >= 0))
        throw std::invalid_argument("observer '" + text + "': THRESHOLD must be >= 0");
    if (!(o.spread > 0))
        throw std::invalid_argument("observer '" + text + "': SPREAD must be > 0");
    if (!(o.lapse >= 0 && o.lapse <= 1))
        throw std::invalid_argument("observer '" + text + "': LAPSE must be in [0, 1]");
    return o;
}

double DetectionObserver::p_correct(double delta, double guess) const {
    const double seen = seen_probability(*this, delta);
    // Not lapsing: seen, or a guess; lapsing: a guess.
    return (1.0 - lapse) * (seen + (1.0 - seen) * guess) + lapse * guess;
}

bool simulated_detection(const DetectionObserver& observer, double delta, double guess,
                         std::mt19937_64& rng) {
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    if (observer.lapse > 0 && uniform(rng) < observer.lapse) return uniform(rng) < guess;
    const double seen = seen_probability(observer, delta);
    if (uniform(rng) < seen) return true;
    return uniform(rng) < guess;
}

MatchObserver MatchObserver::parse(const std::string& text) {
    std::string numbers = text;
    MatchObserver o;
    if (const size_t comma = numbers.rfind(',');
        comma != std::string::npos && numbers.substr(comma + 1) == "log") {
        o.log_scale = true;
        numbers.resize(comma);
    }
    const std::vector<double> parts = observer_numbers(numbers, "BIAS,NOISE[,log]");
    if (parts.size() != 2)
        throw std::invalid_argument("observer '" + text + "': expected BIAS,NOISE[,log]");
    o.bias = parts[0];
    o.noise = parts[1];
    if (!(o.noise >= 0))
        throw std::invalid_argument("observer '" + text + "': NOISE must be >= 0");
    return o;
}

double simulated_match(const MatchObserver& observer, double target, double lo, double hi,
                       std::mt19937_64& rng) {
    std::normal_distribution<double> noise(0.0, observer.noise);
    const double e = observer.noise > 0 ? noise(rng) : 0.0;
    double match = observer.log_scale && target > 0
                       ? std::exp(std::log(target) + observer.bias + e)
                       : target + observer.bias + e;
    if (!std::isfinite(match)) match = target;
    return std::clamp(match, std::min(lo, hi), std::max(lo, hi));
}

}  // namespace lucent::study

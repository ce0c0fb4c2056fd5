#include "analysis/analyze.h"

#include <chrono>
#include <map>

#include "analysis/data/grouping.h"
#include "analysis/data/subject_matrix.h"

namespace lucent::analysis {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_between(Clock::time_point from, Clock::time_point to) {
    return std::chrono::duration<double>(to - from).count();
}

// The mixed-model fits of a run, in order, timed for ModelFitProgress.
class FitProgress {
public:
    FitProgress(const std::vector<FactorData>& pairs, const AnalysisRequest& request)
        : on_fit_(request.on_fit) {
        for (const FactorData& pair : pairs) {
            std::size_t ratings = 0;
            for (const Group& g : pair.data.groups) ratings += g.values.size();
            for (const std::string& model : request.models.mixed)
                fits_.push_back({model, ratings});
        }
    }
    // Before a pair's models: the time from here to the first one's end is its (the
    // model frame is built for the pair's first model).
    void pair_starts() { mark_ = Clock::now(); }
    ModelFitHook hook(const FactorData& pair) {
        if (!on_fit_) return {};
        return [this, &pair](const std::string&, const RatingModelFit* fit) {
            const Fit& f = fits_.at(next_);
            ModelFitProgress p;
            p.model = f.model;
            p.index = static_cast<int>(next_) + 1;
            p.total = static_cast<int>(fits_.size());
            p.question = pair.question;
            p.factor = pair.factor;
            p.ratings = f.ratings;
            if (!fit) {
                if (next_ == 0) start_ = mark_;
                on_fit_(p);
                return;
            }
            const Clock::time_point now = Clock::now();
            p.done = true;
            p.fitted = fit->fitted;
            p.seconds = seconds_between(mark_, now);
            mark_ = now;
            p.elapsed = seconds_between(start_, now);
            Rate& rate = rates_[f.model];
            rate.seconds += p.seconds;
            rate.ratings += static_cast<double>(f.ratings);
            all_.seconds += p.seconds;
            all_.ratings += static_cast<double>(f.ratings);
            ++next_;
            for (std::size_t i = next_; i < fits_.size(); ++i) {
                const auto known = rates_.find(fits_[i].model);
                const Rate& r = known != rates_.end() ? known->second : all_;
                if (r.ratings > 0)
                    p.left +=
                        r.seconds / r.ratings * static_cast<double>(fits_[i].ratings);
            }
            on_fit_(p);
        };
    }

private:
    struct Fit {
        std::string model;
        std::size_t ratings;
    };
    struct Rate {
        double seconds = 0.0, ratings = 0.0;
    };
    std::function<void(const ModelFitProgress&)> on_fit_;
    std::vector<Fit> fits_;
    std::size_t next_ = 0;
    Clock::time_point start_, mark_;
    std::map<std::string, Rate> rates_;
    Rate all_;
};

}  // namespace

AnalysisResult analyze_table(const LongTable& table, const AnalysisRequest& request) {
    const auto pairs =
        split_by_question_and_factor(table, request.question, request.factor);
    if (pairs.empty())
        throw InputError(
            std::string("no ratings") +
            (request.question.empty() ? "" : " for question '" + request.question + "'") +
            (request.factor.empty() ? "" : " for factor '" + request.factor + "'"));
    AnalysisResult result;
    std::vector<OneWayAnalysis>& analyses = result.pairs;
    FitProgress progress(pairs, request);
    for (const FactorData& pair : pairs) {
        if (request.on_pair)
            request.on_pair(pair.question, pair.factor, pair.data.groups.size());
        analyses.push_back(
            analyze_one_way(pair.question, pair.factor, pair.data, request.alpha));
        analyses.back().missing_ratings = pair.missing_ratings;
        std::vector<std::string> levels;
        for (const Group& g : pair.data.groups) levels.push_back(g.level);
        SubjectMatrix matrix =
            subject_by_level(table, pair.question, pair.factor, levels);
        analyses.back().within = analyze_within_subject(
            matrix.complete, std::move(matrix.incomplete_participants));
        progress.pair_starts();
        analyses.back().models =
            fit_pair_models(table, pair.question, pair.factor, levels, request.models,
                            progress.hook(pair));
    }
    if (request.primary) {
        result.primary = *request.primary;
        result.primary_reason =
            std::string("as ") +
            (request.primary_source.empty() ? "requested" : request.primary_source) +
            " states";
        return result;
    }
    // Within only when the design is within: in every pair, (the stated share of) every
    // participant rated every level. The pair furthest from that decides and is named.
    if (!(request.within_share > 0.0 && request.within_share <= 1.0))
        throw InputError("within share must lie in (0, 1], got " +
                         std::to_string(request.within_share));
    const OneWayAnalysis* weakest = nullptr;
    double weakest_share = 2.0;
    bool all_within = true;
    for (const OneWayAnalysis& a : analyses) {
        const int total = pair_participants(a);
        const double share =
            total > 0 ? static_cast<double>(a.within.participants) / total : 0.0;
        // A share of 10 of 12 against 0.8333...: compare counts, not rounded ratios.
        const bool within =
            a.within.computed && static_cast<double>(a.within.participants) >=
                                     request.within_share * total - 1e-9;
        all_within = all_within && within;
        if (!weakest || share < weakest_share) {
            weakest = &a;
            weakest_share = share;
        }
    }
    result.primary = all_within ? Design::Within : Design::Between;
    const std::string wanted =
        request.within_share >= 1.0
            ? std::string("every participant")
            : "at least " +
                  std::to_string(static_cast<int>(request.within_share * 100.0 + 0.5)) +
                  "% of participants";
    const std::string counts = std::to_string(weakest->within.participants) + " of " +
                               std::to_string(pair_participants(*weakest)) +
                               " participants rated every level of " + weakest->question +
                               " ~ " + weakest->factor;
    if (all_within)
        result.primary_reason = "from the data: in every (question, factor) " + wanted +
                                " rated every level (fewest: " + counts + ")";
    else
        result.primary_reason = "from the data: only " + counts + ", and within needs " +
                                wanted + " (and at least 2) to have rated every level";
    return result;
}

int pair_participants(const OneWayAnalysis& pair) {
    return pair.within.participants +
           static_cast<int>(pair.within.excluded_participants.size());
}

std::size_t pair_ratings(const OneWayAnalysis& pair) {
    std::size_t n = 0;
    for (const Descriptives& d : pair.descriptives) n += d.n;
    return n;
}

}  // namespace lucent::analysis

#include "analysis/scaling/paired_comparison.h"

#include <algorithm>
#include <boost/math/distributions/binomial.hpp>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <map>
#include <numeric>

#include "analysis/data/long_table.h"
#include "analysis/report/format.h"

namespace lucent::analysis {
namespace {

std::optional<double> finite(double v) {
    return std::isfinite(v) ? std::optional<double>(v) : std::nullopt;
}

std::optional<double> chi2_upper(double statistic, double df) {
    if (!(df > 0) || !std::isfinite(statistic)) return std::nullopt;
    if (statistic <= 0) return 1.0;
    return boost::math::cdf(
        boost::math::complement(boost::math::chi_squared(df), statistic));
}

std::string short_text(double v) { return format_short(Statistic(v)); }
std::string p_text(std::optional<double> p) { return format_p_short(p); }

// "{a, b}" for a note.
std::string set_text(const std::vector<std::string>& names) {
    std::string text = "{";
    for (std::size_t i = 0; i < names.size(); ++i) text += (i ? ", " : "") + names[i];
    return text + "}";
}

// Reachability in a small directed graph (stimuli of one block: tens at most).
std::vector<std::vector<char>> closure(std::vector<std::vector<char>> reach) {
    const std::size_t n = reach.size();
    for (std::size_t i = 0; i < n; ++i) reach[i][i] = 1;
    for (std::size_t k = 0; k < n; ++k)
        for (std::size_t i = 0; i < n; ++i)
            if (reach[i][k])
                for (std::size_t j = 0; j < n; ++j)
                    if (reach[k][j]) reach[i][j] = 1;
    return reach;
}

// Stage 1: the rows of the GLM (ordered pairs as given, or unordered pairs with the
// lower index first), who beat whom how often, and each stimulus's wins and comparisons
// and the first-shown tally in `fit`; counts naming an unknown stimulus or not finite
// and >= 0 are refused.
struct Tally {
    std::vector<PairCount> rows;
    std::vector<std::vector<double>> beat;  // beat[s][t]: times s was chosen over t
};

Tally tally_counts(const PairedData& data, bool ordered, PairedFit& fit) {
    const std::size_t n = data.stimuli.size();
    Tally out;
    std::vector<PairCount>& rows = out.rows;
    std::map<std::pair<std::size_t, std::size_t>, std::size_t> row_of;
    std::vector<std::vector<double>>& beat = out.beat;
    beat.assign(n, std::vector<double>(n, 0.0));
    for (const PairCount& c : data.counts) {
        if (c.first >= n || c.second >= n)
            throw InputError("paired comparison: a pair names stimulus index " +
                             std::to_string(std::max(c.first, c.second)) + " of only " +
                             std::to_string(n));
        if (!(c.first_wins >= 0 && c.second_wins >= 0 && std::isfinite(c.first_wins) &&
              std::isfinite(c.second_wins)))
            throw InputError("paired comparison: win counts must be finite and >= 0");
        if (c.first == c.second) continue;  // a stimulus against itself says nothing
        fit.position.first_chosen += c.first_wins;
        fit.position.trials += c.first_wins + c.second_wins;
        beat[c.first][c.second] += c.first_wins;
        beat[c.second][c.first] += c.second_wins;
        PairCount row = c;
        if (!ordered && row.first > row.second) {
            std::swap(row.first, row.second);
            std::swap(row.first_wins, row.second_wins);
        }
        const auto [at, added] =
            row_of.emplace(std::pair(row.first, row.second), rows.size());
        if (added) {
            rows.push_back(row);
        } else {
            rows[at->second].first_wins += row.first_wins;
            rows[at->second].second_wins += row.second_wins;
        }
    }
    for (std::size_t s = 0; s < n; ++s)
        for (std::size_t t = 0; t < n; ++t) {
            fit.abilities[s].wins += beat[s][t];
            fit.abilities[s].comparisons += beat[s][t] + beat[t][s];
        }

    return out;
}

// Stage 2: the share of first-shown choices and its exact binomial test, with a note
// when it shows a position bias.
void test_position(PairedFit& fit) {
    // R's binom.test against 1/2: twice the smaller tail, at most 1.
    if (fit.position.trials > 0) {
        const double x = fit.position.first_chosen, t = fit.position.trials;
        fit.position.share = x / t;
        const boost::math::binomial_distribution<> b(t, 0.5);
        const double lower = boost::math::cdf(b, std::min(x, t - x));
        fit.position.p = std::min(1.0, 2.0 * lower);
        if (*fit.position.p < 0.05)
            fit.notes.push_back(
                "The first-shown stimulus was chosen in " + short_text(x) + " of " +
                short_text(t) + " comparisons (" + short_text(100.0 * x / t) +
                "%; exact binomial test against 50%: p = " + p_text(fit.position.p) +
                "): a position bias, e.g. always pressing the same key.");
    }
}

// Stage 3: the connected parts of the comparison graph, largest first (each has a
// scale of its own), each stimulus's group in `fit`, with notes for a stimulus never
// compared and for unconnected groups.
std::vector<std::vector<std::size_t>> connected_groups(
    const PairedData& data, const std::vector<std::vector<double>>& beat,
    PairedFit& fit) {
    const std::size_t n = data.stimuli.size();
    std::vector<std::vector<char>> linked(n, std::vector<char>(n, 0));
    for (std::size_t s = 0; s < n; ++s)
        for (std::size_t t = 0; t < n; ++t) linked[s][t] = beat[s][t] + beat[t][s] > 0;
    const auto connected = closure(linked);
    std::vector<std::vector<std::size_t>> groups;
    std::vector<int> group_of(n, -1);
    for (std::size_t s = 0; s < n; ++s) {
        if (group_of[s] >= 0 || fit.abilities[s].comparisons == 0) continue;
        groups.emplace_back();
        for (std::size_t t = 0; t < n; ++t)
            if (connected[s][t]) {
                group_of[t] = static_cast<int>(groups.size() - 1);
                groups.back().push_back(t);
            }
    }
    // Largest first; a tie keeps the order of the stimuli.
    std::stable_sort(groups.begin(), groups.end(),
                     [](const auto& a, const auto& b) { return a.size() > b.size(); });
    for (std::size_t g = 0; g < groups.size(); ++g)
        for (std::size_t s : groups[g]) {
            group_of[s] = static_cast<int>(g);
            fit.abilities[s].group = g;
        }
    fit.groups = static_cast<int>(groups.size());
    for (std::size_t s = 0; s < n; ++s)
        if (fit.abilities[s].comparisons == 0)
            fit.notes.push_back(data.stimuli[s] +
                                " was never compared with another stimulus: it has no "
                                "ability.");
    if (groups.size() > 1) {
        std::string text = "The comparisons fall into " + std::to_string(groups.size()) +
                           " unconnected groups: ";
        for (std::size_t g = 0; g < groups.size(); ++g) {
            std::vector<std::string> names;
            for (std::size_t s : groups[g]) names.push_back(data.stimuli[s]);
            text += (g == 0                   ? ""
                     : g + 1 == groups.size() ? " and "
                                              : ", ") +
                    set_text(names);
        }
        fit.notes.push_back(
            text +
            "; there is no common scale: abilities are scaled within each "
            "group, each with its own reference at 0, and compare only "
            "within it.");
    }
    return groups;
}

}  // namespace

PairedFit fit_paired_comparison(const PairedData& data, const PairedOptions& options) {
    const std::size_t n = data.stimuli.size();
    PairedFit fit;
    fit.model = options.link == BinomialLink::logit ? "Bradley-Terry (logit)"
                                                    : "Thurstone Case V (probit)";
    fit.abilities.resize(n);
    for (std::size_t s = 0; s < n; ++s) fit.abilities[s].stimulus = data.stimuli[s];

    const bool ordered = options.screen_order_rows || options.order_effect;
    const Tally tally = tally_counts(data, ordered, fit);
    const std::vector<PairCount>& rows = tally.rows;
    const std::vector<std::vector<double>>& beat = tally.beat;
    test_position(fit);
    const std::vector<std::vector<std::size_t>> groups =
        connected_groups(data, beat, fit);
    std::vector<std::vector<char>> wins(n, std::vector<char>(n, 0));
    for (std::size_t s = 0; s < n; ++s)
        for (std::size_t t = 0; t < n; ++t) wins[s][t] = beat[s][t] > 0;

    // Within a group the maximum likelihood is finite only where every stimulus beat,
    // and lost to, the others through some chain of comparisons (the win graph strongly
    // connected; Zermelo 1929, Ford 1957). The largest strongly connected part is
    // scaled; the stimuli above it won every comparison linking them to it, those below
    // lost every one: their abilities run to infinity and are reported in words.
    const auto reach = closure(wins);
    std::vector<char> scaled(n, 0);
    std::vector<std::size_t> references;
    for (std::size_t g = 0; g < groups.size(); ++g) {
        std::vector<std::size_t> core;
        for (std::size_t s : groups[g]) {
            std::vector<std::size_t> part;
            for (std::size_t t : groups[g])
                if (reach[s][t] && reach[t][s]) part.push_back(t);
            if (part.size() > core.size()) core = part;
        }
        if (core.size() < 2) core.clear();
        for (std::size_t s : core) scaled[s] = 1;
        std::vector<std::string> above, below;
        for (std::size_t s : groups[g]) {
            if (scaled[s]) continue;
            bool up;
            if (!core.empty()) {
                up = reach[s][core[0]];  // s beat the scaled part through some chain
            } else {
                up = 2 * fit.abilities[s].wins >= fit.abilities[s].comparisons;
            }
            fit.abilities[s].unbounded = up ? 1 : -1;
            (up ? above : below).push_back(data.stimuli[s]);
        }
        if (core.empty() && !groups[g].empty()) {
            std::vector<std::size_t> by_wins = groups[g];
            std::stable_sort(
                by_wins.begin(), by_wins.end(), [&](std::size_t a, std::size_t b) {
                    return fit.abilities[a].wins / fit.abilities[a].comparisons >
                           fit.abilities[b].wins / fit.abilities[b].comparisons;
                });
            std::vector<std::string> names;
            for (std::size_t s : by_wins) names.push_back(data.stimuli[s]);
            fit.notes.push_back(
                "Every comparison among " + set_text(names) +
                " went the same way as an ordering of them (highest first as listed): no "
                "stimulus both won and lost against the others, so no finite scale "
                "exists; "
                "only the order is known.");
            continue;
        }
        const std::size_t ref = [&] {
            for (std::size_t s : core)
                if (data.stimuli[s] == options.reference) return s;
            return core.front();
        }();
        references.push_back(ref);
        (void)above;
        (void)below;
    }
    if (!options.reference.empty()) {
        const auto it =
            std::find(data.stimuli.begin(), data.stimuli.end(), options.reference);
        if (it == data.stimuli.end())
            throw InputError("paired comparison: the reference '" + options.reference +
                             "' is not one of the stimuli compared");
        const std::size_t r = static_cast<std::size_t>(it - data.stimuli.begin());
        if (!scaled[r] && fit.abilities[r].comparisons > 0)
            fit.notes.push_back("The reference " + options.reference +
                                " has an unbounded ability, so " +
                                (references.empty() ? std::string("no stimulus")
                                                    : data.stimuli[references.front()]) +
                                " is at 0 instead.");
    }
    for (std::size_t r : references) fit.abilities[r].reference = true;

    // The GLM over the rows between scaled stimuli of one group.
    std::vector<int> column(n, -1);
    int columns = 0;
    for (std::size_t s = 0; s < n; ++s)
        if (scaled[s] && !fit.abilities[s].reference) column[s] = columns++;
    const int order_column = options.order_effect ? columns++ : -1;
    std::vector<const PairCount*> used;
    for (const PairCount& r : rows)
        if (scaled[r.first] && scaled[r.second] && r.first_wins + r.second_wins > 0)
            used.push_back(&r);
    if (!references.empty() && !used.empty() && columns > 0) {
        BinomialData glm;
        glm.x = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(used.size()), columns);
        glm.successes.resize(static_cast<Eigen::Index>(used.size()));
        glm.trials.resize(static_cast<Eigen::Index>(used.size()));
        for (std::size_t i = 0; i < used.size(); ++i) {
            const auto r = static_cast<Eigen::Index>(i);
            if (column[used[i]->first] >= 0) glm.x(r, column[used[i]->first]) = 1.0;
            if (column[used[i]->second] >= 0) glm.x(r, column[used[i]->second]) = -1.0;
            if (order_column >= 0) glm.x(r, order_column) = 1.0;
            glm.successes[r] = used[i]->first_wins;
            glm.trials[r] = used[i]->first_wins + used[i]->second_wins;
        }
        const BinomialFit g = fit_binomial_glm(glm, options.link);
        fit.converged = g.converged && !g.separation;
        fit.rows = g.observations;
        fit.parameters = g.parameters;
        fit.df_residual = g.df_residual;
        const bool usable = !g.rank_deficient && g.coefficients.allFinite();
        for (std::size_t s = 0; s < n; ++s) {
            if (fit.abilities[s].reference) {
                fit.abilities[s].ability = 0.0;
                fit.abilities[s].se = 0.0;
            } else if (column[s] >= 0 && usable) {
                fit.abilities[s].ability = finite(g.coefficients[column[s]]);
                fit.abilities[s].se = finite(g.standard_errors[column[s]]);
            }
        }
        if (order_column >= 0 && usable) {
            fit.order_effect = finite(g.coefficients[order_column]);
            fit.order_effect_se = finite(g.standard_errors[order_column]);
        }
        fit.deviance = finite(g.deviance);
        fit.null_deviance = finite(g.null_deviance);
        fit.aic = finite(g.aic);
        fit.log_likelihood = finite(g.log_likelihood);
        if (fit.deviance) fit.fit_p = chi2_upper(*fit.deviance, fit.df_residual);
        if (fit.deviance && fit.null_deviance) {
            fit.lr_chi2 = std::max(0.0, *fit.null_deviance - *fit.deviance);
            fit.lr_p = chi2_upper(*fit.lr_chi2, fit.parameters);
        }
        if (g.separation || !g.converged)
            fit.notes.push_back(
                "The fit did not settle (probabilities at 0 or 1): the "
                "abilities are not reliable.");
        if (g.rank_deficient)
            fit.notes.push_back(
                "The comparisons do not identify every ability (the "
                "design is singular); none is reported.");
    }

    // The unbounded stimuli in words, beside the finite range.
    double highest = 0.0, lowest = 0.0;
    for (const StimulusAbility& a : fit.abilities)
        if (a.ability) {
            highest = std::max(highest, *a.ability);
            lowest = std::min(lowest, *a.ability);
        }
    for (const StimulusAbility& a : fit.abilities) {
        if (a.unbounded == 0 || a.comparisons == 0) continue;
        const bool all = a.unbounded > 0 ? a.wins == a.comparisons : a.wins == 0;
        std::string text = a.stimulus + (a.unbounded > 0 ? " won " : " lost ");
        text += all ? "every comparison (" + short_text(a.comparisons) + " of " +
                          short_text(a.comparisons) + ")"
                    : "every comparison linking it to the scaled stimuli";
        text += ": its ability is unbounded";
        if (!references.empty())
            text += a.unbounded > 0 ? " (reported as > " + short_text(highest) + ")"
                                    : " (reported as < " + short_text(lowest) + ")";
        fit.notes.push_back(text + ".");
    }

    // With unbounded abilities the test covers only the stimuli left in the fit: the
    // others already won or lost every comparison, which is no chance.
    const bool any_unbounded =
        std::any_of(fit.abilities.begin(), fit.abilities.end(),
                    [](const StimulusAbility& a) { return a.unbounded != 0; });
    if (fit.lr_p && *fit.lr_p >= 0.05 && !any_unbounded)
        fit.notes.push_back(
            "The abilities do not differ from 0 (the all-equal model): likelihood-ratio "
            "chi-square = " +
            short_text(*fit.lr_chi2) + " on " + std::to_string(fit.parameters) +
            " df, p = " + p_text(fit.lr_p) + "; the choices are consistent with chance.");
    if (fit.fit_p && *fit.fit_p < 0.05)
        fit.notes.push_back(
            "The model fits poorly: deviance " + short_text(*fit.deviance) + " on " +
            std::to_string(fit.df_residual) + " df, p = " + p_text(fit.fit_p) +
            ": the choices are not explained by one ability per stimulus.");
    return fit;
}

std::vector<std::string> series_order(const std::vector<const ChoiceRow*>& rows,
                                      const std::vector<std::string>& order) {
    std::vector<std::string> seen;
    std::map<std::string, std::optional<double>> value;
    for (const ChoiceRow* row : rows)
        for (int k = 0; k < shown_count(row->task); ++k) {
            const auto [it, added] = value.emplace(row->shown[k], row->value[k]);
            if (added)
                seen.push_back(row->shown[k]);
            else if (row->value[k] && it->second && *row->value[k] != *it->second)
                throw InputError("line " + std::to_string(row->source_line) +
                                 ": stimulus " + row->shown[k] + " has series value " +
                                 format_full(row->value[k]) + " here and " +
                                 format_full(it->second) +
                                 " before: one stimulus, one value");
        }
    if (!order.empty()) {
        std::vector<std::string> result;
        for (const std::string& s : order)
            if (value.count(s)) result.push_back(s);
        for (const std::string& s : seen)
            if (std::find(order.begin(), order.end(), s) == order.end())
                result.push_back(s);
        return result;
    }
    const bool all_values =
        std::all_of(seen.begin(), seen.end(),
                    [&](const std::string& s) { return value[s].has_value(); });
    if (all_values)
        std::stable_sort(seen.begin(), seen.end(),
                         [&](const std::string& a, const std::string& b) {
                             return *value[a] < *value[b];
                         });
    return seen;
}

PairedData paired_data(const std::vector<const ChoiceRow*>& rows,
                       const std::vector<std::string>& stimuli) {
    PairedData data;
    data.stimuli = stimuli;
    std::map<std::string, std::size_t> index;
    for (std::size_t s = 0; s < stimuli.size(); ++s) index[stimuli[s]] = s;
    std::map<std::pair<std::size_t, std::size_t>, std::size_t> row_of;
    for (const ChoiceRow* row : rows) {
        if (row->task != ChoiceTask::pair || row->is_catch) continue;
        const auto a = index.find(row->shown[0]), b = index.find(row->shown[1]);
        if (a == index.end() || b == index.end()) continue;
        const auto [at, added] =
            row_of.emplace(std::pair(a->second, b->second), data.counts.size());
        if (added) data.counts.push_back({a->second, b->second, 0, 0});
        PairCount& c = data.counts[at->second];
        (row->choice == 1 ? c.first_wins : c.second_wins) += 1;
    }
    return data;
}

std::vector<ChoiceBlock> choice_blocks(
    const ChoiceTable& table, bool pairs,
    const std::map<std::string, std::vector<std::string>>& orders) {
    std::vector<ChoiceBlock> blocks;
    std::map<std::pair<std::string, std::string>, std::size_t> index;
    for (const ChoiceRow& row : table.rows) {
        if ((row.task == ChoiceTask::pair) != pairs) continue;
        const auto [it, added] =
            index.emplace(std::pair(row.block, row.question), blocks.size());
        if (added) blocks.push_back({row.block, row.question, {}, {}, {}, {}, 0, 0});
        blocks[it->second].rows.push_back(&row);
    }
    for (ChoiceBlock& block : blocks) {
        const auto order = orders.find(block.block);
        block.stimuli =
            series_order(block.rows, order == orders.end() ? std::vector<std::string>{}
                                                           : order->second);
        for (const std::string& s : block.stimuli) {
            std::optional<double> v;
            for (const ChoiceRow* row : block.rows)
                for (int k = 0; k < shown_count(row->task) && !v; ++k)
                    if (row->shown[k] == s) v = row->value[k];
            block.values.push_back(v);
        }
        std::map<std::string, std::size_t> of;
        for (const ChoiceRow* row : block.rows) {
            if (row->is_catch) {
                ++block.catch_trials;
                if (row->expected && *row->expected != row->choice) ++block.catch_failed;
                continue;
            }
            const auto [it, added] =
                of.emplace(row->participant, block.participants.size());
            if (added)
                block.participants.emplace_back(row->participant,
                                                std::vector<const ChoiceRow*>{});
            block.participants[it->second].second.push_back(row);
        }
    }
    return blocks;
}

std::vector<PairedBlockFits> fit_paired_blocks(
    const ChoiceTable& table, const PairedOptions& options,
    const std::map<std::string, std::vector<std::string>>& orders) {
    PairedOptions other = options;
    other.link =
        options.link == BinomialLink::logit ? BinomialLink::probit : BinomialLink::logit;
    std::vector<PairedBlockFits> result;
    for (const ChoiceBlock& b : choice_blocks(table, true, orders)) {
        PairedBlockFits block;
        block.block = b.block;
        block.question = b.question;
        block.stimuli = b.stimuli;
        block.values = b.values;
        block.catch_trials = b.catch_trials;
        block.catch_failed = b.catch_failed;
        const PairedData pooled = paired_data(b.rows, b.stimuli);
        block.pooled = fit_paired_comparison(pooled, options);
        block.pooled_other_link = fit_paired_comparison(pooled, other);
        for (const auto& [who, rows] : b.participants)
            block.participants.emplace_back(
                who, fit_paired_comparison(paired_data(rows, b.stimuli), options));
        result.push_back(std::move(block));
    }
    return result;
}

}  // namespace lucent::analysis

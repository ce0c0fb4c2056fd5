#include "analysis/mixed/rating_models.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include "analysis/models/rating_model.h"
#include "common/number_text.h"

namespace lucent::analysis {
namespace {

PairFrame pair_frame(const LongTable& table, const std::string& question,
                     const std::string& factor, const std::vector<std::string>& levels) {
    PairFrame pair;
    std::vector<std::string> rating_text, level, participant, stimulus;
    std::set<std::string> wanted(levels.begin(), levels.end()), seen;
    for (const RatingRow& row : table.rows) {
        if (row.question != question || row.factor != factor || !row.rating) continue;
        if (!wanted.count(row.level.str())) continue;
        const double value = table.origin + *row.rating;
        pair.ratings.push_back(value);
        rating_text.push_back(common::shortest_text(value));
        level.push_back(row.level.str());
        participant.push_back(row.participant.str());
        stimulus.push_back(row.stimulus.str());
        seen.insert(row.level.str());
        pair.participants.insert(row.participant.str());
        pair.stimuli.insert(row.stimulus.str());
    }
    for (const auto& l : levels)
        if (seen.count(l)) pair.levels.push_back(l);
    pair.frame.set("rating", std::move(rating_text));
    pair.frame.set("level", std::move(level));
    pair.frame.set("participant", std::move(participant));
    pair.frame.set("stimulus", std::move(stimulus));
    return pair;
}

RandomStructure random_structure(const PairFrame& pair) {
    RandomStructure structure;
    if (pair.participants.size() < 2) {
        structure.participant = false;
        structure.notes.push_back(
            "One participant: there is no spread between participants to estimate, so "
            "the participant term is left out.");
    }
    std::map<std::string, std::set<std::string>> stimuli_of_level;
    const auto& level = pair.frame.text("level");
    const auto& stimulus = pair.frame.text("stimulus");
    for (std::size_t i = 0; i < level.size(); ++i)
        stimuli_of_level[level[i]].insert(stimulus[i]);
    const bool one_per_level =
        std::all_of(stimuli_of_level.begin(), stimuli_of_level.end(),
                    [](const auto& entry) { return entry.second.size() == 1; });
    if (pair.stimuli.size() < 2) {
        structure.stimulus = false;
        structure.notes.push_back("One stimulus: the stimulus term is left out.");
    } else if (one_per_level) {
        structure.stimulus = false;
        structure.notes.push_back(
            "One stimulus per level: stimulus and level are confounded, so the stimulus "
            "term is left out and the level effects include the pictures' own "
            "differences (show several pictures per level to separate them).");
    }
    return structure;
}

}  // namespace

std::string formula(const RandomStructure& structure) {
    std::string text = "rating ~ level";
    if (structure.participant) text += " + (1 | participant)";
    if (structure.stimulus) text += " + (1 | stimulus)";
    return text;
}

RatingModelFit empty_fit(const std::string& model, const PairFrame& pair,
                         const RandomStructure& structure) {
    RatingModelFit fit;
    fit.model = model;
    fit.formula = formula(structure);
    fit.observations = int(pair.ratings.size());
    fit.participants = int(pair.participants.size());
    fit.stimuli = int(pair.stimuli.size());
    fit.levels = pair.levels;
    fit.reference_level = pair.levels.empty() ? "" : pair.levels.front();
    fit.notes = structure.notes;
    return fit;
}

Statistic finite(double value) {
    return std::isfinite(value) ? Statistic(value) : std::nullopt;
}

const RatingModelFit* PairModels::of(std::string_view model) const {
    for (const RatingModelFit& fit : fits)
        if (fit.model == model) return &fit;
    return nullptr;
}

bool ModelChoice::runs(const std::string& model) const {
    return model == kOneWayTests
               ? anova
               : std::find(mixed.begin(), mixed.end(), model) != mixed.end();
}

std::string parse_rating_model(const std::string& text, const std::string& what) {
    if (text == kOneWayTests || find_rating_model(text)) return text;
    throw InputError(what + ": '" + text + "' is not one of " + rating_model_names());
}

ModelChoice parse_model_list(const std::string& list, const std::string& primary) {
    ModelChoice choice;
    choice.anova = false;
    std::vector<std::string> listed;
    std::size_t start = 0;
    while (start <= list.size()) {
        const std::size_t comma = std::min(list.find(',', start), list.size());
        listed.push_back(
            parse_rating_model(list.substr(start, comma - start), "--model"));
        start = comma + 1;
    }
    choice.anova = std::find(listed.begin(), listed.end(), kOneWayTests) != listed.end();
    choice.mixed.clear();
    for (const RatingModelSpec* model : rating_models())  // registry order
        if (std::find(listed.begin(), listed.end(), model->name) != listed.end())
            choice.mixed.push_back(model->name);
    choice.primary = choice.runs(primary) ? primary : listed.front();
    return choice;
}

PairModels fit_pair_models(const LongTable& table, const std::string& question,
                           const std::string& factor,
                           const std::vector<std::string>& levels,
                           const ModelChoice& choice, const ModelFitHook& on_fit) {
    PairModels models;
    if (choice.mixed.empty()) return models;
    const PairFrame pair = pair_frame(table, question, factor, levels);
    RandomStructure structure = random_structure(pair);
    std::map<std::string, int> ratings_per_level;
    for (const auto& level : pair.frame.text("level")) ++ratings_per_level[level];
    const bool one_rating_each =
        std::all_of(ratings_per_level.begin(), ratings_per_level.end(),
                    [](const auto& entry) { return entry.second < 2; });
    // Data no model can be fitted to: every model's record says why, and none is fitted.
    bool fit_none = true;
    if (pair.levels.size() >= 2 && one_rating_each)
        structure.notes.insert(
            structure.notes.begin(),
            "Needs at least 2 ratings in some level (each level has 1): "
            "a model with a parameter per level fits them exactly, so "
            "no model is fitted.");
    else if (pair.levels.size() < 2)
        structure.notes.insert(structure.notes.begin(),
                               std::to_string(pair.levels.size()) +
                                   " level with ratings: there is nothing to compare, so "
                                   "no model is fitted.");
    else
        fit_none = false;
    for (const std::string& name : choice.mixed) {
        const RatingModelSpec* model = find_rating_model(name);
        if (!model) throw InputError("model '" + name + "' is not registered");
        if (on_fit) on_fit(name, nullptr);
        models.fits.push_back(fit_none ? empty_fit(name, pair, structure)
                                       : model->fit(pair, structure, choice));
        if (on_fit) on_fit(name, &models.fits.back());
    }
    return models;
}

}  // namespace lucent::analysis

#include <algorithm>
#include <stdexcept>

#include "analysis/models/rating_model.h"

namespace lucent::analysis {

const RatingModelSpec& clmm_model();
const RatingModelSpec& lmm_model();

namespace {

std::vector<const RatingModelSpec*>& registered() {
    static std::vector<const RatingModelSpec*> models = {
        &clmm_model(),
        &lmm_model(),
    };
    return models;
}

}  // namespace

const std::vector<const RatingModelSpec*>& rating_models() { return registered(); }

const RatingModelSpec* find_rating_model(std::string_view name) {
    for (const RatingModelSpec* model : registered())
        if (model->name == name) return model;
    return nullptr;
}

std::string rating_model_names() {
    std::string names = kOneWayTests;
    for (const RatingModelSpec* model : registered()) names += ", " + model->name;
    return names;
}

std::string rating_model_help() {
    std::string text = std::string(kOneWayTests) + " (the one-way tests)";
    for (const RatingModelSpec* model : registered()) text += ", " + model->help;
    return text;
}

RatingModelRegistration::RatingModelRegistration(const RatingModelSpec& model)
    : model_(&model) {
    if (model.name == kOneWayTests || find_rating_model(model.name))
        throw std::logic_error("rating model '" + model.name + "' is registered already");
    registered().push_back(model_);
}

RatingModelRegistration::~RatingModelRegistration() { std::erase(registered(), model_); }

}  // namespace lucent::analysis

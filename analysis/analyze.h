#pragma once
// The analysis entry point: a long table of ratings in (from the CSV reader, the study
// database reader or the simulator), one analysis per (question, factor) pair out.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "analysis/data/long_table.h"
#include "analysis/mixed/rating_models.h"
#include "analysis/stats/one_way_analysis.h"

namespace lucent::analysis {

// The progress of one mixed-model fit (lucent analyze shows it on stderr): called before
// each fit (`done` false) and after it.
struct ModelFitProgress {
    std::string model;         // its registered name
    int index = 0, total = 0;  // this fit (from 1) of every mixed-model fit of the run
    std::string question, factor;
    std::size_t ratings = 0;  // the pair's ratings, which a fit's time grows with
    bool done = false;
    bool fitted = false;  // done: the model was fitted (else its notes say why not)
    // Done: this fit's seconds, the seconds since the first fit began, and the seconds
    // the fits left should take: each one's ratings at the seconds per rating its model
    // took so far (all the fits so far', before its model has one).
    double seconds = 0.0, elapsed = 0.0, left = 0.0;
};

struct AnalysisRequest {
    double alpha = 0.10;   // the thesis's level; Tukey intervals at 1 - alpha
    std::string question;  // only this question ("" = all)
    std::string factor;    // only this factor ("" = all)
    // Called before each pair is analyzed (progress on long runs); may be empty.
    std::function<void(const std::string& question, const std::string& factor,
                       std::size_t levels)>
        on_pair;
    // The primary design; empty: chosen from the data (within_share below).
    std::optional<Design> primary;
    // Who set `primary`, for the report ("--design", "the protocol's [analysis] plan").
    std::string primary_source;
    // With no `primary`: within only when, in every (question, factor) pair, at least
    // this share of the pair's participants rated every level (1: every participant, a
    // truly within-subject design) and at least two did; otherwise between.
    double within_share = 1.0;
    // The analyses to run besides the one-way ones, and which leads the report.
    ModelChoice models;
    // Called before and after each mixed-model fit (progress on long runs); may be empty.
    std::function<void(const ModelFitProgress&)> on_fit;
};

struct AnalysisResult {
    std::vector<OneWayAnalysis> pairs;
    Design primary = Design::Between;  // the request's, or the one the data allow
    std::string primary_reason;        // one sentence: why this design leads the report
};

// The participants of a pair: those with a rating at some level (complete or not).
int pair_participants(const OneWayAnalysis& pair);
// The ratings the pair's between-subject tests use.
std::size_t pair_ratings(const OneWayAnalysis& pair);

// Throws InputError when no rating matches the filters.
AnalysisResult analyze_table(const LongTable& table, const AnalysisRequest& request);

}  // namespace lucent::analysis

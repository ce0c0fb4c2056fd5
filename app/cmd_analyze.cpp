// lucent analyze: one-way ANOVA, Tukey HSD, Kruskal-Wallis and Welch reports with plots
// from a study database or a long CSV of ratings
// (participant,stimulus,factor,level,question,rating); and the perceptual scales of
// forced choices (Bradley-Terry, Thurstone, MLDS) from a study database or a choices CSV;
// and matches and thresholds of adjust and staircase blocks from a study database.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "analysis/analyze.h"
#include "analysis/data/long_table.h"
#include "analysis/matching/matching_report.h"
#include "analysis/models/rating_model.h"
#include "analysis/report/report.h"
#include "analysis/scaling/mlds.h"
#include "analysis/scaling/paired_comparison.h"
#include "analysis/scaling/scaling_report.h"
#include "analysis/stats/one_way_analysis.h"
#include "app/commands.h"
#include "app/study_input.h"

namespace lucent::app {
namespace {

ThumbnailMaker thumbnail_maker = nullptr;

struct AnalyzeArgs {
    std::string input, out_dir, factor, question, formats = "md,csv,html", scale = "1..7";
    std::string design;  // "", "between" or "within"
    std::string images;  // folder of rendered stimuli for thumbnails
    std::string models = "anova,clmm", primary_model;
    bool random_slopes = false;
    double alpha = 0.10;
    double within_share = 1.0;
    int bootstrap = 200, six_point = 200;  // MLDS: bootstrap samples, six-point data sets
    std::string psychometric = "gaussian";  // thresholds: "gaussian" or "weibull"
    uint64_t seed = 1;
};

// The forced choices' scales (paired comparisons, MLDS), when the input has any.
void add_scaling_section(const AnalyzeArgs& args, const AnalysisInput& input,
                         analysis::ReportOptions& options) {
    using namespace lucent::analysis;
    const ChoiceTable& choices = input.choices;
    const auto& orders = input.choice_orders;
    if (choices.rows.empty()) return;
    std::cerr << "lucent analyze: scaling " << choices.rows.size()
              << " forced choices (paired comparisons, MLDS)\n";
    const std::vector<PairedBlockFits> paired = fit_paired_blocks(choices, {}, orders);
    MldsOptions mlds_options;
    mlds_options.bootstrap = args.bootstrap;
    mlds_options.seed = args.seed;
    mlds_options.six_point_simulations = args.six_point;
    const std::vector<MldsBlockFits> mlds =
        fit_mlds_blocks(choices, mlds_options, orders);
    std::map<std::string, std::filesystem::path> pictures;
    if (!args.images.empty())
        for (const ChoiceRow& row : choices.rows)
            for (int k = 0; k < shown_count(row.task); ++k) {
                const std::filesystem::path png =
                    std::filesystem::path(args.images) / (row.shown[k] + ".png");
                std::error_code error;
                if (!pictures.count(row.shown[k]) &&
                    std::filesystem::is_regular_file(png, error))
                    pictures[row.shown[k]] = png;
            }
    ScalingSection section = scaling_section(paired, mlds, pictures);
    options.extra_blocks = std::move(section.blocks);
    options.extra_files = std::move(section.files);
}

// Matching and thresholds (adjust and staircase blocks), when a study database has any;
// appended after the scales.
void add_matching_section(const AnalyzeArgs& args, const AnalysisInput& input,
                          analysis::ReportOptions& options) {
    using namespace lucent::analysis;
    const MatchingTable& table = input.matching;
    if (table.matches.empty() && table.staircases.empty()) return;
    std::cerr << "lucent analyze: " << table.matches.size() << " matches, "
              << table.staircases.size() << " staircase trials\n";
    for (const std::string& p : table.excluded_participants)
        std::cerr << "lucent analyze: excluded participant " << p
                  << " from the matches and thresholds\n";
    const study::Protocol* protocol = table.protocol ? &*table.protocol : nullptr;
    if (!protocol)
        options.input_notes.push_back(
            std::string(input.from_study ? "The stored protocol could not be read"
                                         : "A table of observations holds no protocol") +
            ": the matches have no target values and the staircases are taken as pairs "
            "(guess rate 1/2), not replayed.");
    ThresholdOptions threshold_options;
    threshold_options.family = args.psychometric == "weibull"
                                   ? PsychometricFamily::weibull
                                   : PsychometricFamily::cumulative_gaussian;
    threshold_options.bootstrap = args.bootstrap;
    threshold_options.seed = args.seed;
    MatchingSection section = matching_section(
        analyse_matches(table.matches, protocol),
        analyse_thresholds(table.staircases, protocol, threshold_options));
    options.extra_blocks.insert(options.extra_blocks.end(), section.blocks.begin(),
                                section.blocks.end());
    options.extra_files.insert(options.extra_files.end(), section.files.begin(),
                               section.files.end());
}

// "0.4 s", "12 s", "3 min 05 s".
std::string duration_text(double seconds) {
    char text[32];
    if (seconds < 10.0)
        std::snprintf(text, sizeof text, "%.1f s", seconds);
    else if (seconds < 120.0)
        std::snprintf(text, sizeof text, "%.0f s", seconds);
    else {
        const long whole = std::lround(seconds);
        std::snprintf(text, sizeof text, "%ld min %02ld s", whole / 60, whole % 60);
    }
    return text;
}

// The mixed models are the slow part of a large study (1e6 ratings: over a minute, the
// one-way tests a second): one stderr line per fit, begun before it and ended after it
// with its time, the time so far and an estimate of the time left. Like lucent render's
// batch progress, on stderr only, so stdout keeps the report's file names.
void show_fit_progress(const analysis::ModelFitProgress& p) {
    if (!p.done) {
        std::cerr << "lucent analyze: " << p.model << " " << p.index << "/" << p.total
                  << ": question " << p.question << ", factor " << p.factor << " ("
                  << p.ratings << " ratings) ..." << std::flush;
        return;
    }
    std::cerr << " " << (p.fitted ? "" : "not fitted, ") << duration_text(p.seconds)
              << "; " << duration_text(p.elapsed) << " elapsed, ~"
              << duration_text(p.left) << " left\n"
              << std::flush;
}

int run_analyze(const AnalyzeArgs& args) {
    using namespace lucent::analysis;
    try {
        if (!(args.alpha > 0.0 && args.alpha < 1.0))
            throw InputError("--alpha must lie strictly between 0 and 1");
        ReportOptions options;
        parse_formats(args.formats, options);
        options.alpha = args.alpha;
        options.source = args.input;
        options.inputs = {args.input};  // a report file never replaces the input
        if (!(args.within_share > 0.0 && args.within_share <= 1.0))
            throw InputError("--within-share must lie in (0, 1]");
        options.scale = parse_scale(args.scale);
        // A choices CSV holds no ratings; a study database may hold every kind.
        const AnalysisInput input = read_analysis_input(args.input, options.scale);
        const LongTable& table = input.ratings;
        const std::optional<Design>& plan_design = input.plan_design;
        const std::string& plan_model = input.plan_model;
        options.input_notes = input.notes;
        options.question_scales = input.question_scales;
        add_scaling_section(args, input, options);
        add_matching_section(args, input, options);
        if (table.rows.empty() && options.extra_blocks.empty())
            throw InputError(args.input +
                             ": holds no ratings, no forced choices, no matches and no "
                             "staircase trials");
        std::string primary_model = kOneWayTests;
        std::string primary_model_source;
        if (!args.primary_model.empty()) {
            primary_model = parse_rating_model(args.primary_model, "--primary-model");
            primary_model_source = "--primary-model " + args.primary_model;
        } else if (!plan_model.empty()) {
            primary_model =
                parse_rating_model(plan_model, "the protocol's primary_model");
            primary_model_source = "the protocol's [analysis] primary_model";
        }
        if (!args.images.empty()) {
            options.level_images = level_images_from_directory(table, args.images);
            if (thumbnail_maker) options.thumbnail_png = thumbnail_maker;
        }
        AnalysisRequest request{args.alpha, args.question, args.factor,
                                [](const std::string& question, const std::string& factor,
                                   std::size_t levels) {
                                    std::cerr << "analyzing " << question << " ~ "
                                              << factor << " (" << levels << " levels)\n";
                                }};
        request.on_fit = show_fit_progress;
        request.within_share = args.within_share;
        request.models = parse_model_list(args.models, primary_model);
        request.models.random_slopes = args.random_slopes;
        if (!args.primary_model.empty() && !request.models.runs(primary_model))
            throw InputError("--primary-model " + args.primary_model +
                             " is not among --model " + args.models);
        if (request.models.primary == primary_model)
            request.models.primary_source = primary_model_source;
        if (args.design == "within") request.primary = Design::Within;
        if (args.design == "between") request.primary = Design::Between;
        if (request.primary) request.primary_source = "--design " + args.design;
        if (!request.primary && plan_design) {
            request.primary = plan_design;
            request.primary_source = "the protocol's [analysis] primary_design";
        }
        if (table.rows.empty()) {  // no ratings: the scales, matches, thresholds are it
            for (const auto& path : write_report({}, args.out_dir, options))
                std::cout << path.string() << "\n";
            return kExitOk;
        }
        const AnalysisResult result = analyze_table(table, request);
        options.primary = result.primary;
        options.models = request.models;
        options.primary_reason = result.primary_reason;
        std::cerr << "lucent analyze: primary design " << design_name(result.primary)
                  << ", " << result.primary_reason << "\n";
        for (const auto& path : write_report(result.pairs, args.out_dir, options))
            std::cout << path.string() << "\n";
        return kExitOk;
    } catch (const InputError& e) {
        std::cerr << "lucent analyze: " << e.what() << "\n";
        return kExitUsage;
    }
}

}  // namespace

void set_analyze_thumbnail_maker(ThumbnailMaker maker) { thumbnail_maker = maker; }

void register_analyze(CLI::App& app, int& exit_code) {
    auto args = std::make_shared<AnalyzeArgs>();
    auto* cmd = app.add_subcommand(
        "analyze",
        "One-way ANOVA, Tukey HSD, Kruskal-Wallis and Welch, and ordinal and linear "
        "mixed models (participants and stimuli random) per (question, factor), with "
        "plots, from a study database or a long CSV of ratings; paired comparisons and "
        "MLDS scaled from a study database or a choices CSV");
    cmd->add_option("input", args->input,
                    "Study database, or long CSV: "
                    "participant,stimulus,factor,level,question,rating")
        ->required();
    cmd->add_option("--out", args->out_dir, "Directory for the report")->required();
    cmd->add_option("--alpha", args->alpha, "Significance level (Tukey CI at 1 - alpha)")
        ->capture_default_str();
    cmd->add_option("--factor", args->factor, "Analyze only this factor");
    cmd->add_option("--question", args->question, "Analyze only this question");
    cmd->add_option("--format", args->formats, "Comma-separated subset of md,csv,html")
        ->capture_default_str();
    cmd->add_option("--design", args->design,
                    "Primary design: between or within (default: the protocol's analysis "
                    "plan; for a CSV, within when every participant rated every level)")
        ->check(CLI::IsMember({"between", "within"}));
    cmd->add_option("--within-share", args->within_share,
                    "Without --design or a plan: within only when at least this share of "
                    "each (question, factor)'s participants rated every level")
        ->capture_default_str();
    cmd->add_option("--images", args->images,
                    "Folder of rendered stimuli (lucent render's output): each level's "
                    "picture is shown beside its descriptives, embedded in report.html");
    cmd->add_option("--model", args->models,
                    "Analyses to run: a comma-separated subset of " +
                        analysis::rating_model_help())
        ->capture_default_str();
    cmd->add_option("--primary-model", args->primary_model,
                    "The analysis that leads the report: one of " +
                        analysis::rating_model_names() +
                        " (default: the protocol's [analysis] primary_model; for a CSV, "
                        "anova)");
    cmd->add_flag("--random-slopes", args->random_slopes,
                  "lmm: random slopes for the level within participant, where the design "
                  "identifies them (the report says when it does not)");
    cmd->add_option("--scale", args->scale,
                    "Accepted ratings: MIN..MAX, or 'any' for any finite number")
        ->capture_default_str();
    cmd->add_option("--bootstrap", args->bootstrap,
                    "MLDS and thresholds: parametric bootstrap samples for the scale's "
                    "and the JNDs' intervals (0: none)")
        ->check(CLI::Range(0, 100000))
        ->capture_default_str();
    cmd->add_option("--six-point", args->six_point,
                    "MLDS: simulated data sets of the six-point test (0: no test)")
        ->check(CLI::Range(0, 100000))
        ->capture_default_str();
    cmd->add_option("--seed", args->seed,
                    "MLDS and thresholds: the bootstrap's and the test's seed")
        ->capture_default_str();
    cmd->add_option("--psychometric", args->psychometric,
                    "Thresholds: the psychometric function fitted to staircase trials, "
                    "gaussian (cumulative Gaussian) or weibull")
        ->check(CLI::IsMember({"gaussian", "weibull"}))
        ->capture_default_str();
    cmd->callback([args, &exit_code] { exit_code = run_analyze(*args); });
}

}  // namespace lucent::app

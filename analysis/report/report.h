#pragma once
// Writes the analysis report: Markdown and/or HTML (summary table in the layout of the
// thesis's Table 4.4, then per (question, factor): plot, descriptives, ANOVA, Tukey HSD,
// Kruskal-Wallis and Welch), machine-readable CSV tables, and one SVG plot per pair.
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "analysis/data/long_table.h"
#include "analysis/report/document.h"
#include "analysis/stats/one_way_analysis.h"

namespace lucent::analysis {

struct ReportOptions {
    double alpha =
        0.10;  // significance level (the thesis used 0.10); Tukey CI at 1 - alpha
    bool markdown = true, csv = true, html = true;
    std::string source;  // input description printed in the header
    // Files the report must never replace (its input): a report file that is one of
    // them, or any SQLite database, is refused before anything is written.
    std::vector<std::filesystem::path> inputs;
    Design primary = Design::Between;  // shown first in the summary and in each section
    // The analyses that ran (the one-way ones, the mixed models) and which leads: the
    // summary marks it "(primary)" and puts it first.
    ModelChoice models;
    std::string
        primary_reason;  // why it leads (AnalysisResult::primary_reason); may be empty
    // Paragraphs after the input line: what the input reader left out and why (sessions
    // not completed, failed catch trials, withdrawn).
    std::vector<std::string> input_notes;
    // The rating scale: the plots' y axis (ticks at integers); "any": the data's range.
    RatingScale scale;
    // A question's own scale where the input says it (a study database's protocol:
    // 1..points), in place of `scale` on its plots.
    std::map<std::string, RatingScale> question_scales;
    // A picture of each level's stimulus, shown beside its descriptives (HTML embeds the
    // PNG, so the report stays one file): (factor, level) -> (stimulus id, PNG path).
    std::map<std::pair<std::string, std::string>,
             std::pair<std::string, std::filesystem::path>>
        level_images;
    // Makes the PNG bytes of a small thumbnail of a picture file (throws when it cannot
    // be decoded). Unset: the file itself is embedded and the browser scales it.
    std::function<std::string(const std::filesystem::path&)> thumbnail_png;
    // Sections after the rating analyses (the forced choices' scales,
    // analysis/scaling/scaling_report.h) and their files (plots always, CSV with `csv`).
    // With no rating analyses they are the whole report.
    std::vector<Block> extra_blocks;
    ReportFiles extra_files;
};

// The picture of each (factor, level) from a folder of rendered stimuli (`lucent
// render`'s output): the first stimulus rated at that level that has
// `DIR/<stimulus>.png`. Throws InputError naming the folder when it is not one.
std::map<std::pair<std::string, std::string>,
         std::pair<std::string, std::filesystem::path>>
level_images_from_directory(const LongTable& table,
                            const std::filesystem::path& directory);

// "md,csv,html" (any subset, comma-separated); throws InputError naming a bad entry.
void parse_formats(const std::string& list, ReportOptions& options);

// Writes into `directory` (created if needed), each file to a temporary name first and
// renamed; returns the files written. Throws InputError (one line) on a refused file.
std::vector<std::filesystem::path> write_report(
    const std::vector<OneWayAnalysis>& analyses, const std::filesystem::path& directory,
    const ReportOptions& options);

// File-name-safe slug for plot names: letters, digits, '-', '_'.
std::string plot_file_name(const std::string& question, const std::string& factor);
// The per-factor figure (every question of the factor side by side).
std::string figure_file_name(const std::string& factor);

}  // namespace lucent::analysis

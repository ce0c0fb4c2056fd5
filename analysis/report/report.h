#pragma once
// Writes the analysis report: Markdown and/or HTML (summary table in the layout of the
// thesis's Table 4.4, then per (question, factor): plot, descriptives, ANOVA, Tukey HSD,
// Kruskal-Wallis and Welch), machine-readable CSV tables, and one SVG plot per pair.
#include <filesystem>
#include <string>
#include <vector>

#include "stats/one_way_analysis.h"

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
};

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

#include "analysis/report/report.h"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <sstream>

#include "analysis/data/long_table.h"
#include "analysis/models/rating_model.h"
#include "analysis/report/document.h"
#include "analysis/report/format.h"
#include "analysis/report/mixed_sections.h"
#include "analysis/report/rating_figures.h"
#include "common/csv.h"
#include "common/html/html_page.h"
#include "common/output_file.h"

namespace lucent::analysis {
namespace {

std::string md_cell(const std::string& s) {
    std::string out;
    for (char c : s) out += c == '|' ? std::string("\\|") : std::string(1, c);
    return out;
}

// "yes" / "no" at the report's alpha, the level the Tukey intervals are drawn at, so a
// pair's verdict always agrees with whether its interval excludes 0.
std::string significant_at(const Statistic& p, double alpha) {
    if (!p) return "undefined";
    return *p < alpha ? "yes" : "no";
}

std::string configuration(const OneWayAnalysis& a) {
    return a.question + " ~ " + a.factor;
}

// The within-subject test a summary shows: the repeated-measures F with the
// Greenhouse-Geisser p (the uncorrected p where epsilon is undefined, e.g. two levels).
Statistic within_summary_p(const WithinSubjectAnalysis& w) {
    return w.anova.p_gg ? w.anova.p_gg : w.anova.p;
}

// The y axis of `question`'s plots: its own scale where the input gave one, else the
// report's.
RatingScale scale_of(const ReportOptions& options, const std::string& question) {
    const auto own = options.question_scales.find(question);
    return own != options.question_scales.end() ? own->second : options.scale;
}

// One axis for several questions' panels: the widest of their scales.
RatingScale shared_scale(const ReportOptions& options,
                         const std::vector<QuestionPanel>& panels) {
    RatingScale shared = options.scale;
    for (std::size_t i = 0; i < panels.size(); ++i) {
        const RatingScale s = scale_of(options, panels[i].question);
        if (i == 0) shared = s;
        shared.any = shared.any || s.any;
        shared.min = std::min(shared.min, s.min);
        shared.max = std::max(shared.max, s.max);
    }
    return shared;
}

// Every participant who rated the pair, complete or not.
int participants_of(const OneWayAnalysis& a) {
    return a.within.participants +
           static_cast<int>(a.within.excluded_participants.size());
}

// Who a test used: the between-subject tests every rating of the pair; the
// within-subject tests the participants who rated every level.
std::string used_cell(const OneWayAnalysis& a, Design design) {
    std::size_t ratings = 0;
    for (const Descriptives& d : a.descriptives) ratings += d.n;
    const int total = participants_of(a);
    if (design == Design::Between)
        return std::to_string(total) +
               (total == 1 ? " participant, " : " participants, ") +
               std::to_string(ratings) + (ratings == 1 ? " rating" : " ratings");
    return std::to_string(a.within.participants) + " of " + std::to_string(total) +
           " participants complete";
}

// The summary's verdict: yes / no at alpha, or, where the test has no p-value, why not
// in words ("undefined: needs ..."), so a reader of the summary alone is not left with
// a bare "undefined".
std::string verdict_cell(const Statistic& p, double alpha, const std::string& why) {
    if (p || why.empty()) return significant_at(p, alpha);
    return "undefined: " + why;
}

// Why the between-subject ANOVA of a pair has no p-value.
std::string why_between_undefined(const AnovaResult& r) {
    if (r.groups >= 2 && r.df_within <= 0.0)
        return "needs at least 2 ratings in some level (each level has 1)";
    return r.note;
}

// Why the within-subject tests of a pair were not computed.
std::string why_within_not_computed(const OneWayAnalysis& a) {
    const std::size_t levels = a.descriptives.size() - a.empty_levels.size();
    if (a.within.participants < 2 && levels >= 2)
        return "needs at least 2 participants who rated every level (" +
               std::to_string(a.within.participants) + " did)";
    return a.within.note;
}

std::vector<std::string> summary_cells(const OneWayAnalysis& a, Design design,
                                       double alpha) {
    if (design == Design::Between)
        return {"one-way ANOVA", format_p_short(a.anova.p), format_short(a.anova.f),
                verdict_cell(a.anova.p, alpha, why_between_undefined(a.anova)),
                used_cell(a, design)};
    if (!a.within.computed)
        return {"repeated measures", "undefined", "undefined",
                verdict_cell({}, alpha, why_within_not_computed(a)),
                used_cell(a, design)};
    const Statistic p = within_summary_p(a.within);
    return {"repeated measures (G-G)", format_p_short(p), format_short(a.within.anova.f),
            verdict_cell(p, alpha, a.within.anova.note), used_cell(a, design)};
}

// Said under the summary when the analysis holds one participant (a first pilot, or
// scripts/run-default): why most of its tests are undefined.
constexpr const char* kOneParticipant =
    "One participant: a test that is undefined says why in its row. A test weighs the "
    "differences between levels against the spread between participants, or between "
    "ratings of one level, and one person rating each stimulus once leaves none. The "
    "descriptives and figures show this participant's ratings; the within-subject "
    "tests need two or more participants.";

std::string participants_note(const WithinSubjectAnalysis& w) {
    std::string text = std::to_string(w.participants) + " participants rated every level";
    if (!w.excluded_participants.empty()) {
        text += "; left out (a level missing): ";
        for (std::size_t i = 0; i < w.excluded_participants.size(); ++i)
            text += (i ? ", " : "") + w.excluded_participants[i];
    }
    return text;
}

std::vector<Block> within_subject_blocks(const OneWayAnalysis& a, double alpha) {
    const WithinSubjectAnalysis& w = a.within;
    std::vector<Block> doc;
    doc.push_back({Block::kHeading, "Within-subject tests", {}, {}, 3});
    if (!w.computed) {
        doc.push_back({Block::kParagraph, "Not computed: " + w.note + "."});
        return doc;
    }
    doc.push_back(
        {Block::kParagraph, participants_note(w) +
                                ". A participant's value at a level is the mean "
                                "of their ratings of that level's stimuli."});
    const RepeatedMeasuresAnova& r = w.anova;
    Table rm{{"source", "SS", "df", "MS", "F", "p", "p (G-G)", "p (H-F)"}, {}};
    rm.rows.push_back({a.factor, format_short(r.ss_effect), format_short(r.df_effect),
                       format_short(r.ss_effect / r.df_effect), format_short(r.f),
                       format_p_short(r.p), format_p_short(r.p_gg),
                       format_p_short(r.p_hf)});
    rm.rows.push_back({"participants", format_short(r.ss_participants),
                       format_short(static_cast<double>(r.participants - 1)), "", "", "",
                       "", ""});
    rm.rows.push_back(
        {"error (" + a.factor + " x participants)", format_short(r.ss_error),
         format_short(r.df_error),
         r.df_error > 0 ? format_short(r.ss_error / r.df_error) : "undefined", "", "", "",
         ""});
    doc.push_back({Block::kHeading, "Repeated-measures ANOVA", {}, {}, 4});
    doc.push_back({Block::kTable, "", rm});
    doc.push_back({Block::kParagraph,
                   "Mauchly's W = " + format_short(r.mauchly_w) +
                       ", p = " + format_p_short(r.mauchly_p) +
                       "; Greenhouse-Geisser epsilon = " + format_short(r.gg_epsilon) +
                       ", Huynh-Feldt epsilon = " + format_short(r.hf_epsilon) +
                       " (its p uses min(1, epsilon)); " + "partial eta squared = " +
                       format_short(r.partial_eta_sq) + ", generalized eta squared = " +
                       format_short(r.generalized_eta_sq) +
                       (r.note.empty() ? "" : ". Note: " + r.note)});
    const FriedmanResult& f = w.friedman;
    doc.push_back({Block::kParagraph,
                   "Friedman (tie-corrected): chi squared = " + format_short(f.chi_sq) +
                       ", df = " + format_short(f.df) + ", p = " + format_p_short(f.p) +
                       ", Kendall's W = " + format_short(f.kendall_w) +
                       (f.note.empty() ? "" : " (" + f.note + ")")});
    Table paired{{"level a", "level b", "diff (b - a)", "t", "df", "p", "p (Holm)",
                  "significant at alpha"},
                 {}};
    for (const PairedComparison& c : w.paired)
        paired.rows.push_back(
            {c.level_a, c.level_b, format_short(c.diff), format_short(c.t),
             format_short(c.df), format_p_short(c.p), format_p_short(c.p_holm),
             c.note.empty() ? significant_at(c.p_holm, alpha) : c.note});
    doc.push_back({Block::kHeading, "Paired t-tests, Holm-adjusted", {}, {}, 4});
    doc.push_back({Block::kTable, "", paired});
    return doc;
}

std::vector<Block> build_document(const std::vector<OneWayAnalysis>& analyses,
                                  const ReportOptions& options) {
    std::vector<Block> doc;
    doc.push_back({Block::kHeading, "Lucent analysis report", {}, {}, 1});
    if (analyses.empty()) {  // forced choices only: their scales are the report
        doc.push_back({Block::kParagraph, "Input: " + options.source + "."});
        for (const std::string& note : options.input_notes)
            doc.push_back({Block::kParagraph, note});
        doc.insert(doc.end(), options.extra_blocks.begin(), options.extra_blocks.end());
        return doc;
    }
    std::string analyses_run;
    if (options.models.anova) analyses_run += "One-way ANOVA per (question, factor); ";
    for (const RatingModelSpec* model : rating_models())
        if (options.models.runs(model->name)) analyses_run += model->ran;
    doc.push_back({Block::kParagraph,
                   "Input: " + options.source + ". " + analyses_run +
                       "alpha = " + format_short(options.alpha) +
                       ", Tukey HSD intervals at " + format_short(1.0 - options.alpha) +
                       " confidence, descriptive intervals and model effects at 95%."});
    for (const std::string& note : options.input_notes)
        doc.push_back({Block::kParagraph, note});
    // Summary in the layout of the thesis's Table 4.4: both designs of the one-way
    // ANOVA and each mixed model, the primary analysis first.
    const Design primary = options.primary;
    const Design secondary = primary == Design::Within ? Design::Between : Design::Within;
    const ModelChoice& models = options.models;
    Table summary{{"configuration", "analysis", "test", "p", "statistic",
                   "significant at alpha", "used"},
                  {}};
    for (const OneWayAnalysis& a : analyses) {
        std::vector<std::vector<std::string>> rows;
        if (models.anova)
            for (Design design : {primary, secondary}) {
                const bool leads = models.primary == kOneWayTests && design == primary;
                std::vector<std::string> row{
                    configuration(a),
                    std::string(design_name(design)) + (leads ? " (primary)" : "")};
                for (std::string& cell : summary_cells(a, design, options.alpha))
                    row.push_back(std::move(cell));
                rows.push_back(std::move(row));
            }
        for (const RatingModelSpec* model : rating_models()) {
            std::vector<std::string> cells =
                mixed_summary_cells(a, *model, options.alpha);
            if (cells.empty()) continue;
            const bool leads = models.primary == model->name;
            std::vector<std::string> row{configuration(a),
                                         model->name + (leads ? " (primary)" : "")};
            for (std::string& cell : cells) row.push_back(std::move(cell));
            if (leads)
                rows.insert(rows.begin(), std::move(row));
            else
                rows.push_back(std::move(row));
        }
        summary.rows.insert(summary.rows.end(), rows.begin(), rows.end());
    }
    doc.push_back({Block::kHeading, "Summary", {}, {}, 2});
    if (const RatingModelSpec* leading = find_rating_model(models.primary))
        doc.push_back({Block::kParagraph,
                       "Primary analysis: the " + leading->title +
                           (models.primary_source.empty()
                                ? std::string()
                                : ", as " + models.primary_source + " states") +
                           ", with participants and stimuli as random effects."});
    doc.push_back(
        {Block::kParagraph,
         std::string(models.primary == kOneWayTests ? "Primary design: "
                                                    : "Design of the one-way tests: ") +
             design_name(primary) +
             (primary == Design::Within
                  ? " (repeated-measures tests on the means of the participants "
                    "who rated every level)"
                  : " (levels compared as independent groups of ratings)") +
             (options.primary_reason.empty() ? "" : ", " + options.primary_reason) +
             ". Column \"used\": the participants and ratings each test used."});
    doc.push_back({Block::kTable, "", summary});
    int participants = 0;
    for (const OneWayAnalysis& a : analyses)
        participants = std::max(participants, participants_of(a));
    if (participants == 1) doc.push_back({Block::kParagraph, kOneParticipant});

    // One figure per factor, its questions side by side on one scale (thesis Fig. 4.5).
    std::vector<std::string> factors;
    for (const OneWayAnalysis& a : analyses)
        if (std::find(factors.begin(), factors.end(), a.factor) == factors.end())
            factors.push_back(a.factor);
    doc.push_back({Block::kHeading, "Figures by factor", {}, {}, 2});
    for (const std::string& factor : factors) {
        std::vector<QuestionPanel> panels;
        for (const OneWayAnalysis& a : analyses)
            if (a.factor == factor) panels.push_back({a.question, a.descriptives});
        Block figure{Block::kPlot, figure_file_name(factor), {}, {}};
        figure.svg = factor_figure_svg(factor, panels, shared_scale(options, panels));
        doc.push_back(figure);
    }

    for (const OneWayAnalysis& a : analyses) {
        doc.push_back({Block::kHeading, configuration(a), {}, {}, 2});
        Block plot{Block::kPlot, plot_file_name(a.question, a.factor), {}, {}};
        plot.svg = mean_ci_plot_svg(configuration(a), a.question, a.descriptives,
                                    a.factor, scale_of(options, a.question));
        doc.push_back(plot);
        Block thumbnails{Block::kImages, "", {}, {}};
        for (const Descriptives& d : a.descriptives) {
            const auto image = options.level_images.find({a.factor, d.level});
            if (image != options.level_images.end())
                thumbnails.images.push_back(
                    {a.factor + " " + d.level + " (" + image->second.first + ")",
                     image->second.second});
        }
        if (!thumbnails.images.empty()) doc.push_back(thumbnails);
        const std::vector<Block> mixed = mixed_model_blocks(a);
        const bool mixed_leads = models.primary != kOneWayTests;
        if (mixed_leads) doc.insert(doc.end(), mixed.begin(), mixed.end());
        const std::vector<Block> within = within_subject_blocks(a, options.alpha);
        if (models.anova && primary == Design::Within)
            doc.insert(doc.end(), within.begin(), within.end());

        Table desc{{"level", "n", "mean", "SD", "SE", "median", "95% CI"}, {}};
        for (const Descriptives& d : a.descriptives)
            desc.rows.push_back(
                {d.level, std::to_string(d.n), format_short(d.mean), format_short(d.sd),
                 format_short(d.se), format_short(d.median),
                 d.ci_low
                     ? "[" + format_short(d.ci_low) + ", " + format_short(d.ci_high) + "]"
                     : "undefined"});
        doc.push_back({Block::kHeading, "Descriptives", {}, {}, 3});
        doc.push_back({Block::kTable, "", desc});

        if (models.anova) {
            const AnovaResult& an = a.anova;
            Table anova{{"source", "SS", "df", "MS", "F", "p"}, {}};
            anova.rows.push_back(
                {"between", format_short(an.ss_between), format_short(an.df_between),
                 format_short(an.ms_between), format_short(an.f), format_p_short(an.p)});
            anova.rows.push_back({"within", format_short(an.ss_within),
                                  format_short(an.df_within), format_short(an.ms_within),
                                  "", ""});
            anova.rows.push_back({"total", format_short(an.ss_between + an.ss_within),
                                  format_short(an.df_between + an.df_within), "", "",
                                  ""});
            doc.push_back({Block::kHeading, "One-way ANOVA", {}, {}, 3});
            doc.push_back({Block::kTable, "", anova});
            doc.push_back(
                {Block::kParagraph, "eta squared = " + format_short(an.eta_sq) +
                                        ", omega squared = " + format_short(an.omega_sq) +
                                        (an.note.empty() ? "" : ". Note: " + an.note)});

            const TukeyResult& tk = a.tukey;
            doc.push_back({Block::kHeading, "Tukey HSD", {}, {}, 3});
            if (tk.pairs.empty()) {
                doc.push_back({Block::kParagraph, "Not computed: " + tk.note});
            } else {
                Table tukey{{"level a", "level b", "diff (b - a)", "se", "q", "p adj",
                             "lower", "upper", "p adj < " + format_short(tk.alpha)},
                            {}};
                for (const TukeyPair& p : tk.pairs)
                    tukey.rows.push_back({p.level_a, p.level_b, format_short(p.diff),
                                          format_short(p.se), format_short(p.q),
                                          format_p_short(p.p_adj), format_short(p.lower),
                                          format_short(p.upper),
                                          significant_at(p.p_adj, tk.alpha)});
                doc.push_back({Block::kTable, "", tukey});
                std::string hsd = "q critical (alpha " + format_short(tk.alpha) +
                                  ") = " + format_short(tk.q_critical);
                if (tk.hsd_05)
                    hsd += "; HSD[.05] = " + format_short(tk.hsd_05) +
                           ", HSD[.01] = " + format_short(tk.hsd_01);
                else
                    hsd += "; groups are unbalanced (Tukey-Kramer), so no single HSD";
                doc.push_back({Block::kParagraph, hsd});
            }
            doc.push_back({Block::kHeading, "Rank and heteroscedastic tests", {}, {}, 3});
            doc.push_back(
                {Block::kParagraph,
                 "Kruskal-Wallis (tie-corrected): H = " + format_short(a.kruskal.h) +
                     ", df = " + format_short(a.kruskal.df) +
                     ", p = " + format_p_short(a.kruskal.p) +
                     (a.kruskal.note.empty() ? "" : " (" + a.kruskal.note + ")")});
            doc.push_back({Block::kParagraph,
                           "Welch's ANOVA: F = " + format_short(a.welch.f) +
                               ", df1 = " + format_short(a.welch.df1) +
                               ", df2 = " + format_short(a.welch.df2) +
                               ", p = " + format_p_short(a.welch.p) +
                               (a.welch.note.empty() ? "" : " (" + a.welch.note + ")")});
        }
        std::string notes;
        for (const std::string& level : a.empty_levels)
            notes += "Level '" + level +
                     "' has no observations and is left out of the tests. ";
        if (a.missing_ratings > 0)
            notes += std::to_string(a.missing_ratings) + " missing ratings were skipped.";
        if (!notes.empty()) doc.push_back({Block::kParagraph, notes});
        if (models.anova && primary == Design::Between)
            doc.insert(doc.end(), within.begin(), within.end());
        if (!mixed_leads) doc.insert(doc.end(), mixed.begin(), mixed.end());
    }
    doc.insert(doc.end(), options.extra_blocks.begin(), options.extra_blocks.end());
    return doc;
}

void render_markdown(const std::vector<Block>& doc, std::ostream& out) {
    for (const Block& b : doc) {
        switch (b.kind) {
            case Block::kHeading:
                out << std::string(b.level, '#') << ' ' << b.text << "\n\n";
                break;
            case Block::kParagraph:
                out << b.text << "\n\n";
                break;
            case Block::kPlot:
                out << "![" << b.text << "](" << b.text << ")\n\n";
                break;
            case Block::kImages:
                for (const Block::Image& image : b.images)
                    out << "![" << image.caption << "](" << image.path.string() << ") ";
                out << "\n\n";
                break;
            case Block::kTable:
                out << '|';
                for (const auto& h : b.table.header) out << ' ' << md_cell(h) << " |";
                out << "\n|";
                for (std::size_t i = 0; i < b.table.header.size(); ++i) out << "---|";
                out << '\n';
                for (const auto& row : b.table.rows) {
                    out << '|';
                    for (const auto& cell : row) out << ' ' << md_cell(cell) << " |";
                    out << '\n';
                }
                out << '\n';
        }
    }
}

// The PNG bytes shown for a level's picture: a thumbnail when the caller can make one
// (lucent-full decodes images; the analysis library does not), else the file itself,
// scaled by the browser. Empty when neither can be read.
std::string embedded_picture(const std::filesystem::path& path,
                             const ReportOptions& options) {
    if (options.thumbnail_png) {
        try {
            return options.thumbnail_png(path);
        } catch (const std::exception&) {
            return {};
        }
    }
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return in ? bytes.str() : std::string();
}

void render_html(const std::vector<Block>& doc, const ReportOptions& options,
                 std::ostream& out) {
    out << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>Lucent analysis "
           "report</"
           "title>\n<style>body{font-family:sans-serif;max-width:60em;margin:auto}"
           "table{border-collapse:collapse}td,th{border:1px solid #bbb;padding:2px 8px;"
           "text-align:right}figure{margin:1em 0}svg{max-width:100%;height:auto}</style>"
        << common::images_drawn_script() << "</head><body>\n";
    for (const Block& b : doc) {
        switch (b.kind) {
            case Block::kHeading:
                out << "<h" << b.level << '>' << common::text_escape(b.text) << "</h"
                    << b.level << ">\n";
                break;
            case Block::kParagraph:
                out << "<p>" << common::text_escape(b.text) << "</p>\n";
                break;
            case Block::kPlot:
                out << "<figure>" << b.svg << "<figcaption>saved as "
                    << common::text_escape(b.text) << "</figcaption></figure>\n";
                break;
            case Block::kImages:
                out << "<div class=\"thumbnails\">";
                for (const Block::Image& image : b.images) {
                    out << "<figure style=\"display:inline-block;margin:4px\">";
                    const std::string png = embedded_picture(image.path, options);
                    if (!png.empty())
                        out << "<img width=\"128\" alt=\""
                            << common::text_escape(image.caption)
                            << "\" src=\"data:image/png;base64,"
                            << common::base64_encode(png) << "\">";
                    else
                        out << "(image unreadable: "
                            << common::text_escape(image.path.string()) << ")";
                    out << "<figcaption>" << common::text_escape(image.caption)
                        << "</figcaption></figure>";
                }
                out << "</div>\n";
                break;
            case Block::kTable:
                out << "<table><tr>";
                for (const auto& h : b.table.header)
                    out << "<th>" << common::text_escape(h) << "</th>";
                out << "</tr>\n";
                for (const auto& row : b.table.rows) {
                    out << "<tr>";
                    for (const auto& cell : row)
                        out << "<td>" << common::text_escape(cell) << "</td>";
                    out << "</tr>\n";
                }
                out << "</table>\n";
        }
    }
    out << "</body></html>\n";
}

// The one-way tests' tables only when they ran (--model); descriptives always.
void write_csv_tables(const std::vector<OneWayAnalysis>& analyses, bool one_way_tests,
                      ReportFiles& files) {
    std::ostringstream anova, tukey, kruskal, welch, desc;
    anova << "question,factor,ss_between,ss_within,df_between,df_within,ms_between,"
             "ms_within,f,p,eta_sq,omega_sq\n";
    tukey << "question,factor,level_a,level_b,diff,se,q,p_adj,lower,upper\n";
    kruskal << "question,factor,h,df,p\n";
    welch << "question,factor,f,df1,df2,p\n";
    desc << "question,factor,level,n,mean,sd,se,median,ci_low,ci_high\n";
    std::ostringstream rm_anova, friedman, paired;
    rm_anova
        << "question,factor,n_participants,f,df_effect,df_error,p,mauchly_w,mauchly_p,"
           "gg_epsilon,p_gg,hf_epsilon,p_hf,partial_eta_sq,generalized_eta_sq\n";
    friedman << "question,factor,n_participants,chi_sq,df,p,kendall_w\n";
    paired << "question,factor,level_a,level_b,diff,t,df,p,p_holm\n";
    for (const OneWayAnalysis& a : analyses) {
        const std::string key =
            common::csv_field(a.question) + ',' + common::csv_field(a.factor) + ',';
        const AnovaResult& r = a.anova;
        anova << key << format_full(r.ss_between) << ',' << format_full(r.ss_within)
              << ',' << format_full(r.df_between) << ',' << format_full(r.df_within)
              << ',' << format_full(r.ms_between) << ',' << format_full(r.ms_within)
              << ',' << format_full(r.f) << ',' << format_p_full(r.p) << ','
              << format_full(r.eta_sq) << ',' << format_full(r.omega_sq) << '\n';
        for (const TukeyPair& p : a.tukey.pairs)
            tukey << key << common::csv_field(p.level_a) << ','
                  << common::csv_field(p.level_b) << ',' << format_full(p.diff) << ','
                  << format_full(p.se) << ',' << format_full(p.q) << ','
                  << format_p_full(p.p_adj) << ',' << format_full(p.lower) << ','
                  << format_full(p.upper) << '\n';
        kruskal << key << format_full(a.kruskal.h) << ',' << format_full(a.kruskal.df)
                << ',' << format_p_full(a.kruskal.p) << '\n';
        welch << key << format_full(a.welch.f) << ',' << format_full(a.welch.df1) << ','
              << format_full(a.welch.df2) << ',' << format_p_full(a.welch.p) << '\n';
        for (const Descriptives& d : a.descriptives)
            desc << key << common::csv_field(d.level) << ',' << d.n << ','
                 << format_full(d.mean) << ',' << format_full(d.sd) << ','
                 << format_full(d.se) << ',' << format_full(d.median) << ','
                 << format_full(d.ci_low) << ',' << format_full(d.ci_high) << '\n';
        const WithinSubjectAnalysis& w = a.within;
        if (!w.computed) continue;  // no row: not a within-subject layout
        const RepeatedMeasuresAnova& rm = w.anova;
        rm_anova << key << w.participants << ',' << format_full(rm.f) << ','
                 << format_full(rm.df_effect) << ',' << format_full(rm.df_error) << ','
                 << format_p_full(rm.p) << ',' << format_full(rm.mauchly_w) << ','
                 << format_p_full(rm.mauchly_p) << ',' << format_full(rm.gg_epsilon)
                 << ',' << format_p_full(rm.p_gg) << ',' << format_full(rm.hf_epsilon)
                 << ',' << format_p_full(rm.p_hf) << ',' << format_full(rm.partial_eta_sq)
                 << ',' << format_full(rm.generalized_eta_sq) << '\n';
        const FriedmanResult& f = w.friedman;
        friedman << key << w.participants << ',' << format_full(f.chi_sq) << ','
                 << format_full(f.df) << ',' << format_p_full(f.p) << ','
                 << format_full(f.kendall_w) << '\n';
        for (const PairedComparison& c : w.paired)
            paired << key << common::csv_field(c.level_a) << ','
                   << common::csv_field(c.level_b) << ',' << format_full(c.diff) << ','
                   << format_full(c.t) << ',' << format_full(c.df) << ','
                   << format_p_full(c.p) << ',' << format_p_full(c.p_holm) << '\n';
    }
    files.emplace_back("descriptives.csv", desc.str());
    if (!one_way_tests) return;
    files.emplace_back("anova.csv", anova.str());
    files.emplace_back("tukey.csv", tukey.str());
    files.emplace_back("kruskal.csv", kruskal.str());
    files.emplace_back("welch.csv", welch.str());
    files.emplace_back("rm_anova.csv", rm_anova.str());
    files.emplace_back("friedman.csv", friedman.str());
    files.emplace_back("posthoc_paired.csv", paired.str());
}

}  // namespace

void parse_formats(const std::string& list, ReportOptions& result) {
    ReportOptions options = result;  // untouched on error
    options.markdown = options.csv = options.html = false;
    std::stringstream in(list);
    std::string item;
    while (std::getline(in, item, ',')) {
        if (item == "md")
            options.markdown = true;
        else if (item == "csv")
            options.csv = true;
        else if (item == "html")
            options.html = true;
        else
            throw InputError("--format: unknown format '" + item +
                             "' (valid: md, csv, html)");
    }
    if (!options.markdown && !options.csv && !options.html)
        throw InputError("--format: no format given (valid: md, csv, html)");
    result = options;
}

namespace {
// prefix + text with every character but letters, digits, '-' and '_' as '-', + ".svg".
std::string svg_file_name(const std::string& prefix, const std::string& text) {
    std::string name = prefix;
    for (char c : text)
        name +=
            std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' ? c : '-';
    return name + ".svg";
}
}  // namespace

std::map<std::pair<std::string, std::string>,
         std::pair<std::string, std::filesystem::path>>
level_images_from_directory(const LongTable& table,
                            const std::filesystem::path& directory) {
    std::error_code error;
    if (!std::filesystem::is_directory(directory, error))
        throw InputError("--images " + directory.string() + ": not a directory");
    std::map<std::pair<std::string, std::string>,
             std::pair<std::string, std::filesystem::path>>
        images;
    for (const RatingRow& row : table.rows) {
        const std::pair<std::string, std::string> key{row.factor, row.level};
        if (images.count(key)) continue;
        const std::filesystem::path png = directory / (row.stimulus + ".png");
        if (std::filesystem::is_regular_file(png, error))
            images[key] = {row.stimulus, png};
    }
    return images;
}

std::string figure_file_name(const std::string& factor) {
    return svg_file_name("figure_", factor);
}

std::string plot_file_name(const std::string& question, const std::string& factor) {
    return svg_file_name("plot_", question + "__" + factor);
}

std::vector<std::filesystem::path> write_report(
    const std::vector<OneWayAnalysis>& analyses, const std::filesystem::path& directory,
    const ReportOptions& options) {
    std::error_code error;
    if (std::filesystem::exists(directory, error) &&
        !std::filesystem::is_directory(directory, error))
        throw InputError(
            directory.string() +
            ": is a file; the report is written into a folder (refusing to touch it)");
    std::filesystem::create_directories(directory, error);
    if (error)
        throw InputError(directory.string() +
                         ": cannot create directory: " + error.message());
    const std::vector<Block> doc = build_document(analyses, options);
    ReportFiles files;
    if (options.markdown || options.html) {
        for (const Block& b : doc)
            if (b.kind == Block::kPlot) files.emplace_back(b.text, b.svg);
    }
    if (options.markdown) {
        std::ostringstream out;
        render_markdown(doc, out);
        files.emplace_back("report.md", out.str());
    }
    if (options.html) {
        std::ostringstream out;
        render_html(doc, options, out);
        files.emplace_back("report.html", out.str());
    }
    if (options.csv && !analyses.empty()) {
        write_csv_tables(analyses, options.models.anova, files);
        write_mixed_csv_tables(analyses, files);
    }
    // The extra sections' plots are in the document already; their tables are CSV.
    for (const auto& [name, text] : options.extra_files) {
        const bool csv = name.size() > 4 && name.compare(name.size() - 4, 4, ".csv") == 0;
        const bool present = std::any_of(files.begin(), files.end(),
                                         [&](const auto& f) { return f.first == name; });
        if (!present && (!csv || options.csv)) files.emplace_back(name, text);
    }
    // Refuse before writing anything: a report file that is the input or a database.
    // Earlier report files are replaced, atomically (readers see the old or the new).
    std::vector<std::filesystem::path> written;
    try {
        for (const auto& [name, text] : files)
            common::check_output_file(directory / name, options.inputs, true);
        for (const auto& [name, text] : files) {
            written.push_back(directory / name);
            common::write_file_atomically(written.back(), true,
                                          [&](std::ostream& out) { out << text; });
        }
    } catch (const common::OutputError& e) {
        throw InputError(e.what());
    }
    return written;
}

}  // namespace lucent::analysis

// Reports: exact CSV headers, 17-digit numbers that parse back, no NaN/Inf anywhere, the
// SVG beside the HTML and embedded in it, hard cases spelled out.
#include "analysis/report/report.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <regex>
#include <sstream>

#include "analysis/analyze.h"
#include "analysis/data/long_table.h"
#include "analysis/report/rating_figures.h"
#include "common/html/html_page.h"
#include "tests/support/test_paths.h"

namespace lucent::analysis {
namespace {

std::string slurp(const std::filesystem::path& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

std::string first_line(const std::string& text) {
    return text.substr(0, text.find('\n'));
}

OneWayData groups(std::vector<std::vector<double>> values) {
    OneWayData data;
    for (std::size_t i = 0; i < values.size(); ++i)
        data.groups.push_back({std::to_string(i + 1), std::move(values[i])});
    return data;
}

TEST(Report, WritesEveryFormatWithExactHeaders) {
    const auto dir = test::scratch_dir("report_formats");
    std::vector<OneWayAnalysis> analyses{
        analyze_one_way("translucent", "thickness",
                        groups({{1, 2, 3, 2}, {4, 5, 6, 5}, {3, 4, 4}}), 0.10),
        analyze_one_way("realistic", "thickness", groups({{4, 4}, {4, 4, 4}}),
                        0.10),  // identical
        analyze_one_way("varnished", "thickness", groups({{1, 1}, {3, 3}}),
                        0.10),  // F = inf
        analyze_one_way("single", "thickness", groups({{1, 2}, {}}),
                        0.10)};  // one + empty
    write_report(analyses, dir, ReportOptions{});
    EXPECT_EQ(
        first_line(slurp(dir / "anova.csv")),
        "question,factor,ss_between,ss_within,df_between,df_within,ms_between,ms_within,"
        "f,p,eta_sq,omega_sq");
    EXPECT_EQ(first_line(slurp(dir / "tukey.csv")),
              "question,factor,level_a,level_b,diff,se,q,p_adj,lower,upper");
    EXPECT_EQ(first_line(slurp(dir / "kruskal.csv")), "question,factor,h,df,p");
    EXPECT_EQ(first_line(slurp(dir / "welch.csv")), "question,factor,f,df1,df2,p");

    const std::string anova = slurp(dir / "anova.csv");
    // Full precision: F for the first pair printed with 17 significant digits
    // round-trips.
    std::istringstream rows(anova);
    std::string header, first;
    std::getline(rows, header);
    std::getline(rows, first);
    std::vector<std::string> cells;
    for (std::stringstream s(first); std::getline(s, header, ',');)
        cells.push_back(header);
    ASSERT_EQ(cells.size(), 12u);
    EXPECT_EQ(std::stod(cells[8]), *analyses[0].anova.f);
    EXPECT_NE(anova.find("realistic,thickness,0,0,1,3,0,0,undefined,undefined"),
              std::string::npos)
        << anova;
    EXPECT_NE(anova.find(",inf,< 1e-300,1,"), std::string::npos) << anova;

    for (const char* name : {"anova.csv", "tukey.csv", "kruskal.csv", "welch.csv",
                             "descriptives.csv", "report.md", "report.html"}) {
        // No NaN in any spelling; "inf" only as a whole cell (spelled out on purpose).
        const std::string text = slurp(dir / name);
        EXPECT_FALSE(std::regex_search(text, std::regex("nan", std::regex::icase)))
            << name;
        EXPECT_FALSE(std::regex_search(text, std::regex("[0-9.]inf|infinity"))) << name;
    }
    const std::string md = slurp(dir / "report.md");
    EXPECT_NE(md.find("| configuration | analysis | test | p | statistic |"),
              std::string::npos);
    EXPECT_NE(md.find("translucent ~ thickness"), std::string::npos);
    EXPECT_NE(md.find("undefined"), std::string::npos);
    EXPECT_NE(md.find("no observations"), std::string::npos);
    const std::string html = slurp(dir / "report.html");
    EXPECT_NE(html.find("<svg"), std::string::npos);
    const auto svg = dir / plot_file_name("translucent", "thickness");
    ASSERT_TRUE(std::filesystem::exists(svg));
    EXPECT_NE(slurp(svg).find("<circle"), std::string::npos);
}

// Two-sided p of Student's t with even df, in closed form (Abramowitz & Stegun 26.7.3):
// p = 1 - sqrt(x) * sum_{j < df/2} c_j (1 - x)^j, x = t^2 / (df + t^2), c_j = prod
// (2i-1)/(2i).
double student_t_two_sided_p_even_df(double t, int df) {
    const double x = t * t / (df + t * t);
    double c = 1.0, sum = 0.0, power = 1.0;
    for (int j = 0; j < df / 2; ++j) {
        if (j > 0) c *= (2.0 * j - 1.0) / (2.0 * j);
        sum += c * power;
        power *= 1.0 - x;
    }
    return 1.0 - std::sqrt(x) * sum;
}

// The Tukey table's row for levels (a, b) of report.md, split into cells.
std::vector<std::string> tukey_row(const std::string& md, const std::string& a,
                                   const std::string& b) {
    const std::string start = "| " + a + " | " + b + " |";
    const std::size_t at = md.find(start);
    if (at == std::string::npos) return {};
    std::vector<std::string> cells;
    std::stringstream line(md.substr(at + 1, md.find('\n', at) - at - 1));
    for (std::string cell; std::getline(line, cell, '|');)
        cells.push_back(cell.substr(1, cell.size() - 2));
    return cells;
}

TEST(Report, TukeySignificanceFollowsTheReportsAlphaAndItsInterval) {
    // Two groups: Tukey's p adj equals the pooled two-sample t-test's p. Means 3 and 5,
    // pooled variance 2.5, se 1: t = 2 on 8 df, p = 0.0805 (between .05 and .10).
    const OneWayData data = groups({{1, 2, 3, 4, 5}, {3, 4, 5, 6, 7}});
    const double p_t = student_t_two_sided_p_even_df(2.0, 8);
    ASSERT_GT(p_t, 0.05);
    ASSERT_LT(p_t, 0.10);
    for (const double alpha : {0.10, 0.05}) {
        const auto dir =
            test::scratch_dir(alpha > 0.07 ? "tukey_alpha_10" : "tukey_alpha_05");
        const OneWayAnalysis a = analyze_one_way("translucent", "r", data, alpha);
        ASSERT_EQ(a.tukey.pairs.size(), 1u);
        EXPECT_NEAR(*a.tukey.pairs[0].p_adj, p_t, 1e-6);
        ReportOptions options;
        options.alpha = alpha;
        write_report({a}, dir, options);
        const std::string md = slurp(dir / "report.md");
        const std::vector<std::string> row = tukey_row(md, "1", "2");
        ASSERT_EQ(row.size(), 9u) << md;
        const double lower = std::stod(row[6]), upper = std::stod(row[7]);
        const bool excludes_zero = lower > 0.0 || upper < 0.0;
        // At .10 the 90% interval excludes 0 and the pair is significant; at .05 neither.
        EXPECT_EQ(excludes_zero, alpha > 0.07) << row[6] << " " << row[7];
        EXPECT_EQ(row[8], excludes_zero ? "yes" : "no") << md;
        EXPECT_NE(md.find("p adj < " + std::string(alpha > 0.07 ? "0.1" : "0.05")),
                  std::string::npos)
            << md;
        EXPECT_EQ(md.find("n.s."), std::string::npos) << md;
    }
}

TEST(Report, NeverReplacesItsInputOrADatabaseAndWritesNothingThen) {
    const auto dir = test::scratch_dir("report_protects_input");
    // The ratings live in the report folder under a name the report also writes.
    const auto input = dir / "anova.csv";
    std::ofstream(input) << "participant,stimulus,factor,level,question,rating\n";
    ReportOptions options;
    options.inputs = {input};
    const std::vector<OneWayAnalysis> analyses{
        analyze_one_way("q", "f", groups({{1, 2}, {3, 4}}), 0.10)};
    try {
        write_report(analyses, dir, options);
        FAIL();
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("is the input"), std::string::npos)
            << e.what();
    }
    EXPECT_EQ(slurp(input), "participant,stimulus,factor,level,question,rating\n");
    EXPECT_FALSE(std::filesystem::exists(dir / "report.md"));  // refused before writing
    // A database in the way is refused too; the folder itself must not be a file.
    std::filesystem::remove(input);
    std::ofstream(dir / "report.md") << std::string("SQLite format 3\0", 16) << "pages";
    EXPECT_THROW(write_report(analyses, dir, ReportOptions{}), InputError);
    EXPECT_THROW(write_report(analyses, dir / "report.md", ReportOptions{}), InputError);
    std::filesystem::remove(dir / "report.md");
    write_report(analyses, dir, ReportOptions{});  // a second run replaces its own files
    write_report(analyses, dir, ReportOptions{});
    EXPECT_TRUE(std::filesystem::exists(dir / "report.md"));
}

std::vector<std::string> csv_cells(const std::string& line) {
    std::vector<std::string> cells;
    std::stringstream s(line);
    for (std::string cell; std::getline(s, cell, ',');) cells.push_back(cell);
    return cells;
}

TEST(Report, WithinSubjectTablesLeadWhenPrimaryAndParseBack) {
    // Four participants rate three levels; P5 rates only one level and is left out.
    std::istringstream csv(
        "participant,stimulus,factor,level,question,rating\n"
        "P1,a,r,18,q,2\nP1,b,r,25,q,4\nP1,c,r,30,q,5\n"
        "P2,a,r,18,q,3\nP2,b,r,25,q,3\nP2,c,r,30,q,6\n"
        "P3,a,r,18,q,1\nP3,b,r,25,q,4\nP3,c,r,30,q,4\n"
        "P4,a,r,18,q,2\nP4,b,r,25,q,5\nP4,c,r,30,q,7\n"
        "P5,a,r,18,q,6\n");
    const LongTable table = read_long_csv(csv, "within.csv", RatingScale{});
    // 4 of 5 participants complete: within only with a stated share of 80% (issue 26
    // item 4: by default every participant must have rated every level).
    EXPECT_EQ(analyze_table(table, AnalysisRequest{}).primary, Design::Between);
    AnalysisRequest request;
    request.within_share = 0.8;
    const AnalysisResult result = analyze_table(table, request);
    ASSERT_EQ(result.primary, Design::Within);
    const auto dir = test::scratch_dir("report_within");
    ReportOptions options;
    options.primary = result.primary;
    write_report(result.pairs, dir, options);

    const std::string rm = slurp(dir / "rm_anova.csv");
    EXPECT_EQ(first_line(rm),
              "question,factor,n_participants,f,df_effect,df_error,p,mauchly_w,mauchly_p,"
              "gg_epsilon,p_gg,hf_epsilon,p_hf,partial_eta_sq,generalized_eta_sq");
    const std::vector<std::string> row = csv_cells(rm.substr(rm.find('\n') + 1));
    ASSERT_EQ(row.size(), 15u) << rm;
    const RepeatedMeasuresAnova& r = result.pairs[0].within.anova;
    EXPECT_EQ(row[2], "4");
    EXPECT_EQ(std::stod(row[3]), *r.f);
    EXPECT_EQ(std::stod(row[10]), *r.p_gg);
    EXPECT_EQ(first_line(slurp(dir / "friedman.csv")),
              "question,factor,n_participants,chi_sq,df,p,kendall_w");
    const std::string paired = slurp(dir / "posthoc_paired.csv");
    EXPECT_EQ(first_line(paired), "question,factor,level_a,level_b,diff,t,df,p,p_holm");
    EXPECT_EQ(std::count(paired.begin(), paired.end(), '\n'), 4);  // header + 3 pairs

    const std::string md = slurp(dir / "report.md");
    const std::size_t within_row = md.find("| q ~ r | within (primary) |");
    const std::size_t between_row = md.find("| q ~ r | between |");
    ASSERT_NE(within_row, std::string::npos) << md;
    ASSERT_NE(between_row, std::string::npos) << md;
    EXPECT_LT(within_row, between_row);
    EXPECT_NE(md.find("left out (a level missing): P5"), std::string::npos);
    // The section of the primary design comes before the between-subject tables.
    EXPECT_LT(md.find("### Within-subject tests"), md.find("### One-way ANOVA"));
    // The factor's figure: one panel per question, the factor named under the levels,
    // which read in parameter order (18, 25, 30), each level's mean drawn once per panel.
    const std::string figure = slurp(dir / figure_file_name("r"));
    EXPECT_NE(figure.find(">q</text>"), std::string::npos) << figure;
    EXPECT_NE(figure.find(">r (mean with 95% CI)</text>"), std::string::npos) << figure;
    EXPECT_LT(figure.find(">18</text>"), figure.find(">25</text>"));
    EXPECT_LT(figure.find(">25</text>"), figure.find(">30</text>"));
    std::size_t circles = 0;
    for (std::size_t at = figure.find("<circle"); at != std::string::npos;
         at = figure.find("<circle", at + 1))
        ++circles;
    EXPECT_EQ(circles, 3u);
    EXPECT_NE(slurp(dir / "report.html").find(figure.substr(0, 40)), std::string::npos)
        << "the HTML embeds the figure";
    for (const char* name :
         {"rm_anova.csv", "friedman.csv", "posthoc_paired.csv", "report.md"})
        EXPECT_FALSE(
            std::regex_search(slurp(dir / name), std::regex("nan", std::regex::icase)))
            << name;
}

// The summary row of `configuration` and `design` in report.md, split into cells.
std::vector<std::string> summary_row(const std::string& md, const std::string& start) {
    const std::size_t at = md.find("| " + start + " |");
    if (at == std::string::npos) return {};
    std::vector<std::string> cells;
    std::stringstream line(md.substr(at + 1, md.find('\n', at) - at - 1));
    for (std::string cell; std::getline(line, cell, '|');)
        cells.push_back(cell.substr(1, cell.size() - 2));
    return cells;
}

TEST(Report, OneParticipantsSummarySaysWhyItsTestsAreUndefined) {
    // What scripts/run-default analyses: one participant, one stimulus per level (no
    // test has spread to work with), and a factor with two stimuli per level (its
    // between-subject ANOVA is defined; its within-subject tests are not).
    std::istringstream csv(
        "participant,stimulus,factor,level,question,rating\n"
        "P1,a,r,18,q,2\nP1,b,r,25,q,4\nP1,c,r,30,q,5\n"
        "P1,d,t,ward,q,3\nP1,e,t,ward,q,4\nP1,f,t,reversed,q,6\nP1,g,t,reversed,q,7\n");
    const LongTable table = read_long_csv(csv, "one.csv", RatingScale{});
    const AnalysisResult result = analyze_table(table, AnalysisRequest{});
    const auto dir = test::scratch_dir("report_one_participant");
    ReportOptions options;
    options.primary = Design::Within;  // as the thesis protocol states
    write_report(result.pairs, dir, options);
    const std::string md = slurp(dir / "report.md");

    const std::vector<std::string> within = summary_row(md, "q ~ r | within (primary)");
    ASSERT_EQ(within.size(), 7u) << md;
    EXPECT_EQ(within[3], "undefined");  // p and F stay the number columns' word
    EXPECT_EQ(within[5],
              "undefined: needs at least 2 participants who rated every level (1 did)");
    const std::vector<std::string> between = summary_row(md, "q ~ r | between");
    ASSERT_EQ(between.size(), 7u) << md;
    EXPECT_EQ(between[3], "undefined");
    EXPECT_EQ(between[5],
              "undefined: needs at least 2 ratings in some level (each level has 1)");
    // Two ratings per level: the between-subject test is defined and says yes or no.
    const std::vector<std::string> defined = summary_row(md, "q ~ t | between");
    ASSERT_EQ(defined.size(), 7u) << md;
    EXPECT_TRUE(defined[5] == "yes" || defined[5] == "no") << defined[5];
    EXPECT_EQ(summary_row(md, "q ~ t | within (primary)")[5],
              "undefined: needs at least 2 participants who rated every level (1 did)");

    // No verdict cell is a bare "undefined", and a paragraph says why, in both formats.
    EXPECT_EQ(md.find("| undefined | 1 participant"), std::string::npos) << md;
    EXPECT_EQ(md.find("| undefined | 1 of 1"), std::string::npos) << md;
    const std::string why = "One participant: a test that is undefined says why";
    EXPECT_NE(md.find(why), std::string::npos) << md;
    EXPECT_NE(slurp(dir / "report.html").find(why), std::string::npos);
}

TEST(Report, TwoParticipantsNeedNoWordOnOneParticipant) {
    std::istringstream csv(
        "participant,stimulus,factor,level,question,rating\n"
        "P1,a,r,18,q,2\nP1,b,r,25,q,4\nP1,c,r,30,q,5\n"
        "P2,a,r,18,q,3\nP2,b,r,25,q,3\nP2,c,r,30,q,6\n");
    const LongTable table = read_long_csv(csv, "two.csv", RatingScale{});
    const AnalysisResult result = analyze_table(table, AnalysisRequest{});
    const auto dir = test::scratch_dir("report_two_participants");
    write_report(result.pairs, dir, ReportOptions{});
    const std::string md = slurp(dir / "report.md");
    EXPECT_EQ(md.find("One participant"), std::string::npos) << md;
    const std::vector<std::string> within = summary_row(md, "q ~ r | within");
    ASSERT_EQ(within.size(), 7u) << md;
    EXPECT_TRUE(within[5] == "yes" || within[5] == "no") << within[5];
}

TEST(Report, FactorFigurePutsQuestionsSideBySideOnOneScale) {
    // Two questions of one factor: two panels 320 wide, one y range for both, so the
    // same value sits at the same height in each panel.
    std::vector<Descriptives> low = describe_all(groups({{1, 2, 3}, {2, 3, 4}}), 0.95);
    std::vector<Descriptives> high = describe_all(groups({{5, 6, 7}, {2, 3, 4}}), 0.95);
    const std::string svg =
        factor_figure_svg("backlight", {{"translucent", low}, {"realistic", high}});
    EXPECT_NE(svg.find("width=\"640\""), std::string::npos) << svg;
    EXPECT_NE(svg.find(">translucent</text>"), std::string::npos);
    EXPECT_NE(svg.find(">realistic</text>"), std::string::npos);
    // Level 2 has mean 3 in both panels: both circles at the same y.
    std::vector<std::string> ys;
    for (std::size_t at = svg.find("<circle"); at != std::string::npos;
         at = svg.find("<circle", at + 1)) {
        const std::size_t cy = svg.find("cy=\"", at) + 4;
        ys.push_back(svg.substr(cy, svg.find('"', cy) - cy));
    }
    ASSERT_EQ(ys.size(), 4u);
    EXPECT_EQ(ys[1], ys[3]) << svg;
    EXPECT_NE(ys[0], ys[2]);  // means 2 and 6
    EXPECT_FALSE(std::regex_search(svg, std::regex("nan|inf", std::regex::icase)));
}

// The y tick labels (right-aligned text) of an SVG plot.
std::vector<std::string> y_ticks(const std::string& svg) {
    std::vector<std::string> ticks;
    const std::regex tick("<text [^>]*text-anchor=\"end\"[^>]*>([^<]*)</text>");
    for (std::sregex_iterator it(svg.begin(), svg.end(), tick), end; it != end; ++it)
        ticks.push_back((*it)[1]);
    return ticks;
}

TEST(Report, PlotsRunOverTheRatingScaleOfTheirQuestion) {
    // Each plot's y axis is its question's scale where the input knows it (a study
    // database: 'realistic' on 5 points), else the report's (1..7); the factor's figure
    // spans both. Ratings that disagree put the 95% intervals past both ends.
    std::istringstream csv(
        "participant,stimulus,factor,level,question,rating\n"
        "P1,a,r,18,translucent,1\nP2,a,r,18,translucent,7\nP3,a,r,18,translucent,4\n"
        "P1,a,r,18,realistic,1\nP2,a,r,18,realistic,5\nP3,a,r,18,realistic,3\n"
        "P1,b,r,25,translucent,2\nP2,b,r,25,translucent,6\nP3,b,r,25,translucent,3\n"
        "P1,b,r,25,realistic,2\nP2,b,r,25,realistic,5\nP3,b,r,25,realistic,1\n");
    const LongTable table = read_long_csv(csv, "scales.csv", RatingScale{});
    const AnalysisResult result = analyze_table(table, AnalysisRequest{});
    const auto dir = test::scratch_dir("report_scales");
    ReportOptions options;
    options.question_scales["realistic"] = RatingScale{false, 1, 5};
    write_report(result.pairs, dir, options);
    using Ticks = std::vector<std::string>;
    EXPECT_EQ(y_ticks(slurp(dir / plot_file_name("realistic", "r"))),
              (Ticks{"1", "2", "3", "4", "5"}));
    EXPECT_EQ(y_ticks(slurp(dir / plot_file_name("translucent", "r"))),
              (Ticks{"1", "2", "3", "4", "5", "6", "7"}));
    const std::string figure = slurp(dir / figure_file_name("r"));
    EXPECT_EQ(y_ticks(figure), (Ticks{"1", "2", "3", "4", "5", "6", "7", "1", "2", "3",
                                      "4", "5", "6", "7"}));
    EXPECT_NE(figure.find("<path"), std::string::npos);  // intervals cut at the scale
    EXPECT_NE(figure.find("the interval goes on past the axis"), std::string::npos);
    // "any": the data's range at round steps.
    options.scale.any = true;
    options.question_scales.clear();
    write_report(result.pairs, dir, options);
    const Ticks any = y_ticks(slurp(dir / plot_file_name("translucent", "r")));
    ASSERT_GE(any.size(), 2u);
    EXPECT_LT(std::stod(any.front()), 1.0);  // the intervals reach below 1
}

TEST(Report, LevelPicturesAreEmbeddedBesideTheirDescriptives) {
    const auto dir = test::scratch_dir("report_thumbnails");
    const auto images = dir / "stimuli";
    std::filesystem::create_directories(images);
    // Two stand-in PNG files (the report embeds bytes, it does not decode them).
    std::ofstream(images / "thin.png", std::ios::binary) << "PNG-thin";
    std::ofstream(images / "thick.png", std::ios::binary) << "PNG-thick";
    std::istringstream csv(
        "participant,stimulus,factor,level,question,rating\n"
        "P1,thin,r,18,q,2\nP1,thick,r,30,q,5\nP2,thin,r,18,q,3\nP2,thick,r,30,q,6\n"
        "P1,nopicture,b,0.8,q,4\nP2,nopicture,b,0.8,q,4\n");
    const LongTable table = read_long_csv(csv, "t.csv", RatingScale{});
    ReportOptions options;
    options.level_images = level_images_from_directory(table, images);
    ASSERT_EQ(options.level_images.size(), 2u);  // the 'b' level has no picture
    EXPECT_EQ(options.level_images.at({"r", "30"}).first, "thick");
    options.csv = false;
    write_report(analyze_table(table, AnalysisRequest{}).pairs, dir / "out", options);
    const std::string html = slurp(dir / "out" / "report.html");
    EXPECT_NE(html.find("data:image/png;base64," + common::base64_encode("PNG-thin")),
              std::string::npos);
    EXPECT_NE(html.find("data:image/png;base64," + common::base64_encode("PNG-thick")),
              std::string::npos);
    EXPECT_LT(html.find(common::base64_encode("PNG-thin")),
              html.find(common::base64_encode("PNG-thick")));
    EXPECT_NE(html.find("r 30 (thick)"), std::string::npos);
    EXPECT_THROW(level_images_from_directory(table, dir / "missing"), InputError);
}

TEST(Report, FormatSelectionAndErrors) {
    ReportOptions options;
    parse_formats("csv", options);
    EXPECT_TRUE(options.csv);
    EXPECT_FALSE(options.markdown || options.html);
    EXPECT_THROW(parse_formats("md,pdf", options), InputError);
    const auto dir = test::scratch_dir("report_csv_only");
    write_report({analyze_one_way("q", "f", groups({{1, 2}, {3, 4}}), 0.05)}, dir,
                 options);
    EXPECT_TRUE(std::filesystem::exists(dir / "anova.csv"));
    EXPECT_FALSE(std::filesystem::exists(dir / "report.md"));
}

}  // namespace
}  // namespace lucent::analysis

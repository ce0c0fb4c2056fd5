// Every plot drawn by a real browser (headless chromium) stays inside its SVG and the
// page: a bench-accuracy figure (five knobs, errors over three decades, a long title),
// the stimulus-set report's small plots, and `lucent analyze`'s report, whose intervals
// run past the 1..7 scale. A script in
// the page measures each <text>'s box (getBoundingClientRect, which includes
// rotations and textLength) against its <svg>'s box and a 1024-pixel page, and writes
// what it found into the DOM that --dump-dom returns.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>

#include "common/html/svg_plot.h"
#include "tests/support/browser.h"

namespace lucent {
namespace {

namespace fs = std::filesystem;

constexpr int kPageWidth = 1024;

std::string read_file(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    return bytes.str();
}

void write_file(const fs::path& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
}

// Sets data-text-check="N texts; outside: ..." on <html> once the page has loaded.
std::string text_check_script() {
    return "<script>window.addEventListener('load', () => {\n"
           "  const page = " +
           std::to_string(kPageWidth) +
           ", out = [];\n"
           "  let texts = 0;\n"
           "  const r4 = (b) => [b.left, b.top, b.right, "
           "b.bottom].map(Math.round).join(',');\n"
           "  for (const svg of document.querySelectorAll('svg')) {\n"
           "    const box = svg.getBoundingClientRect();\n"
           "    if (box.right > page + 0.5) out.push('svg ' + r4(box) + ' past the "
           "page');\n"
           "    for (const t of svg.querySelectorAll('text')) {\n"
           "      if (!t.textContent.trim()) continue;\n"
           "      ++texts;\n"
           "      const b = t.getBoundingClientRect();\n"
           "      if (b.left < box.left - 0.5 || b.right > box.right + 0.5 ||\n"
           "          b.top < box.top - 0.5 || b.bottom > box.bottom + 0.5 ||\n"
           "          b.right > page + 0.5)\n"
           "        out.push(t.textContent + ' at ' + r4(b) + ' outside ' + r4(box));\n"
           "    }\n"
           "  }\n"
           "  document.documentElement.setAttribute('data-text-check',\n"
           "      texts + ' texts; outside: ' + out.join(' | '));\n"
           "});</script>\n";
}

std::string attribute(const std::string& dom, const std::string& name) {
    const std::string key = name + "=\"";
    const auto at = dom.find(key);
    if (at == std::string::npos) return "";
    const auto end = dom.find('"', at + key.size());
    return dom.substr(at + key.size(), end - at - key.size());
}

// The count of texts checked, after the check found none outside.
int texts_all_inside(const std::string& check) {
    const auto outside = check.find(" texts; outside: ");
    if (outside == std::string::npos) return -1;
    if (outside + 17 != check.size()) return -1;
    return std::stoi(check.substr(0, outside));
}

TEST(PlotsInBrowser, BenchAccuracyFigureTextStaysInsideItsSvgAndThePage) {
    const fs::path dir =
        fs::path(LUCENT_BINARY_DIR) / "test-scratch" / "plot_browser_bench";
    fs::remove_all(dir);
    fs::create_directories(dir);
    // The shape of `lucent bench accuracy --technique empirical`: five knobs, RMSE from
    // 1e-4 to 0.2, frame times 0.3..9 ms, value labels beside the points.
    std::vector<common::PlotPanel> panels;
    const char* knobs[] = {"blur_kernel", "depth_precision", "ao_rays", "layer_method",
                           "a_rather_long_quality_knob_name (hybrid=on, rings=24)"};
    for (int k = 0; k < 5; ++k) {
        common::PlotPanel p;
        p.title = knobs[k];
        p.x = {0.3, 1.2 + k, 4.5, 9.0};
        p.y = {0.2, 0.013, 1.1e-3, 1.2e-4};
        p.point_labels = {"16", "32", "320", "peel_and_something"};
        p.x_label = "GPU frame time (ms)";
        p.y_label = "RMSE vs CPU reference";
        p.x_axis.include_zero = p.y_axis.include_zero = true;
        panels.push_back(p);
    }
    const std::string svg = common::figure_svg(
        "lucent bench accuracy: empirical on torus_knot:30k at 256x256 (a title long "
        "enough to need the whole width of the figure and then some more words)",
        panels);
    write_file(dir / "bench-accuracy.svg", svg);
    write_file(dir / "page.html",
               "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\">" +
                   text_check_script() + "</head><body style=\"margin:0\">\n" + svg +
                   "</body></html>\n");
    const test::BrowserPage page =
        test::open_in_browser(dir / "page.html", dir / "screenshot.png", 1100, 700);
    ASSERT_TRUE(page.ok) << page.error;
    const std::string check = attribute(page.dom, "data-text-check");
    // Figure title, 5 x (title, 2 axis labels, >= 8 ticks, 4 point labels).
    EXPECT_GE(texts_all_inside(check), 1 + 5 * 15) << check;
    // Three columns, two rows: a figure no wider than the page.
    EXPECT_NE(svg.find("width=\"960\""), std::string::npos);
    // The error axes are logarithmic: decades labelled in every panel.
    for (const char* decade : {">1e-4<", ">0.001<", ">0.01<", ">0.1<", ">1<"}) {
        std::size_t n = 0;
        for (auto at = svg.find(decade); at != std::string::npos;
             at = svg.find(decade, at + 1))
            ++n;
        EXPECT_EQ(n, 5u) << decade;
    }
    EXPECT_GT(page.non_background_pixels, 10000u);
}

TEST(PlotsInBrowser, StimulusSetReportPlotsKeepTheirTextInside) {
    const fs::path dir =
        fs::path(LUCENT_BINARY_DIR) / "test-scratch" / "plot_browser_set";
    fs::remove_all(dir);
    fs::create_directories(dir);
    // The stimulus-set report's small plots, with a long stimulus id and metric name,
    // an undefined value and a single level.
    const std::string page_html =
        "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\">" + text_check_script() +
        "</head><body>\n" +
        common::histogram_svg("thesis_thickness_exponent_18_backlight_2_view_front",
                              {0.02, 0.1, 0.37, 0.2, 0.1, 0.05, 0.03, 0.0}) +
        common::level_values_svg("RMS contrast", {"18", "25", "30"}, {0.7, NAN, 1.2},
                                 "thickness_exponent") +
        common::level_values_svg("mean luminance inside the silhouette of the object",
                                 {"0.5", "1", "2", "4"}, {0.0123, 0.0131, 0.0129, 0.015},
                                 "backlight") +
        common::level_values_svg("one level", {"a"}, {3.0}) + "</body></html>\n";
    write_file(dir / "page.html", page_html);
    const test::BrowserPage page =
        test::open_in_browser(dir / "page.html", dir / "screenshot.png", 1000, 400);
    ASSERT_TRUE(page.ok) << page.error;
    const std::string check = attribute(page.dom, "data-text-check");
    EXPECT_GE(texts_all_inside(check), 30) << check;
    EXPECT_NE(page_html.find(">0.015<"), std::string::npos);  // round ticks
    EXPECT_NE(page_html.find(">40%<"), std::string::npos);
}

TEST(PlotsInBrowser, AnalysisReportStaysOnTheRatingScaleAndInsideThePage) {
    const fs::path dir =
        fs::path(LUCENT_BINARY_DIR) / "test-scratch" / "plot_browser_report";
    fs::remove_all(dir);
    fs::create_directories(dir);
    // Three participants who disagree: each level's 95% CI (t with 2 df) runs past
    // both ends of 1..7, as the -4.68..12.01 axis of the old report did.
    {
        std::ofstream csv(dir / "ratings.csv");
        csv << "participant,stimulus,factor,level,question,rating\n";
        const int ratings[3][3] = {{1, 2, 4}, {7, 6, 7}, {4, 1, 5}};
        for (int p = 0; p < 3; ++p)
            for (int l = 0; l < 3; ++l)
                for (const char* q : {"translucent", "realistic", "soft", "glowing"})
                    csv << 'p' << p << ",s" << l << ",thickness_exponent," << 18 + l
                        << ',' << q << ',' << ratings[p][l] << '\n';
    }
    const std::string command = std::string("'") + LUCENT_EXECUTABLE + "' analyze '" +
                                (dir / "ratings.csv").string() + "' --out '" +
                                (dir / "report").string() + "' > '" +
                                (dir / "analyze.log").string() + "' 2>&1";
    ASSERT_EQ(std::system(command.c_str()), 0) << read_file(dir / "analyze.log");
    // The y axes are the scale: tick labels (right-aligned text) exactly 1..7.
    const std::string figure =
        read_file(dir / "report" / "figure_thickness_exponent.svg");
    ASSERT_FALSE(figure.empty());
    std::set<std::string> y_ticks;
    const std::regex tick("<text [^>]*text-anchor=\"end\"[^>]*>([^<]*)</text>");
    for (std::sregex_iterator it(figure.begin(), figure.end(), tick), end; it != end;
         ++it)
        y_ticks.insert((*it)[1]);
    EXPECT_EQ(y_ticks, (std::set<std::string>{"1", "2", "3", "4", "5", "6", "7"}));
    EXPECT_NE(figure.find("<path"), std::string::npos);  // intervals cut at the scale
    // Four questions: three panels in the first row, one in the second.
    EXPECT_NE(figure.find("width=\"960\""), std::string::npos);

    std::string html = read_file(dir / "report" / "report.html");
    const auto body_end = html.rfind("</body>");
    ASSERT_NE(body_end, std::string::npos);
    html.insert(body_end, text_check_script());
    write_file(dir / "report" / "checked.html", html);
    const test::BrowserPage page = test::open_in_browser(
        dir / "report" / "checked.html", dir / "screenshot.png", 1100, 3000);
    ASSERT_TRUE(page.ok) << page.error;
    const std::string check = attribute(page.dom, "data-text-check");
    EXPECT_GE(texts_all_inside(check), 50) << check;
}

}  // namespace
}  // namespace lucent

namespace lucent {
namespace {

// `lucent bench fidelity`'s figure as the command writes it (a tiny run: one case, two
// techniques, a few renders): every technique a labelled curve, the text inside the SVG
// and the page, the CSV beside it with the fitted technique's error.
TEST(PlotsInBrowser, BenchFidelityFigureHasACurvePerTechniqueInsideThePage) {
    const fs::path dir =
        fs::path(LUCENT_BINARY_DIR) / "test-scratch" / "plot_browser_fidelity";
    fs::remove_all(dir);
    fs::create_directories(dir);
    const std::string command =
        std::string("'") + LUCENT_EXECUTABLE +
        "' bench fidelity --case thin --size 20 --paths 8 --evaluations 4 "
        "--techniques ward,dipole --csv '" +
        (dir / "fidelity.csv").string() + "' --svg '" + (dir / "fidelity.svg").string() +
        "' > '" + (dir / "bench.log").string() + "' 2>&1";
    ASSERT_EQ(std::system(command.c_str()), 0) << read_file(dir / "bench.log");
    const std::string svg = read_file(dir / "fidelity.svg");
    for (const char* label : {">ward (ao_rays)<", ">dipole (", ">path (paths)<"})
        EXPECT_NE(svg.find(label), std::string::npos) << label;
    EXPECT_EQ(svg.find("nan"), std::string::npos);
    EXPECT_NE(read_file(dir / "fidelity.csv").find("\"thin ward\",\"mean Delta E00\""),
              std::string::npos)
        << read_file(dir / "fidelity.csv");
    write_file(dir / "page.html",
               "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\">" +
                   text_check_script() + "</head><body style=\"margin:0\">\n" + svg +
                   "</body></html>\n");
    const test::BrowserPage page =
        test::open_in_browser(dir / "page.html", dir / "screenshot.png", 1100, 500);
    ASSERT_TRUE(page.ok) << page.error;
    const std::string check = attribute(page.dom, "data-text-check");
    EXPECT_GE(texts_all_inside(check), 10) << check;
}

}  // namespace
}  // namespace lucent

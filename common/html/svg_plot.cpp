// SVG charts (see svg_plot.h).
#include "common/html/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "common/html/html_page.h"

namespace lucent::common {

std::string svg_number(double x) {
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.2f", x);
    return buffer;
}

std::string svg_header(double width, double height) {
    std::ostringstream svg;
    svg << "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\""
        << height << "\" viewBox=\"0 0 " << width << ' ' << height
        << "\" font-family=\"sans-serif\" font-size=\"12\">\n"
        << "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
    return svg.str();
}

namespace {

std::string count_text(std::size_t n, const char* what) {
    return std::to_string(n) + " " + what + (n == 1 ? "" : "s");
}

void add_note(std::string& note, const std::string& more) {
    note += (note.empty() ? "" : "; ") + more;
}

// floor(log10(v)) robust to 10^k computed inexactly.
int decade_of(double v) { return int(std::floor(std::log10(v) + 1e-9)); }

// "0.25", "120", "-3"; exponent form ("2e-5", "1.5e6") for very small steps or large
// values. Digits as many as the step needs.
std::string linear_label(double v, double step) {
    if (std::fabs(v) < step * 1e-6) return "0";
    char text[48];
    const int step_decade = decade_of(step);
    if (step_decade < -4 || std::fabs(v) >= 1e6) {
        const int e = decade_of(std::fabs(v));
        const int digits = std::max(0, e - step_decade);
        std::snprintf(text, sizeof text, "%.*fe%d", digits, v / std::pow(10.0, e), e);
        return text;
    }
    std::snprintf(text, sizeof text, "%.*f", std::max(0, -step_decade), v);
    return text;
}

// A log axis's tick: 1, 2 or 5 times a power of ten: "0.001", "20", "1e-5", "5e6".
std::string log_label(double v) {
    const int e = decade_of(v);
    char text[48];
    if (e >= -3 && e <= 4)
        std::snprintf(text, sizeof text, "%.*f", std::max(0, -e), v);
    else
        std::snprintf(text, sizeof text, "%de%d", int(std::lround(v / std::pow(10.0, e))),
                      e);
    return text;
}

Axis linear_axis(std::vector<double> values, const AxisOptions& options,
                 std::string note) {
    Axis axis;
    axis.note = std::move(note);
    double lo = 0.0, hi = 1.0;
    if (!values.empty()) {
        lo = *std::min_element(values.begin(), values.end());
        hi = *std::max_element(values.begin(), values.end());
    }
    if (options.include_zero) lo = std::min(lo, 0.0), hi = std::max(hi, 0.0);
    if (hi - lo <= 1e-12 * std::max({1.0, std::fabs(lo), std::fabs(hi)})) {
        if (lo == 0.0) {
            hi = 1.0;
            if (!options.include_zero) lo = -1.0;
        } else {
            const double d = 0.1 * std::fabs(lo);
            lo -= d, hi += d;
            if (options.include_zero) lo = std::min(lo, 0.0), hi = std::max(hi, 0.0);
        }
    }
    const int max_ticks = std::max(options.max_ticks, 2);
    double step = nice_step((hi - lo) / double(max_ticks - 1));
    long first = 0, last = 0;
    for (;;) {
        first = long(std::floor(lo / step + 1e-9));
        last = long(std::ceil(hi / step - 1e-9));
        if (last - first + 1 <= max_ticks) break;
        step = nice_step(step * 1.01);
    }
    axis.lo = double(first) * step;
    axis.hi = double(last) * step;
    for (long k = first; k <= last; ++k) {
        axis.ticks.push_back(double(k) * step);
        axis.labels.push_back(linear_label(double(k) * step, step));
    }
    return axis;
}

Axis log_axis(const std::vector<double>& positive, std::string note) {
    Axis axis;
    axis.note = std::move(note);
    axis.log = true;
    const auto [min_it, max_it] = std::minmax_element(positive.begin(), positive.end());
    const int first = decade_of(*min_it);
    int last = int(std::ceil(std::log10(*max_it) - 1e-9));
    if (last <= first) last = first + 1;
    axis.lo = std::pow(10.0, first);
    axis.hi = std::pow(10.0, last);
    const int decades = last - first;
    const int every = std::max(1, int(std::ceil(decades / 6.0)));
    for (int e = first; e <= last; ++e) {
        const double decade = std::pow(10.0, e);
        if ((e - first) % every == 0) axis.ticks.push_back(decade);
        if (decades <= 2 && e < last)
            for (double m : {2.0, 5.0}) axis.ticks.push_back(m * decade);
    }
    std::sort(axis.ticks.begin(), axis.ticks.end());
    for (double t : axis.ticks) axis.labels.push_back(log_label(t));
    return axis;
}

}  // namespace

double nice_step(double raw) {
    if (!(raw > 0.0) || !std::isfinite(raw)) return 1.0;
    const double decade = std::pow(10.0, decade_of(raw));
    const double f = raw / decade;
    const double m = f <= 1.0 + 1e-9   ? 1.0
                     : f <= 2.0 + 1e-9 ? 2.0
                     : f <= 5.0 + 1e-9 ? 5.0
                                       : 10.0;
    return m * decade;
}

double Axis::fraction(double v) const {
    if (!log) return (v - lo) / (hi - lo);
    if (!(v > 0.0)) return NAN;
    return (std::log10(v) - std::log10(lo)) / (std::log10(hi) - std::log10(lo));
}

Axis choose_axis(const std::vector<double>& values, const AxisOptions& options) {
    std::vector<double> finite;
    std::size_t not_finite = 0;
    for (double v : values) std::isfinite(v) ? finite.push_back(v) : void(++not_finite);
    std::string note;
    if (not_finite)
        add_note(note, count_text(not_finite, "value") + " not finite left out");
    bool log = options.scale == AxisScale::log;
    if (options.scale == AxisScale::automatic && !finite.empty()) {
        const auto [lo, hi] = std::minmax_element(finite.begin(), finite.end());
        log = *lo > 0.0 && *hi / *lo > options.log_ratio;
    }
    if (log) {
        std::vector<double> positive;
        for (double v : finite)
            if (v > 0.0) positive.push_back(v);
        if (positive.size() < finite.size())
            add_note(note, count_text(finite.size() - positive.size(), "value") +
                               " <= 0 left out of the log axis");
        if (!positive.empty()) return log_axis(positive, note);
        add_note(note, "no positive value: linear axis");
    }
    return linear_axis(finite, options, note);
}

Axis fixed_axis(double lo, double hi, int max_ticks, bool integer_steps) {
    if (!(lo < hi) || !std::isfinite(lo) || !std::isfinite(hi))
        return choose_axis({lo, hi}, {AxisScale::linear, max_ticks});
    Axis axis;
    axis.lo = lo;
    axis.hi = hi;
    max_ticks = std::max(max_ticks, 2);
    double step = nice_step((hi - lo) / double(max_ticks - 1));
    if (integer_steps) step = std::max(step, 1.0);
    long first = 0, last = 0;
    for (;;) {
        first = long(std::ceil(lo / step - 1e-9));
        last = long(std::floor(hi / step + 1e-9));
        if (last - first + 1 <= max_ticks) break;
        step = nice_step(step * 1.01);
    }
    for (long k = first; k <= last; ++k) {
        axis.ticks.push_back(double(k) * step);
        axis.labels.push_back(linear_label(double(k) * step, step));
    }
    return axis;
}

namespace {

// Width of `text` in px at `font_size`, estimated on the wide side (sans-serif digits
// and lower case are about 0.55 em; 0.62 leaves room for wider letters).
double text_width(const std::string& text, double font_size) {
    std::size_t chars = 0;
    for (unsigned char c : text)
        if ((c & 0xC0) != 0x80) ++chars;
    return 0.62 * font_size * double(chars);
}

// A <text> at (x, y); squeezed into `room` px (textLength) when it may not fit.
// `extra`: more attributes (" transform=...").
void put_text(std::ostream& svg, double x, double y, const std::string& text,
              const char* anchor, double font_size, double room,
              const std::string& extra = "") {
    if (text.empty()) return;
    svg << "<text x=\"" << svg_number(x) << "\" y=\"" << svg_number(y)
        << "\" text-anchor=\"" << anchor << "\" font-size=\"" << font_size << '"';
    if (room > 0 && text_width(text, font_size) > room)
        svg << " textLength=\"" << svg_number(room)
            << "\" lengthAdjust=\"spacingAndGlyphs\"";
    svg << extra << '>' << markup_escape(text) << "</text>";
}

double widest_label(const Axis& axis, double font_size) {
    double w = 0.0;
    for (const auto& label : axis.labels) w = std::max(w, text_width(label, font_size));
    return w;
}

constexpr double kTickFont = 10, kLabelFont = 11, kTitleFont = 13, kNoteFont = 9;
constexpr const char* kBlue = "#1f77b4";

// Tableau's ten colours (as matplotlib's default cycle), the first being kBlue.
constexpr const char* kSeriesColours[] = {"#1f77b4", "#ff7f0e", "#2ca02c", "#d62728",
                                          "#9467bd", "#8c564b", "#e377c2", "#7f7f7f",
                                          "#bcbd22", "#17becf"};

// Each series as a line through its points with dots, then a legend (panel x0..x1, from
// legend_top down, two columns).
// A series behind the main curve: the colours after the main curve's blue, never it.
const char* behind_colour(std::size_t k) {
    return kSeriesColours[1 + k % (std::size(kSeriesColours) - 1)];
}

// Behind the main curve (PlotPanel::series_behind): the lines only, thin and faint, in
// the colours after the main curve's.
void draw_series_lines(std::ostringstream& svg, const std::vector<PlotSeries>& series,
                       const Axis& xa, const Axis& ya, double left, double right,
                       double top, double bottom) {
    const double plot_w = right - left, plot_h = bottom - top;
    for (std::size_t k = 0; k < series.size(); ++k) {
        const char* colour = behind_colour(k);
        std::string points;
        for (std::size_t i = 0; i < std::min(series[k].x.size(), series[k].y.size());
             ++i) {
            const double fx = xa.fraction(series[k].x[i]),
                         fy = ya.fraction(series[k].y[i]);
            if (!std::isfinite(fx) || !std::isfinite(fy)) continue;
            points += svg_number(left + plot_w * fx) + "," +
                      svg_number(bottom - plot_h * fy) + " ";
        }
        svg << "<polyline points=\"" << points << "\" fill=\"none\" stroke=\"" << colour
            << "\" stroke-width=\"1\" stroke-opacity=\"0.55\"/>\n";
    }
}

// The legend in two columns under the x axis's label: each label in its colour.
void draw_legend(std::ostringstream& svg, const std::vector<std::string>& labels,
                 const std::vector<const char*>& colours, double x0, double x1,
                 double legend_top) {
    const double row = 12, column_w = (x1 - x0 - 8) / 2;
    for (std::size_t k = 0; k < labels.size(); ++k) {
        const double x = x0 + 4 + column_w * double(k % 2),
                     y = legend_top + row * double(k / 2);
        svg << "<rect x=\"" << svg_number(x) << "\" y=\"" << svg_number(y + 2)
            << "\" width=\"10\" height=\"8\" fill=\"" << colours[k] << "\"/>";
        put_text(svg, x + 14, y + 9.5, labels[k], "start", kTickFont, column_w - 16);
    }
    svg << '\n';
}

void draw_series(std::ostringstream& svg, const std::vector<PlotSeries>& series,
                 const Axis& xa, const Axis& ya, double left, double right, double top,
                 double bottom, double x0, double x1, double legend_top) {
    if (series.empty()) return;
    const double plot_w = right - left, plot_h = bottom - top;
    for (std::size_t k = 0; k < series.size(); ++k) {
        const PlotSeries& s = series[k];
        const char* colour = kSeriesColours[k % std::size(kSeriesColours)];
        std::string points, dots;
        for (std::size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
            const double fx = xa.fraction(s.x[i]), fy = ya.fraction(s.y[i]);
            if (!std::isfinite(fx) || !std::isfinite(fy)) continue;
            const std::string x = svg_number(left + plot_w * fx),
                              y = svg_number(bottom - plot_h * fy);
            points += x + "," + y + " ";
            dots += "<circle cx=\"" + x + "\" cy=\"" + y + "\" r=\"3\" fill=\"" + colour +
                    "\"/>";
        }
        svg << "<polyline points=\"" << points << "\" fill=\"none\" stroke=\"" << colour
            << "\" stroke-width=\"1.5\"/>" << dots << '\n';
    }
    // The legend, in the room draw_panel left.
    std::vector<std::string> labels;
    std::vector<const char*> colours;
    for (std::size_t k = 0; k < series.size(); ++k) {
        labels.push_back(series[k].label);
        colours.push_back(kSeriesColours[k % std::size(kSeriesColours)]);
    }
    draw_legend(svg, labels, colours, x0, x1, legend_top);
}

void draw_panel(std::ostringstream& svg, double x0, double y0, double w, double h,
                const PlotPanel& p) {
    const bool categorical = !p.categories.empty();
    const std::size_t n =
        categorical ? p.categories.size() : std::min(p.x.size(), p.y.size());
    auto y_at = [&](const std::vector<double>& v, std::size_t i) {
        return i < v.size() ? v[i] : NAN;
    };
    std::vector<double> ys, xs;
    for (std::size_t i = 0; i < n; ++i) {
        ys.push_back(y_at(p.y, i));
        for (double e : {y_at(p.y_low, i), y_at(p.y_high, i)})
            if (std::isfinite(e)) ys.push_back(e);
        if (!categorical) xs.push_back(p.x[i]);
    }
    for (const PlotSeries& series : p.series)
        for (std::size_t i = 0; i < std::min(series.x.size(), series.y.size()); ++i) {
            xs.push_back(series.x[i]);
            ys.push_back(series.y[i]);
        }
    const Axis ya = p.fixed_y ? *p.fixed_y : choose_axis(ys, p.y_axis);
    const Axis xa = categorical ? Axis{} : choose_axis(xs, p.x_axis);
    std::string note = ya.note;
    if (!categorical && !xa.note.empty()) add_note(note, "x: " + xa.note);
    for (std::size_t i = 0; i < n; ++i) {
        const double ends[2] = {ya.fraction(y_at(p.y_low, i)),
                                ya.fraction(y_at(p.y_high, i))};
        if (std::isfinite(ends[0]) && std::isfinite(ends[1]) &&
            (ends[0] < 0.0 || ends[1] > 1.0)) {
            add_note(note, "\u25B2\u25BC: the interval goes on past the axis");
            break;
        }
    }

    const double y_label_room = p.y_label.empty() ? 0.0 : 18.0;
    const double left = x0 + 6 + y_label_room + widest_label(ya, kTickFont) + 6;
    const double last_x_label = categorical || xa.labels.empty()
                                    ? 0.0
                                    : text_width(xa.labels.back(), kTickFont) / 2;
    const double right = x0 + w - std::max(14.0, last_x_label + 4);
    const double top = y0 + (p.title.empty() ? 12.0 : 30.0);
    const std::size_t legend_rows = p.series.size() + (p.series_behind ? 1 : 0);
    const double legend_h = 12.0 * double((legend_rows + 1) / 2);
    const double bottom = y0 + h - 18 - (p.x_label.empty() ? 0.0 : 16.0) -
                          (note.empty() ? 0.0 : 13.0) - legend_h;
    const double plot_w = right - left, plot_h = bottom - top;
    const auto py = [&](double v) { return bottom - plot_h * ya.fraction(v); };
    const auto px = [&](std::size_t i) {
        return categorical ? left + plot_w * (double(i) + 0.5) / double(n)
                           : left + plot_w * xa.fraction(p.x[i]);
    };

    put_text(svg, x0 + w / 2, y0 + 18, p.title, "middle", kTitleFont, w - 8,
             " font-weight=\"bold\"");
    svg << '\n';
    // Grid and ticks.
    for (std::size_t t = 0; t < ya.ticks.size(); ++t) {
        const double y = py(ya.ticks[t]);
        svg << "<line x1=\"" << svg_number(left) << "\" y1=\"" << svg_number(y)
            << "\" x2=\"" << svg_number(right) << "\" y2=\"" << svg_number(y)
            << "\" stroke=\"#e4e4e4\"/>";
        put_text(svg, left - 4, y + 3.5, ya.labels[t], "end", kTickFont,
                 left - 4 - (x0 + 4 + y_label_room));
    }
    svg << '\n';
    if (categorical) {
        for (std::size_t i = 0; i < n; ++i)
            put_text(svg, px(i), bottom + 13, p.categories[i], "middle", kTickFont,
                     plot_w / double(n) - 2);
    } else {
        for (std::size_t t = 0; t < xa.ticks.size(); ++t) {
            const double x = left + plot_w * xa.fraction(xa.ticks[t]);
            svg << "<line x1=\"" << svg_number(x) << "\" y1=\"" << svg_number(top)
                << "\" x2=\"" << svg_number(x) << "\" y2=\"" << svg_number(bottom)
                << "\" stroke=\"#e4e4e4\"/>";
            put_text(svg, x, bottom + 13, xa.labels[t], "middle", kTickFont, 0);
        }
    }
    svg << "\n<line x1=\"" << svg_number(left) << "\" y1=\"" << svg_number(top)
        << "\" x2=\"" << svg_number(left) << "\" y2=\"" << svg_number(bottom)
        << "\" stroke=\"black\"/><line x1=\"" << svg_number(left) << "\" y1=\""
        << svg_number(bottom) << "\" x2=\"" << svg_number(right) << "\" y2=\""
        << svg_number(bottom) << "\" stroke=\"black\"/>\n";
    put_text(svg, (left + right) / 2, bottom + 29, p.x_label, "middle", kLabelFont,
             w - 8);
    const double yl_x = x0 + 14, yl_y = (top + bottom) / 2;
    put_text(
        svg, yl_x, yl_y, p.y_label, "middle", kLabelFont, plot_h,
        " transform=\"rotate(-90 " + svg_number(yl_x) + ' ' + svg_number(yl_y) + ")\"");
    put_text(svg, x0 + 4, y0 + h - 5, note, "start", kNoteFont, w - 8, " fill=\"#555\"");
    svg << '\n';

    if (p.series_behind)
        draw_series_lines(svg, p.series, xa, ya, left, right, top, bottom);
    // Intervals, clipped to the y axis with a triangle where they go on.
    const auto defined = [&](std::size_t i) {
        return std::isfinite(y_at(p.y, i)) && std::isfinite(ya.fraction(y_at(p.y, i))) &&
               (categorical || std::isfinite(xa.fraction(p.x[i])));
    };
    for (std::size_t i = 0; i < n; ++i) {
        const double low = y_at(p.y_low, i), high = y_at(p.y_high, i);
        if (!std::isfinite(low) || !std::isfinite(high)) continue;
        if (!categorical && !std::isfinite(xa.fraction(p.x[i]))) continue;
        const double x = px(i);
        const auto clipped = [&](double v) {
            const double f = ya.fraction(v);
            return std::isfinite(f) ? std::clamp(f, 0.0, 1.0) : 0.0;
        };
        const double y1 = bottom - plot_h * clipped(low),
                     y2 = bottom - plot_h * clipped(high);
        svg << "<line x1=\"" << svg_number(x) << "\" y1=\"" << svg_number(y1)
            << "\" x2=\"" << svg_number(x) << "\" y2=\"" << svg_number(y2)
            << "\" stroke=\"#444\"/>";
        for (const auto& [end, y] : {std::pair{low, y1}, std::pair{high, y2}}) {
            const double f = ya.fraction(end);
            if (std::isfinite(f) && f >= 0.0 && f <= 1.0)
                svg << "<line x1=\"" << svg_number(x - 6) << "\" y1=\"" << svg_number(y)
                    << "\" x2=\"" << svg_number(x + 6) << "\" y2=\"" << svg_number(y)
                    << "\" stroke=\"#444\"/>";
            else  // the interval goes on beyond the axis: a triangle pointing on
                svg << "<path d=\"M" << svg_number(x - 5) << ' '
                    << svg_number(y + (y == y1 ? -7 : 7)) << " L" << svg_number(x + 5)
                    << ' ' << svg_number(y + (y == y1 ? -7 : 7)) << " L" << svg_number(x)
                    << ' ' << svg_number(y) << " Z\" fill=\"#444\"/>";
        }
        svg << '\n';
    }
    if (p.join) {
        std::string points;
        for (std::size_t i = 0; i < n; ++i)
            if (defined(i))
                points += svg_number(px(i)) + "," + svg_number(py(p.y[i])) + " ";
        if (!points.empty())  // no empty <polyline> where nothing is defined
            svg << "<polyline points=\"" << points << "\" fill=\"none\" stroke=\""
                << kBlue << "\" stroke-width=\"" << (p.series_behind ? "2.5" : "1.5")
                << "\"/>\n";
    }
    for (std::size_t i = 0; i < n; ++i) {
        if (!defined(i)) continue;
        const double x = px(i), y = py(p.y[i]);
        const bool open = i < p.open_points.size() && p.open_points[i];
        svg << "<circle cx=\"" << svg_number(x) << "\" cy=\"" << svg_number(y)
            << "\" r=\"" << (categorical ? 4 : 3.5) << "\" fill=\""
            << (open ? "white" : kBlue) << "\""
            << (open ? std::string(" stroke=\"") + kBlue + "\" stroke-width=\"1.2\""
                     : std::string())
            << "/>";
        if (i < p.ringed_points.size() && p.ringed_points[i])
            svg << "<circle cx=\"" << svg_number(x) << "\" cy=\"" << svg_number(y)
                << "\" r=\"6.5\" fill=\"none\" stroke=\"#d62728\" stroke-width=\"1.2\"/>";
        if (i < p.point_labels.size()) {
            const bool to_left = x > left + 0.7 * plot_w;
            const double label_y = y - 6 < top + 2 ? y + 14 : y - 6;
            put_text(svg, to_left ? x - 5 : x + 5, label_y, p.point_labels[i],
                     to_left ? "end" : "start", kTickFont,
                     to_left ? x - 5 - (x0 + 2) : x0 + w - 2 - (x + 5));
        }
        svg << '\n';
    }
    const double legend_top = bottom + (p.x_label.empty() ? 18.0 : 34.0);
    if (!p.series_behind) {
        draw_series(svg, p.series, xa, ya, left, right, top, bottom, x0, x0 + w,
                    legend_top);
        return;
    }
    // The main curve first in the legend, in its blue; then the series' colours.
    std::vector<std::string> labels{p.main_label};
    std::vector<const char*> colours{kBlue};
    for (std::size_t k = 0; k < p.series.size(); ++k) {
        labels.push_back(p.series[k].label);
        colours.push_back(behind_colour(k));
    }
    draw_legend(svg, labels, colours, x0, x0 + w, legend_top);
}

}  // namespace

std::string figure_svg(const std::string& title, const std::vector<PlotPanel>& panels,
                       const FigureLayout& layout) {
    const std::size_t count = std::max<std::size_t>(panels.size(), 1);
    const std::size_t columns =
        std::min<std::size_t>(count, std::size_t(std::max(layout.max_columns, 1)));
    const std::size_t rows = (count + columns - 1) / columns;
    const double title_h = title.empty() ? 0.0 : 26.0;
    const double width = layout.panel_width * double(columns);
    std::ostringstream svg;
    svg << svg_header(width, title_h + layout.panel_height * double(rows));
    put_text(svg, width / 2, 18, title, "middle", 15, width - 8, " font-weight=\"bold\"");
    svg << '\n';
    for (std::size_t i = 0; i < panels.size(); ++i)
        draw_panel(svg, layout.panel_width * double(i % columns),
                   title_h + layout.panel_height * double(i / columns),
                   layout.panel_width, layout.panel_height, panels[i]);
    svg << "</svg>\n";
    return svg.str();
}

std::string histogram_svg(const std::string& title, const std::vector<double>& shares,
                          const std::string& x_label) {
    constexpr double kWidth = 200, kHeight = 124, kRight = 10, kTop = 22, kBottom = 30;
    double top_share = 0.0;
    for (double s : shares)
        if (std::isfinite(s)) top_share = std::max(top_share, s);
    Axis ya = choose_axis({100.0 * top_share}, {AxisScale::linear, 4, true});
    for (auto& label : ya.labels) label += "%";
    const Axis xa = fixed_axis(0.0, 1.0, 3);
    const double left = 6 + widest_label(ya, kTickFont) + 6;
    const double plot_w = kWidth - left - kRight, plot_h = kHeight - kTop - kBottom;
    const double bottom = kTop + plot_h;
    std::ostringstream svg;
    svg << svg_header(kWidth, kHeight);
    put_text(svg, kWidth / 2, 15, title, "middle", 11, kWidth - 8);
    svg << '\n';
    for (std::size_t t = 0; t < ya.ticks.size(); ++t) {
        const double y = bottom - plot_h * ya.fraction(ya.ticks[t]);
        svg << "<line x1=\"" << svg_number(left) << "\" y1=\"" << svg_number(y)
            << "\" x2=\"" << svg_number(left + plot_w) << "\" y2=\"" << svg_number(y)
            << "\" stroke=\"#e4e4e4\"/>";
        put_text(svg, left - 3, y + 3, ya.labels[t], "end", 9, left - 5);
    }
    const double bar_w = plot_w / double(std::max<std::size_t>(shares.size(), 1));
    for (std::size_t i = 0; i < shares.size(); ++i) {
        const double s = std::isfinite(shares[i]) ? std::max(shares[i], 0.0) : 0.0;
        const double bar_h = plot_h * ya.fraction(100.0 * s);
        svg << "<rect x=\"" << svg_number(left + bar_w * double(i)) << "\" y=\""
            << svg_number(bottom - bar_h) << "\" width=\"" << svg_number(bar_w * 0.9)
            << "\" height=\"" << svg_number(bar_h) << "\" fill=\"" << kBlue << "\"/>";
    }
    svg << "\n<line x1=\"" << svg_number(left) << "\" y1=\"" << svg_number(bottom)
        << "\" x2=\"" << svg_number(left + plot_w) << "\" y2=\"" << svg_number(bottom)
        << "\" stroke=\"black\"/><line x1=\"" << svg_number(left) << "\" y1=\""
        << svg_number(kTop) << "\" x2=\"" << svg_number(left) << "\" y2=\""
        << svg_number(bottom) << "\" stroke=\"black\"/>\n";
    for (std::size_t t = 0; t < xa.ticks.size(); ++t)
        put_text(svg, left + plot_w * xa.fraction(xa.ticks[t]), bottom + 11, xa.labels[t],
                 "middle", 9, 0);
    put_text(svg, left + plot_w / 2, kHeight - 5, x_label, "middle", 10, kWidth - 8);
    svg << "\n</svg>\n";
    return svg.str();
}

std::string level_values_svg(const std::string& title,
                             const std::vector<std::string>& levels,
                             const std::vector<double>& values,
                             const std::string& x_label) {
    PlotPanel panel;
    panel.title = title;
    panel.x_label = x_label;
    panel.categories = levels;
    panel.y = values;
    panel.y_axis = {AxisScale::linear, 4, false};
    return figure_svg("", {panel}, {240, 170, 1});
}

}  // namespace lucent::common

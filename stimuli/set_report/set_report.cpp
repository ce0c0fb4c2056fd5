// The stimulus-set report: read and check the manifest, measure every series' pairs of
// levels, then write the HTML page and the contact sheet.
// [SECTION] reading: the manifest (strict), the files it lists (present, unchanged)
// [SECTION] measuring: displayed pixels, object masks, Lab, luminance; series and pairs
// [SECTION] writing: report.html (self-contained) and contact-sheet.png
// [SECTION] the command
#include "stimuli/set_report/set_report.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <numeric>
#include <optional>
#include <set>
#include <sstream>

#include "common/content_hash.h"
#include "common/csv.h"
#include "common/html/html_page.h"
#include "common/html/svg_plot.h"
#include "common/number_text.h"
#include "common/output_file.h"
#include "common/srgb.h"
#include "renderer/core/display_transform.h"
#include "renderer/core/image.h"
#include "renderer/core/progress.h"
#include "stimuli/manifest.h"
#include "stimuli/set_report/contact_sheet.h"
#include "stimuli/set_report/ssim.h"

namespace lucent::stimuli {
namespace {

namespace fs = std::filesystem;
using common::markup_escape;

constexpr int kThumbnailSide = 160;

[[noreturn]] void fail(const std::string& message) { throw SetReportError(message); }

std::string cell(const std::map<std::string, std::string>& row,
                 const std::string& column) {
    const auto it = row.find(column);
    return it == row.end() ? std::string() : it->second;
}

std::string fixed(double value, int decimals) {
    if (!std::isfinite(value)) return "undefined";
    char text[32];
    std::snprintf(text, sizeof text, "%.*f", decimals, value);
    return text;
}

std::vector<std::string> split(const std::string& text, char separator) {
    std::vector<std::string> parts;
    std::size_t start = 0;
    while (start <= text.size()) {
        const std::size_t end = std::min(text.find(separator, start), text.size());
        parts.push_back(text.substr(start, end - start));
        start = end + 1;
    }
    return parts;
}

// ---- [SECTION] reading -------------------------------------------------------------

struct ManifestTable {
    std::vector<std::string> header;
    std::vector<std::map<std::string, std::string>> rows;  // file order
};

ManifestTable read_manifest_strictly(const fs::path& directory) {
    std::error_code error;
    if (!fs::is_directory(directory, error))
        fail(directory.string() +
             ": not a directory (give the --out DIR of 'lucent render')");
    const fs::path file = directory / "manifest.csv";
    if (!fs::is_regular_file(file, error))
        fail(file.string() +
             ": missing: not a Lucent stimulus set ('lucent render CONFIG --out DIR' "
             "writes "
             "one)");
    std::ifstream in(file, std::ios::binary);
    std::string line;
    if (!in || !std::getline(in, line)) fail(file.string() + ": cannot read, or empty");
    ManifestTable table;
    table.header = common::split_csv_line(line);
    for (const char* required : {"id", "file", "files", "technique", "width", "height",
                                 "object_pixels", "content_hash", "software_version"})
        if (std::find(table.header.begin(), table.header.end(), required) ==
            table.header.end())
            fail(file.string() + ": not a Lucent stimulus-set manifest (no column '" +
                 required + "')");
    std::set<std::string> ids;
    for (int number = 2; std::getline(in, line); ++number) {
        if (line.empty() || line == "\r") continue;
        const auto cells = common::split_csv_line(line);
        if (cells.size() != table.header.size())
            fail(file.string() + ":" + std::to_string(number) + ": " +
                 std::to_string(cells.size()) + " fields, the header has " +
                 std::to_string(table.header.size()));
        std::map<std::string, std::string> row;
        for (std::size_t c = 0; c < cells.size(); ++c) row[table.header[c]] = cells[c];
        if (row["id"].empty() || !ids.insert(row["id"]).second)
            fail(file.string() + ":" + std::to_string(number) + ": id: '" + row["id"] +
                 "' is empty or listed twice");
        table.rows.push_back(std::move(row));
    }
    if (table.rows.empty()) fail(file.string() + ": lists no stimuli");
    return table;
}

// The files of a row, each a plain name inside the directory, present and unchanged.
std::vector<fs::path> checked_files(const fs::path& directory,
                                    const std::map<std::string, std::string>& row) {
    const std::string manifest = (directory / "manifest.csv").string();
    std::vector<fs::path> files;
    for (const std::string& name : split(cell(row, "files"), ';')) {
        if (name.empty()) continue;
        const fs::path relative(name);
        if (relative.filename() != relative || name == "." || name == "..")
            fail(manifest + ": stimulus '" + cell(row, "id") + "': files: '" + name +
                 "' is not a file name inside " + directory.string());
        const fs::path path = directory / relative;
        std::error_code error;
        if (!fs::is_regular_file(path, error))
            fail(path.string() + ": missing (listed in " + manifest + ")");
        files.push_back(path);
    }
    if (files.empty())
        fail(manifest + ": stimulus '" + cell(row, "id") + "' lists no files");
    // The content hash as the batch renderer computes it: each file's hash as a field.
    common::ContentHash hasher;
    for (const auto& path : files) {
        try {
            hasher.field(common::hash_file(path));
        } catch (const std::runtime_error& e) {
            fail(e.what());  // "PATH: cannot read"
        }
    }
    if (hasher.hex() != cell(row, "content_hash")) {
        std::string names;
        for (const auto& path : files)
            names += (names.empty() ? "" : ", ") + path.string();
        fail(names + ": changed since " + manifest + " was written (content hash " +
             hasher.hex() + ", listed " + cell(row, "content_hash") + ")");
    }
    return files;
}

// The file that is measured: the PNG (what participants see), else TIFF, else EXR.
fs::path displayed_file(const std::vector<fs::path>& files) {
    for (const char* wanted : {".png", ".tif", ".tiff", ".exr"})
        for (const auto& file : files) {
            std::string ext = file.extension().string();
            std::transform(ext.begin(), ext.end(), ext.begin(),
                           [](unsigned char c) { return char(std::tolower(c)); });
            if (ext == wanted) return file;
        }
    return files.front();
}

// ---- [SECTION] measuring -----------------------------------------------------------

// One stimulus as displayed: sRGB-encoded RGB, its object mask and a hash of the pixels.
struct Displayed {
    int width = 0, height = 0;
    std::vector<float> rgb;
    std::vector<std::uint8_t> mask;
    std::string pixel_hash;
};

Displayed decode(const fs::path& file, const std::string& background) {
    Image image;
    try {
        image = read_image(file);
    } catch (const std::exception& e) {
        fail(e.what());
    }
    std::string ext = file.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    const bool linear_with_alpha = ext == ".exr";
    // The background as the file stores it (PNG/TIFF: sRGB-encoded linear knob value).
    float encoded_background[3] = {0, 0, 0};
    const auto parts = split(background, ',');
    for (int c = 0; c < 3; ++c)
        if (parts.size() == 3)
            if (const auto v = common::parse_finite(parts[std::size_t(c)]))
                encoded_background[c] = display_value(float(*v));
    Displayed out;
    out.width = image.width;
    out.height = image.height;
    const std::size_t n = std::size_t(image.width) * image.height;
    out.rgb.resize(n * 3);
    out.mask.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
        bool object = false;
        for (int c = 0; c < 3; ++c) {
            float v = image.rgba[i * 4 + c];
            if (!std::isfinite(v)) v = 0.0f;
            v = linear_with_alpha ? display_value(v) : std::clamp(v, 0.0f, 1.0f);
            out.rgb[i * 3 + c] = v;
            object |= std::fabs(v - encoded_background[c]) > 0.5f / 255.0f;
        }
        out.mask[i] = linear_with_alpha ? image.rgba[i * 4 + 3] > 0.5f : object;
    }
    common::ContentHash hasher;
    hasher.field(std::to_string(out.width) + "x" + std::to_string(out.height));
    for (float v : out.rgb) hasher.word(std::uint32_t(std::lround(double(v) * 65535.0)));
    out.pixel_hash = hasher.hex();
    return out;
}

// What the pair measurements need of one stimulus.
struct Measured {
    Displayed displayed;
    std::vector<Lab> lab;
    std::vector<double> luminance;  // Rec. 709 Y of the decoded (linear) values
};

Measured measure(Displayed displayed, const SrgbToLab& to_lab) {
    Measured m;
    m.lab = to_lab.convert(displayed.rgb);
    const std::size_t n = displayed.mask.size();
    m.luminance.resize(n);
    for (std::size_t i = 0; i < n; ++i)
        m.luminance[i] = 0.2126 * common::srgb_decode(displayed.rgb[i * 3]) +
                         0.7152 * common::srgb_decode(displayed.rgb[i * 3 + 1]) +
                         0.0722 * common::srgb_decode(displayed.rgb[i * 3 + 2]);
    m.displayed = std::move(displayed);
    return m;
}

// Parameter columns: between `height` and `object_pixels` (the batch renderer's layout).
std::vector<std::string> parameter_columns(const std::vector<std::string>& header) {
    const auto begin = std::find(header.begin(), header.end(), "height");
    const auto end = std::find(header.begin(), header.end(), "object_pixels");
    if (begin == header.end() || end <= begin) return {};
    return std::vector<std::string>(begin + 1, end);
}

void build_series(SetReport& report, const std::vector<std::string>& header) {
    std::vector<std::string> candidates = {"technique", "mesh"};
    for (const auto& column : parameter_columns(header)) candidates.push_back(column);
    for (std::size_t i = 0; i < report.stimuli.size(); ++i) {
        const std::string& name = report.stimuli[i].series;
        if (name.empty()) continue;
        auto it = std::find_if(report.series.begin(), report.series.end(),
                               [&](const ReportSeries& s) { return s.name == name; });
        if (it == report.series.end()) {
            report.series.push_back({name, {}, {}});
            it = report.series.end() - 1;
        }
        it->members.push_back(i);
    }
    for (auto& series : report.series) {
        for (const auto& column : candidates) {
            std::set<std::string> values;
            for (std::size_t m : series.members)
                values.insert(cell(report.stimuli[m].cells, column));
            if (values.size() > 1) series.varying.push_back(column);
        }
        // Level order: by value when one numeric parameter varies, else set order.
        if (series.varying.size() == 1) {
            const std::string& column = series.varying.front();
            bool numeric = true;
            for (std::size_t m : series.members)
                numeric &= common::parse_finite(cell(report.stimuli[m].cells, column))
                               .has_value();
            if (numeric)
                std::stable_sort(series.members.begin(), series.members.end(),
                                 [&](std::size_t a, std::size_t b) {
                                     return *common::parse_finite(
                                                cell(report.stimuli[a].cells, column)) <
                                            *common::parse_finite(
                                                cell(report.stimuli[b].cells, column));
                                 });
        }
        for (std::size_t m : series.members) {
            std::string level;
            for (const auto& column : series.varying) {
                const std::string value = cell(report.stimuli[m].cells, column);
                if (value.empty()) continue;  // a parameter this technique lacks
                level += (level.empty() ? "" : ", ") + column + "=" + value;
            }
            report.stimuli[m].level = level;
        }
    }
}

// Every pair (a, b), a < b, of n levels in order.
std::vector<std::pair<std::size_t, std::size_t>> all_pairs(std::size_t n) {
    std::vector<std::pair<std::size_t, std::size_t>> pairs;
    for (std::size_t a = 0; a < n; ++a)
        for (std::size_t b = a + 1; b < n; ++b) pairs.emplace_back(a, b);
    return pairs;
}

// The neighbouring levels of a large series, as positions in level order (a < b, sorted):
// each level and the next; and where several parameters vary (a grid), for each of them
// the levels that share every other varying value, ordered by that parameter (by value
// when all are numbers, else in level order), each with the next. O(n log n) pairs.
std::vector<std::pair<std::size_t, std::size_t>> neighbour_pairs(
    const SetReport& report, const ReportSeries& series) {
    const std::size_t n = series.members.size();
    std::set<std::pair<std::size_t, std::size_t>> pairs;
    for (std::size_t a = 0; a + 1 < n; ++a) pairs.emplace(a, a + 1);
    if (series.varying.size() >= 2) {
        for (std::size_t along = 0; along < series.varying.size(); ++along) {
            const std::string& column = series.varying[along];
            std::map<std::string, std::vector<std::size_t>> lines;  // the others' values
            for (std::size_t position = 0; position < n; ++position) {
                const auto& cells = report.stimuli[series.members[position]].cells;
                std::string key;
                for (std::size_t v = 0; v < series.varying.size(); ++v)
                    if (v != along) key += cell(cells, series.varying[v]) + '\x1f';
                lines[key].push_back(position);
            }
            for (auto& [key, line] : lines) {
                bool numeric = true;
                for (std::size_t position : line)
                    numeric &=
                        common::parse_finite(
                            cell(report.stimuli[series.members[position]].cells, column))
                            .has_value();
                if (numeric)
                    std::stable_sort(
                        line.begin(), line.end(), [&](std::size_t a, std::size_t b) {
                            return *common::parse_finite(cell(
                                       report.stimuli[series.members[a]].cells, column)) <
                                   *common::parse_finite(cell(
                                       report.stimuli[series.members[b]].cells, column));
                        });
                for (std::size_t k = 0; k + 1 < line.size(); ++k)
                    pairs.emplace(std::min(line[k], line[k + 1]),
                                  std::max(line[k], line[k + 1]));
            }
        }
    }
    return {pairs.begin(), pairs.end()};
}

std::string set_name_of(const fs::path& directory) {
    // manifest.json's "set" value; the folder's name when it has none.
    std::ifstream in(directory / "manifest.json", std::ios::binary);
    std::string text((std::istreambuf_iterator<char>(in)),
                     std::istreambuf_iterator<char>());
    const std::string key = "\"set\": \"";
    const auto start = text.find(key);
    if (start != std::string::npos) {
        const auto end = text.find('"', start + key.size());
        if (end != std::string::npos)
            return text.substr(start + key.size(), end - start - key.size());
    }
    return fs::absolute(directory).lexically_normal().filename().string();
}

}  // namespace

SetReport measure_stimulus_set(const fs::path& directory,
                               const SetReportOptions& options) {
    if (!(options.min_delta_e >= 0.0) || !std::isfinite(options.min_delta_e))
        fail("--min-delta-e: " + std::to_string(options.min_delta_e) +
             " is not a non-negative number");
    const ManifestTable table = read_manifest_strictly(directory);
    SetReport report;
    report.directory = directory;
    report.min_delta_e = options.min_delta_e;
    report.set_name = set_name_of(directory);

    // Every listed file first, so that a bad set is refused before any decoding.
    std::vector<fs::path> images;
    for (const auto& row : table.rows)
        images.push_back(displayed_file(checked_files(directory, row)));
    for (std::size_t i = 0; i < table.rows.size(); ++i) {
        const auto& row = table.rows[i];
        report.stimuli.push_back({cell(row, "id"),
                                  cell(row, "technique"),
                                  cell(row, "series"),
                                  images[i],
                                  row,
                                  "",
                                  {}});
    }
    build_series(report, table.header);

    // Each stimulus once: thumbnail and pixel hash for all; Lab and luminance per series
    // (kept only while its pairs are measured).
    const SrgbToLab to_lab;
    std::vector<std::string> pixel_hashes(report.stimuli.size());
    std::vector<std::size_t> series_of(report.stimuli.size(), report.series.size());
    for (std::size_t s = 0; s < report.series.size(); ++s)
        for (std::size_t m : report.series[s].members) series_of[m] = s;
    for (std::size_t i = 0; i < report.stimuli.size(); ++i) {
        if (series_of[i] != report.series.size()) continue;  // measured with its series
        auto& stimulus = report.stimuli[i];
        const Displayed d = decode(stimulus.image, cell(stimulus.cells, "background"));
        stimulus.thumbnail = make_thumbnail(d.rgb, d.width, d.height, kThumbnailSide);
        pixel_hashes[i] = d.pixel_hash;
    }
    // The pairs each series compares (positions in level order, (a, b) with a < b), all
    // counted first for the progress callback.
    std::vector<std::vector<std::pair<std::size_t, std::size_t>>> compared;
    std::size_t total_pairs = 0;
    for (auto& series : report.series) {
        const std::size_t n = series.members.size();
        series.pairs_possible = n * (n - 1) / 2;
        series.all_pairs = n <= options.all_pairs_up_to;
        compared.push_back(series.all_pairs ? all_pairs(n)
                                            : neighbour_pairs(report, series));
        total_pairs += compared.back().size();
    }
    std::size_t pairs_done = 0;
    for (std::size_t s = 0; s < report.series.size(); ++s) {
        const ReportSeries& series = report.series[s];
        const auto& pairs = compared[s];
        const std::size_t n = series.members.size();
        // Each member is measured when the first pair needing it comes up (in order of
        // its later member) and released after its last pair: a grid compared on
        // neighbours holds about one row of measurements, not the whole series.
        std::vector<std::size_t> last_use(n, 0);
        std::vector<std::vector<std::size_t>> ending_at(
            n);  // pairs by their later member
        for (std::size_t k = 0; k < pairs.size(); ++k) {
            last_use[pairs[k].first] =
                std::max(last_use[pairs[k].first], pairs[k].second);
            last_use[pairs[k].second] =
                std::max(last_use[pairs[k].second], pairs[k].second);
            ending_at[pairs[k].second].push_back(k);
        }
        std::vector<std::optional<Measured>> measured(n);
        struct Outcome {
            std::optional<PairDifference> pair;
            std::string warning;
        };
        std::vector<Outcome> outcomes(pairs.size());
        for (std::size_t position = 0; position < n; ++position) {
            auto& stimulus = report.stimuli[series.members[position]];
            Displayed d = decode(stimulus.image, cell(stimulus.cells, "background"));
            stimulus.thumbnail = make_thumbnail(d.rgb, d.width, d.height, kThumbnailSide);
            pixel_hashes[series.members[position]] = d.pixel_hash;
            measured[position] = measure(std::move(d), to_lab);
            for (std::size_t k : ending_at[position]) {
                const auto [a, b] = pairs[k];
                const Measured &x = *measured[a], &y = *measured[b];
                PairDifference pair;
                pair.series = series.name;
                pair.first = series.members[a];
                pair.second = series.members[b];
                pair.adjacent = !series.all_pairs || b == a + 1;
                const std::string names = "series '" + series.name +
                                          "': " + report.stimuli[pair.first].id + " vs " +
                                          report.stimuli[pair.second].id;
                if (x.displayed.width != y.displayed.width ||
                    x.displayed.height != y.displayed.height) {
                    outcomes[k].warning =
                        names + ": images of different sizes, not compared";
                } else {
                    // Object pixels of either image: a level that grows the object
                    // counts.
                    std::vector<std::uint8_t> mask(x.displayed.mask.size());
                    for (std::size_t i = 0; i < mask.size(); ++i)
                        mask[i] = x.displayed.mask[i] || y.displayed.mask[i];
                    pair.delta_e = delta_e_statistics(x.lab, y.lab, mask);
                    pair.ssim =
                        ssim({x.displayed.width, x.displayed.height, x.luminance},
                             {y.displayed.width, y.displayed.height, y.luminance}, mask);
                    pair.identical = x.displayed.pixel_hash == y.displayed.pixel_hash;
                    if (pair.delta_e.mean < options.min_delta_e)
                        outcomes[k].warning = names + ": mean Delta E00 " +
                                              fixed(pair.delta_e.mean, 2) + " is below " +
                                              fixed(options.min_delta_e, 2) +
                                              (pair.adjacent ? " (adjacent levels)" : "");
                    outcomes[k].pair = pair;
                }
                if (options.on_pair) options.on_pair(++pairs_done, total_pairs);
            }
            for (std::size_t m = 0; m <= position; ++m)
                if (measured[m] && last_use[m] <= position) measured[m].reset();
        }
        // In (a, b) order, as the page lists them.
        for (const Outcome& o : outcomes) {
            if (!o.warning.empty()) report.warnings.push_back(o.warning);
            if (o.pair) report.pairs.push_back(*o.pair);
        }
    }

    // Identical pictures anywhere in the set: each stimulus is meant to be its own image.
    std::map<std::string, std::vector<std::size_t>> by_pixels;
    for (std::size_t i = 0; i < report.stimuli.size(); ++i)
        by_pixels[pixel_hashes[i]].push_back(i);
    std::vector<std::vector<std::size_t>> groups;
    for (auto& [hash, members] : by_pixels)
        if (members.size() > 1) groups.push_back(members);
    std::sort(groups.begin(), groups.end());
    for (const auto& members : groups) {
        std::string names;
        for (std::size_t k = 0; k < members.size(); ++k)
            names += std::string(k == 0                    ? ""
                                 : k + 1 == members.size() ? " and "
                                                           : ", ") +
                     report.stimuli[members[k]].id;
        report.warnings.push_back(
            names + " are identical images (separate stimuli, meant to differ)");
    }
    return report;
}

namespace {

// ---- [SECTION] writing -------------------------------------------------------------

// id, technique, then one line per varying parameter (but the technique).
std::vector<std::string> label_of(const ReportStimulus& s) {
    std::vector<std::string> lines = {s.id, s.technique};
    if (s.level.empty()) return lines;
    for (std::size_t start = 0; start <= s.level.size();) {
        const std::size_t end = std::min(s.level.find(", ", start), s.level.size());
        const std::string part = s.level.substr(start, end - start);
        if (part.rfind("technique=", 0) != 0) lines.push_back(part);  // the line above
        start = end + 2;
    }
    return lines;
}

// The groups of the sheet: each series in level order, then the stimuli of none.
std::vector<std::pair<std::string, std::vector<std::size_t>>> sheet_groups(
    const SetReport& r) {
    std::vector<std::pair<std::string, std::vector<std::size_t>>> groups;
    std::vector<bool> placed(r.stimuli.size(), false);
    for (const auto& series : r.series) {
        std::string heading = "series " + series.name;
        if (!series.varying.empty()) {
            heading += " (varies: ";
            for (std::size_t k = 0; k < series.varying.size(); ++k)
                heading += (k ? ", " : "") + series.varying[k];
            heading += ")";
        }
        groups.emplace_back(heading, series.members);
        for (std::size_t m : series.members) placed[m] = true;
    }
    std::vector<std::size_t> rest;
    for (std::size_t i = 0; i < r.stimuli.size(); ++i)
        if (!placed[i]) rest.push_back(i);
    if (!rest.empty())
        groups.emplace_back(r.series.empty() ? "stimuli" : "other stimuli", rest);
    return groups;
}

double statistic(const ReportStimulus& s, const std::string& column) {
    return common::parse_finite(cell(s.cells, column)).value_or(NAN);
}

// The luminance histogram as shares of the object's pixels.
std::vector<double> histogram_shares(const ReportStimulus& s) {
    std::vector<double> counts;
    for (int bin = 0;; ++bin) {
        char column[16];
        std::snprintf(column, sizeof column, "hist_%02d", bin);
        if (!s.cells.count(column)) break;
        counts.push_back(common::parse_finite(cell(s.cells, column)).value_or(0.0));
    }
    const double total = std::accumulate(counts.begin(), counts.end(), 0.0);
    for (double& c : counts) c = total > 0.0 ? c / total : 0.0;
    return counts;
}

void write_html(std::ostream& out, const SetReport& r) {
    out << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>Stimulus set "
        << markup_escape(r.set_name) << "</title>\n<style>"
        << "body{font-family:sans-serif;max-width:80em;margin:auto;padding:0 1em}"
        << "figure{display:inline-block;margin:.4em;vertical-align:top;width:170px}"
        << "figure img{background:#292929;display:block}"
        << "figcaption{font-size:.8em;overflow-wrap:anywhere}"
        << "table{border-collapse:collapse;margin:.5em 0}td,th{border:1px solid #ccc;"
        << "padding:.2em "
           ".5em;text-align:right}td:first-child,th:first-child{text-align:left}"
        << ".warn{color:#a00}.plots svg{margin:.2em}</style>\n"
        // Marks the page once every picture has decoded, for headless-browser checks.
        << common::images_drawn_script() << "</head><body>\n";
    out << "<h1>Stimulus set " << markup_escape(r.set_name) << "</h1>\n<p>"
        << r.stimuli.size() << " stimuli from <code>"
        << markup_escape((r.directory / "manifest.csv").string())
        << "</code>, rendered by lucent "
        << markup_escape(cell(r.stimuli.front().cells, "software_version"))
        << ". Differences "
        << "are CIEDE2000 between the images as displayed (sRGB, littleCMS) over the "
           "pixels "
        << "of either object, and SSIM of luminance (11x11 Gaussian window).</p>\n";

    out << "<h2>Warnings</h2>\n";
    if (r.warnings.empty())
        out << "<p>None: every pair of levels differs by a mean Delta E00 of at least "
            << fixed(r.min_delta_e, 2) << " and no two stimuli are the same image.</p>\n";
    else {
        out << "<ul>\n";
        for (const auto& w : r.warnings)
            out << "<li class=\"warn\">" << markup_escape(w) << "</li>\n";
        out << "</ul>\n";
    }

    out << "<h2>Contact sheet</h2>\n<p>Also as <a "
           "href=\"contact-sheet.png\">contact-sheet.png"
        << "</a>.</p>\n";
    for (const auto& [heading, members] : sheet_groups(r)) {
        out << "<h3>" << markup_escape(heading) << "</h3>\n<div>";
        for (std::size_t m : members) {
            const auto& s = r.stimuli[m];
            out << "<figure><img width=\"" << s.thumbnail.width << "\" height=\""
                << s.thumbnail.height << "\" alt=\"" << markup_escape(s.id)
                << "\" src=\"data:image/png;base64,"
                << common::base64_encode(thumbnail_png(s.thumbnail)) << "\"><figcaption>";
            const auto lines = label_of(s);
            for (std::size_t k = 0; k < lines.size(); ++k)
                out << (k ? "<br>" : "<b>") << markup_escape(lines[k])
                    << (k ? "" : "</b>");
            out << "</figcaption></figure>";
        }
        out << "</div>\n";
    }

    out << "<h2>Differences between levels</h2>\n";
    if (r.series.empty())
        out << "<p>The manifest names no factor series (column "
               "<code>series</code>).</p>\n";
    for (const auto& series : r.series) {
        out << "<h3>Series " << markup_escape(series.name) << "</h3>\n";
        if (!series.all_pairs) {
            std::size_t compared = 0;
            for (const auto& p : r.pairs) compared += p.series == series.name;
            out << "<p>" << series.members.size()
                << " levels: neighbouring levels compared (" << compared << " of "
                << series.pairs_possible
                << " pairs): each level and the next, and where several parameters vary, "
                << "the next value of each with the others equal.</p>\n";
        }
        out << "<table><tr><th>pair</th><th>levels</th><th>mean &Delta;E00</th>"
            << "<th>95th percentile</th><th>share &gt; 1</th><th>SSIM</th><th>pixels</th>"
            << "<th></th></tr>\n";
        for (const auto& p : r.pairs) {
            if (p.series != series.name) continue;
            const auto &a = r.stimuli[p.first], &b = r.stimuli[p.second];
            const bool low = p.delta_e.mean < r.min_delta_e;
            out << "<tr" << (low ? " class=\"warn\"" : "") << "><td>"
                << markup_escape(a.id) << " vs " << markup_escape(b.id)
                << (p.adjacent ? " (adjacent)" : "") << "</td><td>"
                << markup_escape(a.level) << " / " << markup_escape(b.level)
                << "</td><td>" << fixed(p.delta_e.mean, 2) << "</td><td>"
                << fixed(p.delta_e.percentile_95, 2) << "</td><td>"
                << fixed(100.0 * p.delta_e.share_above_1, 1) << "%</td><td>"
                << fixed(p.ssim, 4) << "</td><td>" << p.delta_e.pixels << "</td><td>"
                << (p.identical ? "identical"
                    : low       ? "below threshold"
                                : "")
                << "</td></tr>\n";
        }
        out << "</table>\n<div class=\"plots\">";
        // Tick labels: the value of the one varying parameter, else the technique, else
        // the id; the axis names what varies.
        const bool technique_varies =
            std::find(series.varying.begin(), series.varying.end(), "technique") !=
            series.varying.end();
        std::vector<std::string> levels;
        for (std::size_t m : series.members)
            levels.push_back(series.varying.size() == 1
                                 ? cell(r.stimuli[m].cells, series.varying.front())
                             : technique_varies ? r.stimuli[m].technique
                                                : r.stimuli[m].id);
        const std::string axis = series.varying.size() == 1 ? series.varying.front()
                                 : technique_varies         ? "technique"
                                                            : "stimulus";
        for (const auto& [column, title] :
             std::vector<std::pair<std::string, std::string>>{
                 {"mean_luminance", "mean luminance"},
                 {"rms_contrast", "RMS contrast"},
                 {"skewness", "skewness"},
                 {"saturation_intensity_correlation", "saturation-intensity r"}}) {
            std::vector<double> values;
            for (std::size_t m : series.members)
                values.push_back(statistic(r.stimuli[m], column));
            out << common::level_values_svg(title, levels, values, axis);
        }
        out << "</div>\n";
    }

    out << "<h2>Image statistics per stimulus</h2>\n<p>From the manifest: over the "
           "object's "
        << "pixels of the linear image (stimuli/README.md).</p>\n";
    out << "<table><tr><th>stimulus</th><th>object pixels</th><th>mean luminance</th>"
        << "<th>RMS contrast</th><th>skewness</th><th>saturation-intensity r</th>"
        << "<th>luminance histogram</th></tr>\n";
    for (const auto& s : r.stimuli) {
        out << "<tr><td>" << markup_escape(s.id) << "</td><td>"
            << markup_escape(cell(s.cells, "object_pixels")) << "</td>";
        for (const char* column : {"mean_luminance", "rms_contrast", "skewness",
                                   "saturation_intensity_correlation"})
            out << "<td>" << fixed(statistic(s, column), 3) << "</td>";
        out << "<td>" << common::histogram_svg(s.id, histogram_shares(s))
            << "</td></tr>\n";
    }
    out << "</table>\n</body></html>\n";
}

}  // namespace

std::vector<fs::path> write_set_report(const SetReport& report) {
    const fs::path html = report.directory / "report.html";
    const fs::path sheet = report.directory / "contact-sheet.png";
    if (contact_sheet_font().empty())
        fail(sheet.string() +
             ": no font to label the contact sheet "
             "(/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf, Debian package "
             "fonts-dejavu-core)");
    std::vector<fs::path> inputs = {report.directory / "manifest.csv",
                                    report.directory / "manifest.json"};
    for (const auto& s : report.stimuli) inputs.push_back(s.image);
    try {
        common::check_output_file(html, inputs, true);
        common::check_output_file(sheet, inputs, true);
    } catch (const common::OutputError& e) {
        fail(e.what());
    }
    std::vector<ContactSheetGroup> groups;
    for (const auto& [heading, members] : sheet_groups(report)) {
        ContactSheetGroup group{heading, {}};
        for (std::size_t m : members)
            group.cells.push_back(
                {&report.stimuli[m].thumbnail, label_of(report.stimuli[m])});
        groups.push_back(std::move(group));
    }
    write_contact_sheet(sheet, groups);
    common::write_file_atomically(html, true,
                                  [&](std::ostream& out) { write_html(out, report); });
    return {html, sheet};
}

// ---- [SECTION] the command ---------------------------------------------------------

int run_stimuli_report(const fs::path& directory, const SetReportOptions& options,
                       const std::string& command) {
    // Measuring and writing share one try: an error in either is said the same way.
    try {
        // Progress: one line first when the comparisons are many (logs see it too), then
        // the shared bar on a terminal once the work has run half a second.
        std::unique_ptr<ProgressBar> bar;
        SetReportOptions with_progress = options;
        with_progress.on_pair = [&](std::size_t done, std::size_t total) {
            if (options.on_pair) options.on_pair(done, total);
            if (!bar) {
                if (total > 100)
                    std::cerr << command << ": report: comparing " << total
                              << " pairs of levels\n";
                bar = std::make_unique<ProgressBar>(command + ": report", total);
            }
            bar->update(done);
            if (done == total) bar->finish();
        };
        const SetReport report = measure_stimulus_set(directory, with_progress);
        bar.reset();
        for (const auto& warning : report.warnings)
            std::cerr << command << ": warning: " << warning << "\n";
        for (const auto& file : write_set_report(report))
            std::cout << "wrote " << file.string() << "\n";
    } catch (const SetReportError& e) {
        std::cerr << command << ": " << e.what() << "\n";
        return 2;
    } catch (const std::exception& e) {
        std::cerr << command << ": " << e.what() << "\n";
        return 1;
    }
    return 0;
}

}  // namespace lucent::stimuli

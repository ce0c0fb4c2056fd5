#include "stimuli/manifest.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "common/csv.h"
#include "common/number_text.h"
#include "common/output_file.h"
#include "lucent/version.h"

namespace lucent::stimuli {
namespace {

std::string number(double value) {
    if (!std::isfinite(value)) value = 0.0;  // never let NaN/Inf into a table
    return common::nine_digit_text(value);
}

std::string json_escape(std::string_view text) {
    std::string out;
    for (char c : text) {
        switch (c) {
            case '"':
                out += "\\\"";
                break;
            case '\\':
                out += "\\\\";
                break;
            case '\n':
                out += "\\n";
                break;
            case '\r':
                out += "\\r";
                break;
            case '\t':
                out += "\\t";
                break;
            default:
                if (static_cast<unsigned char>(c) < 0x20) {
                    char code[8];
                    std::snprintf(code, sizeof code, "\\u%04x", c);
                    out += code;
                } else {
                    out += c;
                }
        }
    }
    return out;
}

void write_atomically(const std::filesystem::path& path, const std::string& text) {
    common::write_file_atomically(path, true, [&](std::ostream& out) { out << text; });
}

}  // namespace

std::vector<ManifestField> statistics_fields(const ImageStatistics& stats) {
    std::vector<ManifestField> fields = {
        {"object_pixels", std::to_string(stats.object_pixels), true},
        {"mean_luminance", number(stats.mean_luminance), true},
        {"sd_luminance", number(stats.sd_luminance), true},
        {"rms_contrast", number(stats.rms_contrast), true},
        {"skewness", number(stats.skewness), true},
        {"saturation_intensity_correlation",
         number(stats.saturation_intensity_correlation), true},
    };
    for (std::size_t bin = 0; bin < stats.luminance_histogram.size(); ++bin) {
        char column[32];
        std::snprintf(column, sizeof column, "hist_%02zu", bin);
        fields.push_back({column, std::to_string(stats.luminance_histogram[bin]), true});
    }
    return fields;
}

void write_manifest(const std::filesystem::path& dir, std::string_view set_name,
                    std::span<const ManifestRow> rows) {
    // The header: every column in first-seen order.
    std::vector<std::string> columns;
    for (const auto& row : rows)
        for (const auto& field : row)
            if (std::find(columns.begin(), columns.end(), field.column) == columns.end())
                columns.push_back(field.column);

    std::ostringstream csv;
    for (std::size_t c = 0; c < columns.size(); ++c)
        csv << (c ? "," : "") << common::csv_field(columns[c]);
    csv << "\n";
    for (const auto& row : rows) {
        for (std::size_t c = 0; c < columns.size(); ++c) {
            if (c) csv << ",";
            for (const auto& field : row)
                if (field.column == columns[c]) csv << common::csv_field(field.text);
        }
        csv << "\n";
    }

    std::ostringstream json;
    json << "{\n  \"set\": \"" << json_escape(set_name)
         << "\",\n  \"software_version\": \"" << json_escape(version_string())
         << "\",\n  \"build_hash\": \"" << json_escape(build_hash())
         << "\",\n  \"stimuli\": [";
    for (std::size_t r = 0; r < rows.size(); ++r) {
        json << (r ? ",\n" : "\n") << "    {";
        for (std::size_t f = 0; f < rows[r].size(); ++f) {
            const auto& field = rows[r][f];
            json << (f ? ", " : "") << "\"" << json_escape(field.column) << "\": ";
            if (field.text.empty())
                json << "null";  // a parameter this technique lacks
            else if (field.numeric)
                json << field.text;
            else
                json << "\"" << json_escape(field.text) << "\"";
        }
        json << "}";
    }
    json << "\n  ]\n}\n";

    write_atomically(dir / "manifest.csv", csv.str());
    write_atomically(dir / "manifest.json", json.str());
}

std::map<std::string, std::map<std::string, std::string>> read_manifest_csv(
    const std::filesystem::path& dir) {
    std::map<std::string, std::map<std::string, std::string>> rows;
    std::ifstream in(dir / "manifest.csv");
    std::string line;
    if (!in || !std::getline(in, line)) return rows;
    const auto header = common::split_csv_line(line);
    while (std::getline(in, line)) {
        const auto cells = common::split_csv_line(line);
        if (cells.size() != header.size()) continue;  // a damaged row: render it again
        std::map<std::string, std::string> row;
        for (std::size_t c = 0; c < header.size(); ++c) row[header[c]] = cells[c];
        if (row.count("id")) rows[row["id"]] = std::move(row);
    }
    return rows;
}

}  // namespace lucent::stimuli

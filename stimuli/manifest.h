#pragma once
// Manifests of a rendered stimulus set: manifest.csv and manifest.json, one row per
// stimulus (id, file, technique, every parameter value, mesh hash, image statistics,
// software version, input and content hashes). The CSV is also read back so a second
// run can skip stimuli whose inputs did not change.
#include <filesystem>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "stimuli/image_statistics.h"

namespace lucent::stimuli {

// One manifest cell; numbers are written bare in JSON, text quoted, empty cells as null.
struct ManifestField {
    std::string column;
    std::string text;
    bool numeric = false;
};
using ManifestRow = std::vector<ManifestField>;

// The statistics as manifest fields: object_pixels, mean_luminance, sd_luminance,
// rms_contrast, skewness, saturation_intensity_correlation, hist_00 ... hist_NN.
std::vector<ManifestField> statistics_fields(const ImageStatistics& stats);

// Writes DIR/manifest.csv and DIR/manifest.json (each via a temporary file + rename).
// Rows may have different columns (techniques differ): the CSV header is the union in
// first-seen order and a missing cell is empty.
void write_manifest(const std::filesystem::path& dir, std::string_view set_name,
                    std::span<const ManifestRow> rows);

// Reads DIR/manifest.csv as id -> (column -> text); an absent or unreadable manifest
// gives an empty map (everything is then rendered again).
std::map<std::string, std::map<std::string, std::string>> read_manifest_csv(
    const std::filesystem::path& dir);

}  // namespace lucent::stimuli

#pragma once
// `lucent stimuli report DIR`: what a rendered stimulus set looks like, checked at a
// glance. From DIR/manifest.csv and the images it lists: a contact sheet (every stimulus
// as a labelled thumbnail, grouped by factor series in level order), per series the
// perceptual difference of every pair of levels (CIEDE2000 over object pixels, SSIM of
// luminance), warnings for pairs below a threshold and for identical images, and the
// manifest's image statistics as small plots. Writes DIR/report.html (self-contained)
// and DIR/contact-sheet.png.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "stimuli/set_report/colour_difference.h"
#include "stimuli/set_report/contact_sheet.h"

namespace lucent::stimuli {

// A directory that is not a Lucent set, or whose images are missing or changed since
// the manifest: what() is one line naming the file.
class SetReportError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

struct SetReportOptions {
    // A pair of levels whose mean Delta E00 is below this gets a warning (about what is
    // noticed when images are shown one at a time, not side by side).
    double min_delta_e = 3.0;
    // A series of at most this many levels has every pair compared (a factor's levels,
    // as the thesis's Table 4.3); a larger one (a grid) only its neighbouring levels: the
    // next in level order and, where several parameters vary, the next value of one
    // parameter with the others equal. Every pair of a 400-stimulus grid would be 79,800
    // comparisons; its neighbours are 760.
    std::size_t all_pairs_up_to = 12;
    // Called after each pair is measured with (pairs done, pairs in all); may be empty.
    std::function<void(std::size_t done, std::size_t total)> on_pair;
};

// One manifest row as the report reads it.
struct ReportStimulus {
    std::string id, technique, series;
    std::filesystem::path image;  // the file measured (PNG first: what is displayed)
    std::map<std::string, std::string> cells;  // every manifest column
    std::string level;    // the series' varying parameters, e.g. "thickness_exponent=18"
    Thumbnail thumbnail;  // for the contact sheet and the page
};

// A factor series: the manifest's `series` column, members in level order.
struct ReportSeries {
    std::string name;
    std::vector<std::string> varying;  // the columns whose values differ
    std::vector<std::size_t> members;  // indices into SetReport::stimuli
    bool all_pairs = true;           // false: neighbouring levels only (all_pairs_up_to)
    std::size_t pairs_possible = 0;  // every pair of its levels: n (n - 1) / 2
};

struct PairDifference {
    std::string series;
    std::size_t first = 0, second = 0;  // indices into SetReport::stimuli
    // Neighbours in level order; in a series compared on neighbours only, every pair is
    // one of neighbouring levels (next in level order, or next value of one parameter).
    bool adjacent = false;
    DeltaEStatistics delta_e;
    double ssim = 1.0;
    bool identical = false;  // the decoded pixels are equal
};

struct SetReport {
    std::string set_name;
    std::filesystem::path directory;
    double min_delta_e = 3.0;
    std::vector<ReportStimulus> stimuli;  // manifest order
    std::vector<ReportSeries>
        series;  // first-seen order; stimuli without one are left out
    std::vector<PairDifference> pairs;  // per series, (i, j) with i < j in level order
    std::vector<std::string> warnings;  // one line each
};

// Reads and measures; writes nothing. Throws SetReportError.
SetReport measure_stimulus_set(const std::filesystem::path& directory,
                               const SetReportOptions& options = {});

// Writes DIR/report.html and DIR/contact-sheet.png (each atomically); returns their
// paths. Throws SetReportError or std::runtime_error naming the file.
std::vector<std::filesystem::path> write_set_report(const SetReport& report);

// The command: measures (a progress bar on a terminal, and one line first when there
// are more than 100 pairs to compare), prints each warning on stderr
// ("lucent stimuli report: warning: ..."), writes, prints the files. Returns 0, 2 for a
// directory that is not a valid set (one line, nothing written) or 1 on a write failure.
// `command` prefixes messages ("lucent stimuli report", "lucent render").
int run_stimuli_report(const std::filesystem::path& directory,
                       const SetReportOptions& options,
                       const std::string& command = "lucent stimuli report");

}  // namespace lucent::stimuli

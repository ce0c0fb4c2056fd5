#pragma once
// A page opened in a real browser, for tests of HTML reports: Debian's chromium,
// headless, with a fresh profile and no network services. The page is loaded twice:
// once to read the DOM after its load event (--dump-dom), once for a screenshot PNG.
// Pages mark themselves when their images have decoded: an attribute
// data-images-drawn="N/M" on <html> (N of the M <img> elements complete with
// naturalWidth > 0), set by a small script on load.
#include <cstddef>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace lucent::test {

struct BrowserPage {
    bool ok = false;            // chromium ran and produced both outputs
    std::string error;          // why not, one line (with chromium's last output)
    std::string dom;            // the serialised DOM after load
    std::string images_drawn;   // the data-images-drawn value, or empty when absent
    int width = 0, height = 0;  // the screenshot
    std::vector<float> rgb;     // its pixels, 3 values in [0, 1] each, top row first
    std::size_t non_background_pixels = 0;  // differing from the top-left pixel

    // Pixels of the screenshot for which `test(r, g, b)` holds (e.g. an object's hue
    // that only the page's pictures contain).
    std::size_t count_pixels(const std::function<bool(float, float, float)>& test) const;
};

// Loads `html` (a local file) at width x height CSS pixels and writes the screenshot to
// `screenshot`. Needs `chromium` (Debian package chromium) on PATH.
BrowserPage open_in_browser(const std::filesystem::path& html,
                            const std::filesystem::path& screenshot, int width = 1280,
                            int height = 2000);

}  // namespace lucent::test

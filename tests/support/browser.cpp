#include "tests/support/browser.h"

#include <OpenImageIO/imageio.h>
#include <stdlib.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <vector>

namespace lucent::test {
namespace {

std::string quoted(const std::string& text) {
    std::string out = "'";
    for (char c : text) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return out + "'";
}

std::string read_text(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    return text.str();
}

std::string last_line(const std::string& text) {
    std::istringstream in(text);
    std::string line, last;
    while (std::getline(in, line))
        if (!line.empty()) last = line;
    return last;
}

// One chromium run with a fresh profile; returns its exit status.
int run_chromium(const std::string& arguments, const std::filesystem::path& work,
                 const std::filesystem::path& stdout_file) {
    char profile_template[] = "/tmp/lucent-chromium-XXXXXX";
    const char* profile = mkdtemp(profile_template);
    if (!profile) return -1;
    const std::string command =
        "timeout 180 chromium --headless --no-sandbox --disable-gpu --disable-quic "
        "--no-first-run --disable-background-networking --disable-component-update "
        "--disable-sync --hide-scrollbars --user-data-dir=" +
        quoted(profile) + " " + arguments + " > " + quoted(stdout_file.string()) +
        " 2> " + quoted((work / "chromium.log").string());
    const int status = std::system(command.c_str());
    std::error_code ignored;
    std::filesystem::remove_all(profile, ignored);
    return status;
}

}  // namespace

BrowserPage open_in_browser(const std::filesystem::path& html,
                            const std::filesystem::path& screenshot, int width,
                            int height) {
    BrowserPage page;
    const auto url =
        "file://" + std::filesystem::absolute(html).lexically_normal().string();
    if (!screenshot.parent_path().empty())
        std::filesystem::create_directories(screenshot.parent_path());
    // Chromium's output and log in a scratch folder of their own, removed afterwards.
    char work_template[] = "/tmp/lucent-browser-XXXXXX";
    const char* work_dir = mkdtemp(work_template);
    if (!work_dir) {
        page.error = "cannot create a scratch folder in /tmp";
        return page;
    }
    const std::filesystem::path work = work_dir;
    struct Cleanup {
        std::filesystem::path dir;
        ~Cleanup() {
            std::error_code ignored;
            std::filesystem::remove_all(dir, ignored);
        }
    } cleanup{work};
    if (std::system("command -v chromium > /dev/null 2>&1") != 0) {
        page.error =
            "chromium is not installed (Debian package chromium; scripts/install-deps)";
        return page;
    }
    const auto dom_file = work / "dom.html";
    if (run_chromium("--dump-dom " + quoted(url), work, dom_file) != 0) {
        page.error =
            "chromium --dump-dom failed: " + last_line(read_text(work / "chromium.log"));
        return page;
    }
    page.dom = read_text(dom_file);
    const std::string key = "data-images-drawn=\"";
    if (const auto at = page.dom.find(key); at != std::string::npos) {
        const auto end = page.dom.find('"', at + key.size());
        page.images_drawn = page.dom.substr(at + key.size(), end - at - key.size());
    }

    std::filesystem::remove(screenshot);
    const std::string size = std::to_string(width) + "," + std::to_string(height);
    if (run_chromium("--screenshot=" + quoted(screenshot.string()) +
                         " --window-size=" + size + " " + quoted(url),
                     work, work / "screenshot.out") != 0 ||
        !std::filesystem::exists(screenshot)) {
        page.error = "chromium --screenshot failed: " +
                     last_line(read_text(work / "chromium.log"));
        return page;
    }
    auto in = OIIO::ImageInput::open(screenshot.string());
    if (!in) {
        page.error = screenshot.string() + ": cannot read the screenshot";
        return page;
    }
    const auto& spec = in->spec();
    std::vector<float> pixels(std::size_t(spec.width) * spec.height * spec.nchannels);
    in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, pixels.data());
    page.width = spec.width;
    page.height = spec.height;
    const std::size_t n = std::size_t(spec.width) * spec.height;
    page.rgb.resize(n * 3);
    for (std::size_t i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c)
            page.rgb[i * 3 + c] =
                pixels[i * spec.nchannels + std::min(c, spec.nchannels - 1)];
    page.non_background_pixels = page.count_pixels([&](float r, float g, float b) {
        return std::fabs(r - page.rgb[0]) > 2.0f / 255.0f ||
               std::fabs(g - page.rgb[1]) > 2.0f / 255.0f ||
               std::fabs(b - page.rgb[2]) > 2.0f / 255.0f;
    });
    page.ok = true;
    return page;
}

std::size_t BrowserPage::count_pixels(
    const std::function<bool(float, float, float)>& test) const {
    std::size_t count = 0;
    for (std::size_t i = 0; i + 2 < rgb.size(); i += 3)
        count += test(rgb[i], rgb[i + 1], rgb[i + 2]);
    return count;
}

}  // namespace lucent::test

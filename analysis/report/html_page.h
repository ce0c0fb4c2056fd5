#pragma once
// Pieces shared by Lucent's self-contained HTML reports (analysis and stimulus sets).
#include <string>

namespace lucent::analysis {

// A <script> element that, once the page has loaded, sets the attribute
// data-images-drawn="N/M" on <html>: N of the page's M <img> elements are complete with
// a non-zero natural width. Headless-browser tests read it (tests/support/browser.h).
std::string images_drawn_script();

}  // namespace lucent::analysis

#pragma once
// Pieces of Lucent's self-contained HTML pages (the analysis report and the stimulus-set
// report): escaping, embedded images and the images-drawn marker their tests read.
#include <string>
#include <string_view>

namespace lucent::common {

// Text safe inside HTML or SVG markup and attribute values (& < > ").
std::string markup_escape(std::string_view text);
// Text safe between tags (& < >); double quotes are left as they are.
std::string text_escape(std::string_view text);

// RFC 4648 base64 of `bytes` (images embedded as data: URIs).
std::string base64_encode(std::string_view bytes);

// A <script> element that, once the page has loaded, sets the attribute
// data-images-drawn="N/M" on <html>: N of the page's M <img> elements are complete with
// a non-zero natural width. Headless-browser tests read it (tests/support/browser.h).
std::string images_drawn_script();

}  // namespace lucent::common

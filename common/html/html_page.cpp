// Pieces of Lucent's HTML pages (see html_page.h).
#include "common/html/html_page.h"

#include <algorithm>
#include <cstdint>

namespace lucent::common {

std::string markup_escape(std::string_view text) {
    std::string out;
    for (char c : text) {
        switch (c) {
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '&':
                out += "&amp;";
                break;
            case '"':
                out += "&quot;";
                break;
            default:
                out += c;
        }
    }
    return out;
}

std::string text_escape(std::string_view text) {
    std::string out;
    for (char c : text) {
        if (c == '<')
            out += "&lt;";
        else if (c == '>')
            out += "&gt;";
        else if (c == '&')
            out += "&amp;";
        else
            out += c;
    }
    return out;
}

std::string base64_encode(std::string_view bytes) {
    static constexpr char kDigits[] =
        "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
        // Up to three bytes as one 24-bit group, missing bytes as zero bits.
        const std::size_t n = std::min<std::size_t>(3, bytes.size() - i);
        std::uint32_t group = 0;
        for (std::size_t k = 0; k < 3; ++k)
            group = group << 8 | (k < n ? static_cast<unsigned char>(bytes[i + k]) : 0u);
        for (std::size_t k = 0; k < 4; ++k)
            out += k <= n ? kDigits[(group >> (18 - 6 * k)) & 0x3fu] : '=';
    }
    return out;
}

std::string images_drawn_script() {
    return "<script>window.addEventListener('load',function(){var im=document.images,n=0;"
           "for(var i=0;i<im.length;++i)if(im[i].complete&&im[i].naturalWidth>0)++n;"
           "document.documentElement.setAttribute('data-images-drawn',n+'/"
           "'+im.length);});"
           "</script>\n";
}

}  // namespace lucent::common

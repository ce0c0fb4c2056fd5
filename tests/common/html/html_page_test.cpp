// HTML page pieces: escaping for markup and text, RFC 4648 base64 (section 10's test
// vectors) and the images-drawn marker the browser tests read.
#include "common/html/html_page.h"

#include <gtest/gtest.h>

namespace lucent::common {
namespace {

TEST(HtmlPage, Base64MatchesRfc4648TestVectors) {
    // RFC 4648 section 10.
    EXPECT_EQ(base64_encode(""), "");
    EXPECT_EQ(base64_encode("f"), "Zg==");
    EXPECT_EQ(base64_encode("fo"), "Zm8=");
    EXPECT_EQ(base64_encode("foo"), "Zm9v");
    EXPECT_EQ(base64_encode("foob"), "Zm9vYg==");
    EXPECT_EQ(base64_encode("fooba"), "Zm9vYmE=");
    EXPECT_EQ(base64_encode("foobar"), "Zm9vYmFy");
    EXPECT_EQ(base64_encode(std::string("\xff\x00\xfe", 3)), "/wD+");
    // The last two digits of the alphabet (62 '+', 63 '/').
    EXPECT_EQ(base64_encode("\xfb\xff"), "+/8=");
}

TEST(HtmlPage, MarkupEscapeCoversAttributesAndTextEscapeText) {
    EXPECT_EQ(markup_escape("a<b & \"c\" > d"), "a&lt;b &amp; &quot;c&quot; &gt; d");
    EXPECT_EQ(text_escape("a<b & \"c\" > d"), "a&lt;b &amp; \"c\" &gt; d");
    EXPECT_EQ(markup_escape("plain 'text'"), "plain 'text'");
    EXPECT_EQ(text_escape(""), "");
}

TEST(HtmlPage, ImagesDrawnScriptMarksTheDocument) {
    const std::string script = images_drawn_script();
    EXPECT_EQ(script.rfind("<script>", 0), 0u);
    EXPECT_NE(script.find("data-images-drawn"), std::string::npos);
    EXPECT_NE(script.find("naturalWidth>0"), std::string::npos);
    EXPECT_EQ(script.substr(script.size() - 10), "</script>\n");
}

}  // namespace
}  // namespace lucent::common

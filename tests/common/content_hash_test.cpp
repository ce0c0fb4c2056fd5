// Content hashes: FNV-1a 64 as published (Fowler, Noll, Vo test vectors), a fixed byte
// order for stored words, and fields that cannot run together.
#include "common/content_hash.h"

#include <gtest/gtest.h>

#include <fstream>

#include "tests/support/test_paths.h"

namespace lucent::common {
namespace {

TEST(ContentHash, MatchesPublishedFnv1a64Vectors) {
    EXPECT_EQ(ContentHash().hex(), "cbf29ce484222325");
    EXPECT_EQ(ContentHash().bytes("a").hex(), "af63dc4c8601ec8c");
    EXPECT_EQ(ContentHash().bytes("b").hex(), "af63df4c8601f1a5");
    EXPECT_EQ(ContentHash().bytes("foobar").hex(), "85944171f73967e8");
    EXPECT_EQ(ContentHash().bytes("chongo was here!\n").hex(), "46810940eff5f915");
    EXPECT_EQ(ContentHash().bytes("foobar").result(), 0x85944171f73967e8ull);
    EXPECT_EQ(fnv1a_64("foobar"), 0x85944171f73967e8ull);
}

TEST(ContentHash, FeedingInPiecesIsFeedingTheWhole) {
    EXPECT_EQ(ContentHash().bytes("foo").bytes("bar").hex(), "85944171f73967e8");
    const char raw[] = {'f', 'o', 'o', 'b', 'a', 'r'};
    EXPECT_EQ(ContentHash().bytes(raw, sizeof raw).hex(), "85944171f73967e8");
}

TEST(ContentHash, WordsAreLittleEndianBytes) {
    // 0x626f6f66 = 'f' 'o' 'o' 'b' least significant byte first.
    EXPECT_EQ(ContentHash().word(0x626f6f66u).bytes("ar").hex(), "85944171f73967e8");
}

TEST(ContentHash, FloatBitsFoldNegativeZero) {
    EXPECT_EQ(ContentHash().float_bits(-0.0f).hex(),
              ContentHash().float_bits(0.0f).hex());
    EXPECT_EQ(ContentHash().float_bits(0.0f).hex(), ContentHash().word(0u).hex());
    // 1.0f is 0x3f800000 in IEEE 754 single precision.
    EXPECT_EQ(ContentHash().float_bits(1.0f).hex(),
              ContentHash().word(0x3f800000u).hex());
    EXPECT_NE(ContentHash().float_bits(1.0f).hex(),
              ContentHash().float_bits(-1.0f).hex());
}

TEST(ContentHash, FieldsAreLengthPrefixedAndNeverRunTogether) {
    EXPECT_EQ(ContentHash().field("abc").hex(), ContentHash().bytes("3:abc").hex());
    EXPECT_EQ(ContentHash().field("").hex(), ContentHash().bytes("0:").hex());
    EXPECT_NE(ContentHash().field("ab").field("c").hex(),
              ContentHash().field("a").field("bc").hex());
    EXPECT_NE(ContentHash().text("ab").text("c").hex(),
              ContentHash().text("a").text("bc").hex());
    const std::size_t length = 3;
    EXPECT_EQ(ContentHash().text("abc").hex(),
              ContentHash().bytes(&length, sizeof length).bytes("abc").hex());
}

TEST(ContentHash, HashFileIsTheHashOfItsBytes) {
    const auto dir = test::scratch_dir("content_hash_file");
    std::ofstream(dir / "f.bin", std::ios::binary) << "foobar";
    EXPECT_EQ(hash_file(dir / "f.bin"), "85944171f73967e8");
    std::ofstream(dir / "empty.bin", std::ios::binary).flush();
    EXPECT_EQ(hash_file(dir / "empty.bin"), "cbf29ce484222325");
    EXPECT_THROW(hash_file(dir / "absent"), std::runtime_error);
}

}  // namespace
}  // namespace lucent::common

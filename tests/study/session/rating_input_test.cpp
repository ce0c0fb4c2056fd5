// The rating screen's input rules: no preselection, keys and clicks, changes and times.
#include "study/session/rating_input.h"

#include <gtest/gtest.h>

namespace lucent::study {
namespace {

constexpr int64_t kMs = 1000000;

TEST(RatingInput, NothingIsChosenUntilAKeyAndEnterNeverAnswers) {
    RatingInput in(3, 7, 1000 * kMs);
    for (int q = 0; q < 3; ++q) EXPECT_FALSE(in.rating(q).has_value());
    in.key(RatingKey::Enter, 0, 1100 * kMs);
    EXPECT_FALSE(in.confirmed());
    EXPECT_EQ(in.focus(), 0);
    EXPECT_FALSE(in.all_answered());
}

TEST(RatingInput, DigitsThenEnterWalkThroughStatementsAndConfirm) {
    RatingInput in(3, 7, 1000 * kMs);
    in.key(RatingKey::Digit, 5, 1400 * kMs);
    in.key(RatingKey::Enter, 0, 1500 * kMs);
    EXPECT_EQ(in.focus(), 1);
    in.key(RatingKey::Digit, 2, 1900 * kMs);
    in.key(RatingKey::Digit, 3, 2100 * kMs);  // a change of mind
    in.key(RatingKey::Enter, 0, 2200 * kMs);
    in.key(RatingKey::Digit, 9, 2300 * kMs);  // beyond the scale: ignored
    EXPECT_FALSE(in.rating(2).has_value());
    in.key(RatingKey::Digit, 7, 2600 * kMs);
    EXPECT_FALSE(in.confirmed());
    in.key(RatingKey::Enter, 0, 2800 * kMs);
    ASSERT_TRUE(in.confirmed());
    EXPECT_EQ(in.confirm_ns(), 2800 * kMs);
    const auto r = in.responses({"translucent", "realistic", "varnished"});
    ASSERT_EQ(r.size(), 3u);
    EXPECT_EQ(r[0].rating, 5);
    EXPECT_EQ(r[1].rating, 3);
    EXPECT_EQ(r[2].rating, 7);
    EXPECT_EQ(r[1].changes, 1);
    EXPECT_EQ(r[0].changes, 0);
    EXPECT_DOUBLE_EQ(r[0].rt_ms, 400.0);
    EXPECT_DOUBLE_EQ(r[1].rt_ms, 1100.0);  // to the final choice, not the first
    EXPECT_EQ(r[1].first_choice_ns, 1900 * kMs);
    EXPECT_EQ(r[2].question, "varnished");
    // After confirmation nothing changes.
    in.key(RatingKey::Digit, 1, 3000 * kMs);
    EXPECT_EQ(in.rating(0), 5);
}

TEST(RatingInput, ArrowsStartInTheMiddleAndClampAtTheEnds) {
    RatingInput in(2, 7, 0);
    in.key(RatingKey::Left, 0, 10);
    EXPECT_EQ(in.rating(0), 4);
    for (int i = 0; i < 5; ++i) in.key(RatingKey::Left, 0, 20 + i);
    EXPECT_EQ(in.rating(0), 1);
    in.key(RatingKey::Down, 0, 30);
    in.key(RatingKey::Right, 0, 40);
    in.key(RatingKey::Right, 0, 50);
    EXPECT_EQ(in.rating(1), 5);
    in.key(RatingKey::Up, 0, 60);
    EXPECT_EQ(in.focus(), 0);
    const auto r = in.responses({"a", "b"});
    EXPECT_EQ(r[0].changes, 3);  // 4 -> 3 -> 2 -> 1; the clamped presses change nothing
}

TEST(RatingInput, ClicksAnswerAndNextConfirmsOnlyWhenAllAreAnswered) {
    RatingInput in(2, 7, 0);
    in.click(1, 6, 100);
    EXPECT_EQ(in.focus(), 1);
    in.click_next(150);
    EXPECT_FALSE(in.confirmed());
    in.click(0, 2, 200);
    in.click(0, 2, 250);  // the same point again is not a change
    in.click_next(300);
    EXPECT_TRUE(in.confirmed());
    EXPECT_EQ(in.responses({"a", "b"})[0].changes, 0);
}

TEST(RatingInput, EachQuestionHasItsOwnScaleLength) {
    // 7 points, then 5, then 3: digits and arrows respect the focused question's scale.
    RatingInput in({7, 5, 3}, 0);
    in.key(RatingKey::Digit, 7, 10);
    EXPECT_EQ(in.rating(0), 7);
    in.key(RatingKey::Enter, 0, 20);
    in.key(RatingKey::Digit, 6, 30);  // beyond 5: ignored
    in.key(RatingKey::Digit, 7, 31);
    EXPECT_FALSE(in.rating(1).has_value());
    in.key(RatingKey::Right, 0, 40);  // the middle of 1..5
    EXPECT_EQ(in.rating(1), 3);
    for (int i = 0; i < 4; ++i) in.key(RatingKey::Right, 0, 50 + i);
    EXPECT_EQ(in.rating(1), 5);
    in.key(RatingKey::Enter, 0, 60);
    in.key(RatingKey::Left, 0, 70);  // the middle of 1..3
    EXPECT_EQ(in.rating(2), 2);
    in.click(2, 4, 80);  // a point the 3-point scale does not have
    EXPECT_EQ(in.rating(2), 2);
    in.click(2, 3, 90);
    in.key(RatingKey::Enter, 0, 100);
    ASSERT_TRUE(in.confirmed());
    const auto r = in.responses({"a", "b", "c"});
    EXPECT_EQ(r[0].rating, 7);
    EXPECT_EQ(r[1].rating, 5);
    EXPECT_EQ(r[2].rating, 3);
}

}  // namespace
}  // namespace lucent::study

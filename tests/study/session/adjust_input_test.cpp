// The adjust screen's input (issue 31): steps on a linear and a log scale, the range's
// ends, wheel and drag, and the answer the store receives. Expected values are the
// block's numbers stepped by hand.
#include "study/session/adjust_input.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lucent::study {
namespace {

Block adjust_block(const std::string& scale) {
    Block b;
    b.id = "m";
    b.task = Task::adjust;
    b.knob = "thickness_exponent";
    b.range_min = 0.25;
    b.range_max = 4.0;
    b.scale = scale;
    b.step = scale == "log" ? 0.1 : 0.5;
    b.fine_step = scale == "log" ? 0.01 : 0.05;
    return b;
}

TEST(AdjustInput, StepsCoarseAndFineOnALinearScaleAndStopsAtTheEnds) {
    AdjustInput in(adjust_block("linear"), 1.0, 1'000);
    in.step(true, false, 2'000);   // 1.5
    in.step(true, true, 3'000);    // 1.55
    in.step(false, false, 4'000);  // 1.05
    EXPECT_NEAR(in.value(), 1.05, 1e-12);
    for (int i = 0; i < 10; ++i) in.step(true, false, 5'000 + i);
    EXPECT_EQ(in.value(), 4.0);
    EXPECT_TRUE(in.at_max());
    // 1.05 -> 4 takes 6 steps (the sixth is held at 4); the other four change nothing
    // and are not counted.
    EXPECT_EQ(in.adjustments().size(), 3u + 6u);
    for (int i = 0; i < 20; ++i) in.step(false, false, 6'000 + i);
    EXPECT_EQ(in.value(), 0.25);
    EXPECT_TRUE(in.at_min());
    EXPECT_EQ(in.adjustments().back().input, "key");
    EXPECT_EQ(in.adjustments()[1].input, "fine_key");
}

TEST(AdjustInput, InTheBrowserTheValueIsAlwaysAPictureOfTheSeries) {
    // Linear [0.25, 4] in 16 pictures: 0.25 apart. Coarse 0.5 = two pictures, fine
    // 0.05 = a fifth of one.
    Block b = adjust_block("linear");
    std::vector<double> series;
    for (int i = 0; i < 16; ++i) series.push_back(0.25 + 0.25 * i);
    AdjustInput in(b, 1.1, 0, series);
    // The start is the nearest picture: 1.0 (index 3).
    EXPECT_EQ(in.start(), 1.0);
    EXPECT_EQ(in.series_index(), 3u);
    in.step(true, false, 1);  // 1.5, index 5
    EXPECT_EQ(in.value(), 1.5);
    EXPECT_EQ(in.series_index(), 5u);
    // Two fine steps (0.1) stay nearest 1.5: no change is recorded; the third (0.15)
    // is nearer 1.75.
    in.step(true, true, 2);
    in.step(true, true, 3);
    EXPECT_EQ(in.value(), 1.5);
    EXPECT_EQ(in.adjustments().size(), 1u);
    in.step(true, true, 4);
    EXPECT_EQ(in.value(), 1.75);
    EXPECT_EQ(in.adjustments().size(), 2u);
    // A drag of half the width: half the range (1.875) from 1.65 -> 3.525, nearest 3.5.
    in.drag(50, 100, 5);
    EXPECT_EQ(in.value(), 3.5);
    // Held at the end, which is the last picture exactly.
    in.wheel(10, 6);
    EXPECT_EQ(in.value(), 4.0);
    EXPECT_EQ(in.series_index(), 15u);
    EXPECT_EQ(in.adjustments().size(), 4u);
    in.confirm(7);
    EXPECT_EQ(*in.outcome("m").final_value, 4.0);
    EXPECT_THROW(AdjustInput(b, 1.0, 0, {1.0}), std::invalid_argument);
}

TEST(AdjustInput, AChangeStampedBeforeThePreviousOneIsKeptInOrder) {
    // A key whose X event time is earlier than the wheel notch the frame drew before it
    // (and one before the onset): stored at the previous change's time, never earlier.
    AdjustInput in(adjust_block("linear"), 1.0, 1'000);
    in.step(true, false, 500);  // before the onset: 1'000
    in.wheel(1, 5'000);
    in.step(true, true, 4'000);  // read late: 5'000
    in.step(true, true, 6'000);
    ASSERT_EQ(in.adjustments().size(), 4u);
    EXPECT_EQ(in.adjustments()[0].t_ns, 1'000);
    EXPECT_EQ(in.adjustments()[1].t_ns, 5'000);
    EXPECT_EQ(in.adjustments()[2].t_ns, 5'000);
    EXPECT_EQ(in.adjustments()[3].t_ns, 6'000);
    EXPECT_NEAR(in.value(), 1.0 + 0.5 + 0.5 + 0.05 + 0.05, 1e-12);
}

TEST(AdjustInput, StepsAreFactorsOnALogScale) {
    AdjustInput in(adjust_block("log"), 1.0, 0);
    in.step(true, false, 1);  // 10^0.1
    EXPECT_NEAR(in.value(), std::pow(10.0, 0.1), 1e-12);
    in.step(false, true, 2);  // 10^0.09
    EXPECT_NEAR(in.value(), std::pow(10.0, 0.09), 1e-12);
    // The ends are the range's values exactly.
    for (int i = 0; i < 30; ++i) in.step(false, false, 3 + i);
    EXPECT_EQ(in.value(), 0.25);
    for (int i = 0; i < 30; ++i) in.step(true, false, 40 + i);
    EXPECT_EQ(in.value(), 4.0);
}

TEST(AdjustInput, WheelAndDragMoveOnTheScale) {
    AdjustInput in(adjust_block("linear"), 1.0, 0);
    in.wheel(2, 1);  // two coarse steps
    EXPECT_NEAR(in.value(), 2.0, 1e-12);
    in.wheel(-0.5, 2);  // half a step (a touchpad)
    EXPECT_NEAR(in.value(), 1.75, 1e-12);
    // A quarter of the match's width: a quarter of the range (3.75 / 4).
    in.drag(-50, 200, 3);
    EXPECT_NEAR(in.value(), 1.75 - 0.9375, 1e-12);
    EXPECT_EQ(in.adjustments().back().input, "drag");
    // Degenerate moves change nothing.
    const size_t changes = in.adjustments().size();
    in.drag(10, 0, 4);
    in.drag(NAN, 100, 5);
    in.wheel(INFINITY, 6);
    EXPECT_EQ(in.adjustments().size(), changes);
    EXPECT_TRUE(std::isfinite(in.value()));
    // On a log scale the whole width spans log10(16).
    AdjustInput log(adjust_block("log"), 1.0, 0);
    log.drag(100, 100, 1);
    EXPECT_EQ(log.value(), 4.0);
}

TEST(AdjustInput, TheAnswerHoldsEveryChangeAndNothingAfterTheConfirmation) {
    AdjustInput in(adjust_block("linear"), 9.0, 1'000'000);  // clamped to 4
    EXPECT_EQ(in.start(), 4.0);
    in.step(false, false, 3'000'000);
    in.step(false, true, 5'000'000);
    in.confirm(8'000'000);
    in.step(false, false, 9'000'000);  // after Enter: ignored
    const TrialOutcome out = in.outcome("m");
    ASSERT_TRUE(out.final_value);
    EXPECT_NEAR(*out.final_value, 3.45, 1e-12);
    ASSERT_EQ(out.adjustments.size(), 2u);
    EXPECT_EQ(out.adjustments[0].t_ns, 3'000'000);
    EXPECT_NEAR(out.adjustments[1].value, 3.45, 1e-12);
    ASSERT_EQ(out.responses.size(), 1u);
    EXPECT_EQ(out.responses[0].question, "m");
    EXPECT_EQ(out.responses[0].rating, 1);
    EXPECT_EQ(out.responses[0].changes, 2);
    EXPECT_DOUBLE_EQ(out.responses[0].rt_ms, 7.0);
    EXPECT_EQ(out.responses[0].first_choice_ns, 3'000'000);
    EXPECT_EQ(out.responses[0].final_choice_ns, 5'000'000);
    // Confirmed at the start: no change, the times are the confirmation's.
    AdjustInput still(adjust_block("linear"), 2.0, 0);
    EXPECT_THROW(still.outcome("m"), std::logic_error);
    still.confirm(4'000'000);
    const TrialOutcome kept = still.outcome("m");
    EXPECT_EQ(*kept.final_value, 2.0);
    EXPECT_TRUE(kept.adjustments.empty());
    EXPECT_EQ(kept.responses[0].first_choice_ns, 4'000'000);
    EXPECT_THROW(AdjustInput(Block{}, 1.0, 0), std::invalid_argument);
}

}  // namespace
}  // namespace lucent::study

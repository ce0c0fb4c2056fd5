// Progressive refinement (core/progressive.h): frame sample counts and seeds, the mean
// weighted by sample counts (against the closed form), and what restarts it.
#include "renderer/core/progressive.h"

#include <gtest/gtest.h>

namespace lucent {
namespace {

KnobValues values(int samples, int seed, double other = 0.5) {
    KnobValues v;
    v.set("samples", samples);
    v.set("sample_seed", seed);
    v.set("other", other);
    return v;
}

Image constant(float value) {
    Image image(2, 1);
    for (float& channel : image.rgba) channel = value;
    return image;
}

const ProgressiveRefinement kRefinement{"samples", "sample_seed", 4};

TEST(ProgressiveAccumulator, FramesTakeAFewSamplesEachWithTheSeedAdvanced) {
    ProgressiveAccumulator accumulator(kRefinement);
    const float frame_values[] = {1.f, 2.f, 7.f};
    const int expected_samples[] = {4, 4, 2};  // N = 10 in frames of at most 4
    for (int k = 0; k < 3; ++k) {
        const auto frame = accumulator.next(values(10, 7), "view", 1000);
        ASSERT_TRUE(frame.has_value()) << k;
        EXPECT_EQ(frame->integer("samples"), expected_samples[k]);
        EXPECT_EQ(frame->integer("sample_seed"), 7 + k);
        EXPECT_EQ(frame->scalar("other"), 0.5);
        accumulator.add(constant(frame_values[k]));
    }
    EXPECT_TRUE(accumulator.converged());
    EXPECT_FALSE(accumulator.next(values(10, 7), "view", 1000).has_value());
    // Weighted by sample counts: (4 * 1 + 4 * 2 + 2 * 7) / 10 = 2.6.
    EXPECT_NEAR(accumulator.mean().rgba[0], 2.6f, 1e-6f);
    EXPECT_EQ(accumulator.samples(), 10);
}

TEST(ProgressiveAccumulator, ASmallTargetIsOneFrameAtThatTarget) {
    ProgressiveAccumulator accumulator(kRefinement);
    const auto frame = accumulator.next(values(3, 0), "view", 1000);
    ASSERT_TRUE(frame.has_value());
    EXPECT_EQ(frame->integer("samples"), 3);
    EXPECT_EQ(frame->integer("sample_seed"), 0);  // the image `lucent render` makes
    accumulator.add(constant(5.f));
    EXPECT_TRUE(accumulator.converged());
    EXPECT_EQ(accumulator.mean().rgba[0], 5.f);
}

TEST(ProgressiveAccumulator, AnotherValueOrViewRestartsALargerTargetGoesOn) {
    ProgressiveAccumulator accumulator(kRefinement);
    accumulator.next(values(8, 0), "view", 1000);
    accumulator.add(constant(1.f));
    // Another value of a knob that is not refined: start again at seed 0.
    auto frame = accumulator.next(values(8, 0, 0.25), "view", 1000);
    EXPECT_EQ(frame->integer("sample_seed"), 0);
    accumulator.add(constant(3.f));
    EXPECT_EQ(accumulator.samples(), 4);
    EXPECT_EQ(accumulator.mean().rgba[0], 3.f);
    // Another view (camera, size): again.
    frame = accumulator.next(values(8, 0, 0.25), "orbited", 1000);
    EXPECT_EQ(frame->integer("sample_seed"), 0);
    accumulator.add(constant(2.f));
    accumulator.next(values(8, 0, 0.25), "orbited", 1000);
    accumulator.add(constant(4.f));
    EXPECT_TRUE(accumulator.converged());
    // A larger N goes on from the mean so far with the next seed.
    frame = accumulator.next(values(12, 0, 0.25), "orbited", 1000);
    ASSERT_TRUE(frame.has_value());
    EXPECT_EQ(frame->integer("sample_seed"), 2);
    accumulator.add(constant(6.f));
    EXPECT_NEAR(accumulator.mean().rgba[0], (4 * 2.f + 4 * 4.f + 4 * 6.f) / 12, 1e-6f);
    // A smaller N than the samples so far restarts.
    frame = accumulator.next(values(4, 0, 0.25), "orbited", 1000);
    ASSERT_TRUE(frame.has_value());
    EXPECT_EQ(frame->integer("sample_seed"), 0);
}

TEST(ProgressiveAccumulator, SeedsWrapInsideTheKnobsRange) {
    ProgressiveAccumulator accumulator(kRefinement);
    accumulator.next(values(12, 9), "view", 10);
    accumulator.add(constant(0.f));
    const auto frame = accumulator.next(values(12, 9), "view", 10);
    EXPECT_EQ(frame->integer("sample_seed"), 10);
    accumulator.add(constant(0.f));
    EXPECT_EQ(accumulator.next(values(12, 9), "view", 10)->integer("sample_seed"), 0);
}

}  // namespace
}  // namespace lucent

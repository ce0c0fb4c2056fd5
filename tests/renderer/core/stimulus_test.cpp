// A knob as a function of time (Stimulus::motion): closed-form values over a period,
// any finite time, and a clear refusal of a time that is not finite.
#include "renderer/core/stimulus.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace lucent {
namespace {

KnobMotion tilt(KnobMotion::Shape shape) {
    KnobMotion m;
    m.knob = "tilt";
    m.from = 0.0;
    m.to = 70.0;
    m.period_s = 4.0;
    m.shape = shape;
    return m;
}

TEST(KnobMotion, BackAndForthIsATriangleFromFromToToAndBack) {
    const KnobMotion m = tilt(KnobMotion::Shape::back_and_forth);
    EXPECT_DOUBLE_EQ(m.value_at(0.0), 0.0);
    EXPECT_DOUBLE_EQ(m.value_at(1.0), 35.0);
    EXPECT_DOUBLE_EQ(m.value_at(2.0), 70.0);  // half a period: `to`
    EXPECT_DOUBLE_EQ(m.value_at(3.0), 35.0);
    EXPECT_DOUBLE_EQ(m.value_at(4.0), 0.0);    // one period: back at `from`
    EXPECT_DOUBLE_EQ(m.value_at(9.0), 35.0);   // periodic
    EXPECT_DOUBLE_EQ(m.value_at(-1.0), 35.0);  // and before t = 0
    EXPECT_DOUBLE_EQ(m.value_at(-2.0), 70.0);
}

TEST(KnobMotion, LoopRampsAndJumpsBackEachPeriod) {
    const KnobMotion m = tilt(KnobMotion::Shape::loop);
    EXPECT_DOUBLE_EQ(m.value_at(0.0), 0.0);
    EXPECT_DOUBLE_EQ(m.value_at(1.0), 17.5);
    EXPECT_DOUBLE_EQ(m.value_at(3.0), 52.5);
    EXPECT_DOUBLE_EQ(m.value_at(4.0), 0.0);
    EXPECT_DOUBLE_EQ(m.value_at(-1.0), 52.5);
}

TEST(KnobMotion, StaysExactAndInRangeAtExtremeTimes) {
    const KnobMotion m = tilt(KnobMotion::Shape::back_and_forth);
    // 1e15 is a whole number of 4 s periods: t = 1e15 + 1 is a quarter period in, exactly
    // (t / period would round the phase away at this size).
    EXPECT_DOUBLE_EQ(m.value_at(1e15 + 1.0), 35.0);
    for (double t :
         {std::numeric_limits<double>::max(), -std::numeric_limits<double>::max(),
          std::numeric_limits<double>::denorm_min(), 1e300, -1e-300}) {
        const double v = m.value_at(t);
        EXPECT_TRUE(std::isfinite(v)) << t;
        EXPECT_GE(v, 0.0) << t;
        EXPECT_LE(v, 70.0) << t;
    }
    KnobMotion down = m;  // from > to: the same bounds the other way round
    down.from = 70.0;
    down.to = 0.0;
    EXPECT_DOUBLE_EQ(down.value_at(2.0), 0.0);
    EXPECT_DOUBLE_EQ(down.value_at(1.0), 35.0);
}

TEST(KnobMotion, ATimeThatIsNotFiniteIsRefusedNamingTheKnob) {
    const KnobMotion m = tilt(KnobMotion::Shape::loop);
    for (double t : {std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::infinity()}) {
        try {
            m.value_at(t);
            FAIL() << "accepted t = " << t;
        } catch (const std::invalid_argument& e) {
            EXPECT_NE(std::string(e.what()).find("'tilt'"), std::string::npos)
                << e.what();
        }
    }
}

TEST(Stimulus, ValuesAtMoveOnlyTheMovingKnobs) {
    Stimulus s;
    s.values.set("tilt", 0.0);
    s.values.set("thickness", 0.5);
    EXPECT_FALSE(s.moves());
    EXPECT_EQ(s.values_at(3.0).all(), s.values.all());  // a still is the same at any t
    s.motion.push_back(tilt(KnobMotion::Shape::back_and_forth));
    EXPECT_TRUE(s.moves());
    const KnobValues at_2 = s.values_at(2.0);
    EXPECT_EQ(at_2.scalar("tilt"), 70.0);
    EXPECT_EQ(at_2.scalar("thickness"), 0.5);
}

}  // namespace
}  // namespace lucent

#include "study/session/layout.h"

#include <gtest/gtest.h>

namespace lucent::study {
namespace {

TEST(Layout, ImageIsCentredPixelForPixel) {
    const ScreenLayout l = compute_layout(1280, 1024, 128, 128, 3, 40);
    EXPECT_EQ(l.image.x, (1280 - 128) / 2);
    EXPECT_EQ(l.image.y, (1024 - 128) / 2);
    EXPECT_EQ(l.image.width, 128);
    EXPECT_EQ(l.image.height, 128);
    EXPECT_EQ(l.panel.y + l.panel.height, 1024);
}

TEST(Layout, LargeImagesMoveUpAboveThePanelButNotOffScreen) {
    const ScreenLayout l = compute_layout(1280, 1024, 512, 512, 3, 40);
    EXPECT_LE(l.image.y + l.image.height, l.panel.y);
    EXPECT_GE(l.image.y, 0);
    EXPECT_EQ(l.image.x, 384);
    const ScreenLayout huge = compute_layout(800, 600, 700, 700, 3, 40);
    EXPECT_EQ(huge.image.y, 0);
    EXPECT_EQ(huge.image.width, 700);  // never scaled
}

}  // namespace
}  // namespace lucent::study

namespace lucent::study {
namespace {

ChoiceLayoutInput choice_input(int w, int h, Task task, ChoiceShow show, int size) {
    ChoiceLayoutInput in;
    in.screen_width = w;
    in.screen_height = h;
    Block block;
    block.task = task;
    in.groups = task->answer_groups(block);  // what the lab's runner asks the kind
    in.show = show;
    in.pictures.assign(task->pictures(block), PictureSize{size, size});
    in.row_height = 32;
    in.gap = 24;
    in.group_gap = 96;
    return in;
}

TEST(ChoiceLayout, APairSitsCentredPixelForPixelWithALabelUnderEachPicture) {
    const ChoiceLayout l =
        compute_choice_layout(choice_input(1280, 1024, Task::pair, ChoiceShow::all, 384));
    ASSERT_TRUE(l.fits);
    // 384 + 24 + 384 = 792 wide: (1280 - 792) / 2 = 244; (1024 - 384) / 2 = 320.
    EXPECT_EQ(l.picture, (std::vector<Rect>{{244, 320, 384, 384}, {652, 320, 384, 384}}));
    EXPECT_EQ(l.index, (std::vector<int>{0, 1}));
    EXPECT_EQ(l.question, (Rect{0, 272, 1280, 32}));  // half a row above the pictures
    EXPECT_EQ(l.label[0], (Rect{244, 720, 384, 32}));
    EXPECT_EQ(l.label[1], (Rect{652, 720, 384, 32}));
    EXPECT_EQ(l.bracket[0].width, 0);
    // Each picture (with its label) is its answer.
    EXPECT_EQ(l.alternative[0], (Rect{244, 320, 384, 432}));
    EXPECT_EQ(l.alternative[1], (Rect{652, 320, 384, 432}));
    EXPECT_TRUE(l.alternative[0].contains(300, 400));
    EXPECT_FALSE(l.alternative[0].contains(640, 400));  // the gap answers nothing
    EXPECT_FALSE(l.alternative[1].contains(640, 400));
}

TEST(ChoiceLayout, ATriadsPairsMeetAtTheMiddlePictureAndSplitTheClicksThere) {
    const ChoiceLayout l = compute_choice_layout(
        choice_input(1280, 1024, Task::triad, ChoiceShow::all, 384));
    ASSERT_TRUE(l.fits);
    // 3 x 384 + 2 x 24 = 1200: x from 40.
    EXPECT_EQ(l.picture,
              (std::vector<Rect>{
                  {40, 320, 384, 384}, {448, 320, 384, 384}, {856, 320, 384, 384}}));
    // Brackets from the left picture's centre to the middle's, and on to the right's.
    EXPECT_EQ(l.bracket[0], (Rect{232, 720, 408, 16}));
    EXPECT_EQ(l.bracket[1], (Rect{640, 720, 408, 16}));
    EXPECT_EQ(l.label[0], (Rect{232, 736, 408, 32}));
    EXPECT_EQ(l.label[1], (Rect{640, 736, 408, 32}));
    EXPECT_EQ(l.alternative[0], (Rect{40, 320, 600, 448}));
    EXPECT_EQ(l.alternative[1], (Rect{640, 320, 600, 448}));
    EXPECT_TRUE(l.alternative[0].contains(639, 500));
    EXPECT_TRUE(l.alternative[1].contains(640, 500));
}

TEST(ChoiceLayout, AQuadruplesPairsAreTwoGroupsAWiderGapApart) {
    const ChoiceLayout l = compute_choice_layout(
        choice_input(1280, 1024, Task::quadruple, ChoiceShow::all, 128));
    ASSERT_TRUE(l.fits);
    // 4 x 128 + 24 + 96 + 24 = 656: x from 312; y (1024 - 128) / 2 = 448.
    EXPECT_EQ(l.picture, (std::vector<Rect>{{312, 448, 128, 128},
                                            {464, 448, 128, 128},
                                            {688, 448, 128, 128},
                                            {840, 448, 128, 128}}));
    EXPECT_EQ(l.bracket[0], (Rect{312, 592, 280, 16}));
    EXPECT_EQ(l.bracket[1], (Rect{688, 592, 280, 16}));
    EXPECT_EQ(l.label[0], (Rect{312, 608, 280, 32}));
    EXPECT_EQ(l.label[1], (Rect{688, 608, 280, 32}));
    EXPECT_EQ(l.alternative[0], (Rect{312, 448, 280, 192}));
    EXPECT_EQ(l.alternative[1], (Rect{688, 448, 280, 192}));
    EXPECT_FALSE(l.alternative[0].contains(640, 500));  // between the groups
    EXPECT_FALSE(l.alternative[1].contains(640, 500));
}

TEST(ChoiceLayout, ASequenceShowsEachPartCentredThenTwoAnswerBoxes) {
    auto at = [](Task task, ChoiceShow show, int size) {
        return compute_choice_layout(choice_input(1280, 1024, task, show, size));
    };
    const ChoiceLayout first = at(Task::pair, ChoiceShow::first_part, 384);
    const ChoiceLayout second = at(Task::pair, ChoiceShow::second_part, 384);
    ASSERT_TRUE(first.fits);
    EXPECT_EQ(first.picture, (std::vector<Rect>{{448, 320, 384, 384}}));
    EXPECT_EQ(first.index, (std::vector<int>{0}));
    EXPECT_EQ(second.picture, first.picture);
    EXPECT_EQ(second.index, (std::vector<int>{1}));
    EXPECT_TRUE(first.alternative.empty());  // nothing to answer yet
    EXPECT_TRUE(first.label.empty());
    const ChoiceLayout gap = at(Task::pair, ChoiceShow::nothing, 384);
    EXPECT_TRUE(gap.fits);
    EXPECT_TRUE(gap.picture.empty());
    // The question stays in one place through the sequence.
    EXPECT_EQ(gap.question, first.question);
    const ChoiceLayout answers = at(Task::pair, ChoiceShow::answers, 384);
    EXPECT_TRUE(answers.picture.empty());
    EXPECT_EQ(answers.question, first.question);
    // Boxes of 6 x 2 rows, group_gap apart, centred on the pictures' line.
    EXPECT_EQ(answers.box[0], (Rect{400, 480, 192, 64}));
    EXPECT_EQ(answers.box[1], (Rect{688, 480, 192, 64}));
    EXPECT_EQ(answers.alternative, answers.box);
    EXPECT_EQ(answers.label, answers.box);
    // An MLDS sequence shows a pair side by side: a quadruple's first and second pair.
    const ChoiceLayout q1 = at(Task::quadruple, ChoiceShow::first_part, 128);
    const ChoiceLayout q2 = at(Task::quadruple, ChoiceShow::second_part, 128);
    EXPECT_EQ(q1.picture,
              (std::vector<Rect>{{500, 448, 128, 128}, {652, 448, 128, 128}}));
    EXPECT_EQ(q1.index, (std::vector<int>{0, 1}));
    EXPECT_EQ(q2.picture, q1.picture);
    EXPECT_EQ(q2.index, (std::vector<int>{2, 3}));
    // A triad's pairs share the middle picture.
    EXPECT_EQ(at(Task::triad, ChoiceShow::first_part, 128).index,
              (std::vector<int>{0, 1}));
    EXPECT_EQ(at(Task::triad, ChoiceShow::second_part, 128).index,
              (std::vector<int>{1, 2}));
}

TEST(ChoiceLayout, AWindowTooSmallForThePicturesDoesNotFit) {
    // Three 384-pixel pictures need 1200 pixels: not in 1024.
    EXPECT_FALSE(
        compute_choice_layout(choice_input(1024, 768, Task::triad, ChoiceShow::all, 384))
            .fits);
    // A quadruple of 384 needs 1680 side by side, but a sequence's pair only 792.
    EXPECT_FALSE(compute_choice_layout(
                     choice_input(1280, 1024, Task::quadruple, ChoiceShow::all, 384))
                     .fits);
    EXPECT_TRUE(compute_choice_layout(choice_input(1280, 1024, Task::quadruple,
                                                   ChoiceShow::first_part, 384))
                    .fits);
    // Too low for the question, the pictures and the labels (48 + 384 + 48 rows).
    EXPECT_FALSE(
        compute_choice_layout(choice_input(1280, 479, Task::pair, ChoiceShow::all, 384))
            .fits);
    EXPECT_TRUE(
        compute_choice_layout(choice_input(1280, 480, Task::pair, ChoiceShow::all, 384))
            .fits);
    // In sequence every phase says the same, so a trial waits before its first part.
    for (ChoiceShow show : {ChoiceShow::first_part, ChoiceShow::nothing,
                            ChoiceShow::second_part, ChoiceShow::answers})
        EXPECT_FALSE(
            compute_choice_layout(choice_input(300, 1024, Task::pair, show, 384)).fits);
    // Exactly as wide as the screen fits, pixel for pixel from x = 0.
    const ChoiceLayout edge = compute_choice_layout(
        choice_input(1200, 1024, Task::triad, ChoiceShow::all, 384));
    ASSERT_TRUE(edge.fits);
    EXPECT_EQ(edge.picture.front().x, 0);
    EXPECT_EQ(edge.picture.back().x + 384, 1200);
}

TEST(ChoiceLayout, ContentTallerBelowThanAboveMovesUpToStayOnScreen) {
    // A triad: 48 rows above the pictures (question), 64 below (bracket, label); in 496
    // rows the centred pictures would leave the labels 8 rows off the bottom.
    const ChoiceLayout l =
        compute_choice_layout(choice_input(1200, 496, Task::triad, ChoiceShow::all, 384));
    ASSERT_TRUE(l.fits);
    EXPECT_EQ(l.question.y, 0);
    EXPECT_EQ(l.picture[0].y, 48);
    EXPECT_EQ(l.label[1].y + l.label[1].height, 496);
    EXPECT_EQ(l.alternative[0].y, 48);
}

TEST(ChoiceLayout, PicturesOfDifferentSizesShareTheRowsCentreLine) {
    ChoiceLayoutInput in = choice_input(1280, 1024, Task::pair, ChoiceShow::all, 0);
    in.pictures = {{200, 100}, {300, 300}};
    const ChoiceLayout l = compute_choice_layout(in);
    // 200 + 24 + 300 = 524: x from 378; the row 300 high from y 362.
    EXPECT_EQ(l.picture, (std::vector<Rect>{{378, 462, 200, 100}, {602, 362, 300, 300}}));
    EXPECT_EQ(l.label[0].y, 362 + 300 + 16);
}

}  // namespace
}  // namespace lucent::study

namespace lucent::study {
namespace {

TEST(AdjustLayout, TargetLeftMatchRightAtTrueSizeQuestionAboveHintBelow) {
    const AdjustLayout l = compute_adjust_layout(1280, 1024, {256, 256}, {256, 256}, 32);
    ASSERT_TRUE(l.fits);
    // 256 + 24 + 256 = 536 wide, centred: x = (1280 - 536) / 2 = 372.
    EXPECT_EQ(l.target, (Rect{372, 384, 256, 256}));
    EXPECT_EQ(l.match, (Rect{372 + 256 + 24, 384, 256, 256}));
    EXPECT_EQ(l.question, (Rect{0, 384 - 16 - 32, 1280, 32}));
    EXPECT_EQ(l.hint, (Rect{0, 384 + 256 + 16, 1280, 32}));
    // Pictures of two sizes keep theirs, centred on one line.
    const AdjustLayout m = compute_adjust_layout(1280, 1024, {200, 100}, {64, 64}, 32);
    ASSERT_TRUE(m.fits);
    EXPECT_EQ(m.target.width, 200);
    EXPECT_EQ(m.match.height, 64);
    EXPECT_EQ(m.target.y + 50, m.match.y + 32);
    EXPECT_FALSE(compute_adjust_layout(500, 1024, {256, 256}, {256, 256}, 32).fits);
    EXPECT_FALSE(compute_adjust_layout(1280, 300, {256, 256}, {256, 256}, 32).fits);
}

TEST(ChoiceLayout, AnOddOneOutsThreePicturesEachHaveTheirNameUnderThemAndTheirClicks) {
    Block oddity;
    oddity.task = Task::staircase;
    oddity.staircase_trial = "oddity";
    ChoiceLayoutInput in = choice_input(1280, 1024, Task::pair, ChoiceShow::all, 256);
    in.groups = Task::staircase->answer_groups(oddity);
    ASSERT_EQ(in.groups, (AnswerGroups{{0}, {1}, {2}}));
    in.pictures.assign(3, PictureSize{256, 256});
    const ChoiceLayout l = compute_choice_layout(in);
    ASSERT_TRUE(l.fits);
    ASSERT_EQ(l.picture.size(), 3u);
    ASSERT_EQ(l.label.size(), 3u);
    EXPECT_EQ(l.picture[0].x, (1280 - (3 * 256 + 2 * 24)) / 2);
    for (int k = 0; k < 3; ++k) {
        EXPECT_EQ(l.label[k].x, l.picture[k].x);
        EXPECT_EQ(l.label[k].y, l.picture[k].y + 256 + 16);
        EXPECT_EQ(l.bracket[k].width, 0);
        EXPECT_TRUE(l.alternative[k].contains(l.picture[k].x + 1, l.picture[k].y + 1));
        EXPECT_TRUE(l.alternative[k].contains(l.label[k].x + 1, l.label[k].y + 1));
        for (int j = 0; j < 3; ++j)
            if (j != k)
                EXPECT_FALSE(l.alternative[j].contains(l.picture[k].x + 128,
                                                       l.picture[k].y + 128));
    }
    EXPECT_EQ(l.question.y, l.picture[0].y - 16 - 32);
    in.screen_width = 700;
    EXPECT_FALSE(compute_choice_layout(in).fits);
}

// A kind of its own chooses between two groups of three pictures: laid out from its
// groups alone, as a quadruple's pairs are (edge-to-edge brackets, a wide gap between).
TEST(ChoiceLayout, AnyKindsGroupsAreLaidOutWithNoScreenCodeOfItsOwn) {
    ChoiceLayoutInput in = choice_input(1280, 1024, Task::pair, ChoiceShow::all, 100);
    in.groups = {{0, 1, 2}, {3, 4, 5}};
    in.pictures.assign(6, PictureSize{100, 100});
    const ChoiceLayout l = compute_choice_layout(in);
    ASSERT_TRUE(l.fits);
    // 6 x 100 + 4 x 24 + 96 = 792: x from 244; y (1024 - 100) / 2 = 462.
    ASSERT_EQ(l.picture.size(), 6u);
    EXPECT_EQ(l.picture[0], (Rect{244, 462, 100, 100}));
    EXPECT_EQ(l.picture[2], (Rect{492, 462, 100, 100}));
    EXPECT_EQ(l.picture[3], (Rect{688, 462, 100, 100}));
    EXPECT_EQ(l.picture[5], (Rect{936, 462, 100, 100}));
    EXPECT_EQ(l.bracket, (std::vector<Rect>{{244, 578, 348, 16}, {688, 578, 348, 16}}));
    EXPECT_EQ(l.label, (std::vector<Rect>{{244, 594, 348, 32}, {688, 594, 348, 32}}));
    EXPECT_EQ(l.alternative,
              (std::vector<Rect>{{244, 462, 348, 164}, {688, 462, 348, 164}}));
    // In sequence each part is one group, centred: 3 x 100 + 2 x 24 = 348 from 466.
    in.show = ChoiceShow::second_part;
    const ChoiceLayout second = compute_choice_layout(in);
    EXPECT_EQ(second.index, (std::vector<int>{3, 4, 5}));
    EXPECT_EQ(second.picture.front().x, 466);
    // Groups naming a picture the trial does not have do not fit (never drawn).
    in.show = ChoiceShow::all;
    in.groups = {{0}, {6}};
    EXPECT_FALSE(compute_choice_layout(in).fits);
    // Nor do groups leaving a picture unnamed, or an answer naming none.
    in.groups = {{0, 1, 2}, {4, 5}};
    EXPECT_FALSE(compute_choice_layout(in).fits);
    in.groups = {{0, 1, 2, 3, 4, 5}, {}};
    EXPECT_FALSE(compute_choice_layout(in).fits);
}

}  // namespace
}  // namespace lucent::study

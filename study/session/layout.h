#pragma once
// Where the stimulus and the rating panel go on screen, and where a forced choice's
// pictures, question, answers and click targets go (GL-free, unit-tested).
#include <vector>

#include "study/protocol.h"

namespace lucent::study {

struct Rect {
    int x = 0, y = 0, width = 0, height = 0;  // pixels, origin top-left
    bool contains(int px, int py) const {
        return px >= x && px < x + width && py >= y && py < y + height;
    }
    bool operator==(const Rect&) const = default;
};

struct ScreenLayout {
    Rect image;  // the stimulus, pixel for pixel (never scaled)
    Rect panel;  // statements and scales, along the bottom
};

// The image is centred on the screen; if it would overlap the panel it moves up just
// enough (never above the top edge). Panel: 90% of the width; a header row, two rows
// per question (statement, scale) and the Next button, each `row_height` pixels.
ScreenLayout compute_layout(int screen_width, int screen_height, int image_width,
                            int image_height, int questions, int row_height);

// ---- forced choices (issue 30) -------------------------------------------------------
// What a choice trial's screen shows now. Side by side: `all` (every picture with the
// answers under them). In sequence (two answers): the first part (the first answer's
// pictures: a pair's first picture, an MLDS trial's first pair), nothing (the blank),
// the second part, then the two answers.
enum class ChoiceShow { all, first_part, second_part, nothing, answers };

struct PictureSize {
    int width = 0, height = 0;
};

// Which pictures each answer names (TrialKind::answer_groups): a pair's {0}, {1}; a
// triad's {0, 1}, {1, 2}; a quadruple's {0, 1}, {2, 3}; an odd one out's {0}, {1}, {2}.
using AnswerGroups = std::vector<std::vector<int>>;

struct ChoiceLayoutInput {
    int screen_width = 0, screen_height = 0;
    AnswerGroups groups = {{0}, {1}};
    ChoiceShow show = ChoiceShow::all;
    std::vector<PictureSize> pictures;  // every picture of the trial, in screen order
    int row_height = 32;  // one line of text (the question, an answer's label)
    int gap = 24;         // between two pictures
    int group_gap = 96;   // between two answers' groups of several pictures each
};

struct ChoiceLayout {
    // False when the window is too small to show what `show` shows pixel for pixel with
    // the question and the answers: the trial waits (nothing else below is set).
    bool fits = true;
    // The pictures on screen now, pixel for pixel (never scaled): picture[k] shows the
    // trial's picture index[k] (an index into ChoiceLayoutInput::pictures).
    std::vector<Rect> picture;
    std::vector<int> index;
    Rect question;  // one row above the pictures (or the answer boxes), screen wide
    // One per answer, in answer order; none in a sequence's parts and its blank (the
    // answers are not shown yet). The answers' names, under what they name: a picture of
    // its own; a group of pictures (under a bracket spanning it); the answer boxes in
    // sequence.
    std::vector<Rect> label;
    // Side by side, each group's bracket, its ticks going up at x and x + width from
    // y + height to y: from edge to edge of its pictures, or, where the groups share a
    // picture (a triad), from centre to centre, so two meet at the shared picture's
    // centre. Empty (width 0) for an answer of one picture.
    std::vector<Rect> bracket;
    // In sequence, the Answer phase's boxes (the labels sit in them).
    std::vector<Rect> box;
    // Where a click picks an answer: its pictures with their bracket and label, split
    // at a shared picture's centre (a triad's left and right half); the boxes in
    // sequence.
    std::vector<Rect> alternative;
};

// The row of pictures is centred on the screen; the question row sits `row_height / 2`
// above it, the brackets and labels below it, the whole moved up or down just enough to
// stay on screen. Too wide or too tall for the screen: fits = false.
ChoiceLayout compute_choice_layout(const ChoiceLayoutInput& in);

// ---- matching and thresholds (issue 31) ---------------------------------------------
// An adjust trial: the target (left) and the live match (right) side by side, each pixel
// for pixel, laid out as a side-by-side pair; the question one row above them, the hint
// line (the keys) one row below. Too large for the screen: fits = false.
struct AdjustLayout {
    bool fits = true;
    Rect target, match, question, hint;
};
AdjustLayout compute_adjust_layout(int screen_width, int screen_height,
                                   PictureSize target, PictureSize match, int row_height,
                                   int gap = 24);

// Which picture indices a sequence's part shows: the first or the second answer's
// group. `all`: every picture of the groups; otherwise none.
std::vector<int> choice_part(const AnswerGroups& groups, ChoiceShow show);

}  // namespace lucent::study

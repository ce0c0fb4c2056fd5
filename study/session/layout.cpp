#include "study/session/layout.h"

#include <algorithm>

namespace lucent::study {

ScreenLayout compute_layout(int screen_width, int screen_height, int image_width,
                            int image_height, int questions, int row_height) {
    ScreenLayout l;
    const int panel_height = (2 * questions + 2) * row_height;  // statement + scale rows
    const int panel_width = screen_width * 9 / 10;
    l.panel = {(screen_width - panel_width) / 2, screen_height - panel_height,
               panel_width, panel_height};
    l.image = {(screen_width - image_width) / 2, (screen_height - image_height) / 2,
               image_width, image_height};
    const int margin = row_height / 2;
    if (l.image.y + image_height > l.panel.y - margin)
        l.image.y = std::max(0, l.panel.y - margin - image_height);
    return l;
}

std::vector<int> choice_part(const AnswerGroups& groups, ChoiceShow show) {
    std::vector<int> part;
    switch (show) {
        case ChoiceShow::all:
            for (const std::vector<int>& group : groups)
                part.insert(part.end(), group.begin(), group.end());
            std::sort(part.begin(), part.end());
            part.erase(std::unique(part.begin(), part.end()), part.end());
            break;
        case ChoiceShow::first_part:
        case ChoiceShow::second_part: {
            const size_t k = show == ChoiceShow::first_part ? 0 : 1;
            if (k < groups.size()) part = groups[k];
            break;
        }
        case ChoiceShow::nothing:
        case ChoiceShow::answers:
            break;
    }
    return part;
}

namespace {

Rect bounding(const Rect& a, const Rect& b) {
    const int x0 = std::min(a.x, b.x), y0 = std::min(a.y, b.y);
    const int x1 = std::max(a.x + a.width, b.x + b.width);
    const int y1 = std::max(a.y + a.height, b.y + b.height);
    return {x0, y0, x1 - x0, y1 - y0};
}

int centre(const Rect& r) { return r.x + r.width / 2; }

// How many answers name picture k (a triad's middle picture: two).
int answers_naming(const AnswerGroups& groups, int k) {
    int n = 0;
    for (const std::vector<int>& group : groups)
        n += std::count(group.begin(), group.end(), k) > 0 ? 1 : 0;
    return n;
}

// Neighbouring pictures a and b sit `group_gap` apart when they belong to different
// answers of several pictures each (a quadruple's two pairs), `gap` apart otherwise.
int gap_between(const ChoiceLayoutInput& in, int a, int b) {
    bool together = false, a_in_several = false, b_in_several = false;
    for (const std::vector<int>& group : in.groups) {
        const bool has_a = std::count(group.begin(), group.end(), a) > 0;
        const bool has_b = std::count(group.begin(), group.end(), b) > 0;
        together = together || (has_a && has_b);
        a_in_several = a_in_several || (has_a && group.size() > 1);
        b_in_several = b_in_several || (has_b && group.size() > 1);
    }
    return !together && a_in_several && b_in_several ? in.group_gap : in.gap;
}

// The pictures `indices` in a row starting at x, vertically centred in [row_y, row_y +
// row_height).
int row_width(const ChoiceLayoutInput& in, const std::vector<int>& indices) {
    int width = 0;
    for (size_t k = 0; k < indices.size(); ++k) {
        if (k > 0) width += gap_between(in, indices[k - 1], indices[k]);
        width += in.pictures[indices[k]].width;
    }
    return width;
}

void place_row(const ChoiceLayoutInput& in, const std::vector<int>& indices, int row_y,
               int row_height, ChoiceLayout& l) {
    int x = (in.screen_width - row_width(in, indices)) / 2;
    for (size_t k = 0; k < indices.size(); ++k) {
        if (k > 0) x += gap_between(in, indices[k - 1], indices[k]);
        const PictureSize& p = in.pictures[indices[k]];
        l.picture.push_back({x, row_y + (row_height - p.height) / 2, p.width, p.height});
        l.index.push_back(indices[k]);
        x += p.width;
    }
}

// Side by side: each answer's label (and bracket) under its pictures, and where a click
// picks it. `below`: the first row under the pictures.
void place_answers(const ChoiceLayoutInput& in, int below, ChoiceLayout& l) {
    const int row = in.row_height, tick = row / 2;
    bool shared = false;
    for (size_t k = 0; k < in.pictures.size(); ++k)
        shared = shared || answers_naming(in.groups, static_cast<int>(k)) > 1;
    for (const std::vector<int>& group : in.groups) {
        const Rect& first = l.picture[group.front()];
        const Rect& last = l.picture[group.back()];
        Rect bracket, label, alternative;
        if (group.size() == 1) {
            label = {first.x, below, first.width, row};
        } else {
            const int x0 = shared ? centre(first) : first.x;
            const int x1 = shared ? centre(last) : last.x + last.width;
            bracket = {x0, below, x1 - x0, tick};
            label = {x0, below + tick, x1 - x0, row};
        }
        alternative = label;
        for (int k : group) alternative = bounding(alternative, l.picture[k]);
        // A picture two answers name is split between them at its centre.
        if (answers_naming(in.groups, group.front()) > 1) {
            alternative.width -= centre(first) - alternative.x;
            alternative.x = centre(first);
        }
        if (answers_naming(in.groups, group.back()) > 1)
            alternative.width = centre(last) - alternative.x;
        l.bracket.push_back(bracket);
        l.label.push_back(label);
        l.alternative.push_back(alternative);
    }
}

void shift(ChoiceLayout& l, int dy) {
    auto move = [dy](Rect& r) {
        if (r.width > 0 || r.height > 0) r.y += dy;
    };
    for (Rect& r : l.picture) move(r);
    move(l.question);
    for (std::vector<Rect>* rects : {&l.label, &l.bracket, &l.box, &l.alternative})
        for (Rect& r : *rects) move(r);
}

}  // namespace

ChoiceLayout compute_choice_layout(const ChoiceLayoutInput& in) {
    ChoiceLayout l;
    const int W = in.screen_width, H = in.screen_height, row = in.row_height;
    const int margin = row / 2;
    const bool sequence = in.show != ChoiceShow::all;
    const std::vector<int> all = choice_part(in.groups, ChoiceShow::all);
    // Every picture named by an answer, every answer naming one: place_answers reads a
    // group's pictures by their index in the row.
    const bool empty_group = std::any_of(in.groups.begin(), in.groups.end(),
                                         [](const auto& group) { return group.empty(); });
    if (in.groups.empty() || empty_group || all.size() != in.pictures.size() ||
        all.front() != 0 || all.back() != static_cast<int>(in.pictures.size()) - 1)
        return ChoiceLayout{.fits = false};  // answers naming no picture shown
    // The row of pictures: every picture side by side; in sequence the tallest of them
    // (every part and the answer boxes centred on the same line, so the question stays
    // put through the sequence).
    int picture_height = 0;
    for (const PictureSize& p : in.pictures)
        picture_height = std::max(picture_height, p.height);
    const int answers = static_cast<int>(in.groups.size());
    const int box_width = 6 * row, box_height = 2 * row;
    const int boxes_width = answers * box_width + (answers - 1) * in.group_gap;
    const int row_height =
        sequence ? std::max(picture_height, box_height) : picture_height;
    int widest = 0;
    if (sequence) {
        for (ChoiceShow part : {ChoiceShow::first_part, ChoiceShow::second_part})
            widest = std::max(widest, row_width(in, choice_part(in.groups, part)));
        widest = std::max(widest, boxes_width);
    } else {
        widest = row_width(in, all);
    }
    const int row_y = (H - row_height) / 2;
    l.question = {0, row_y - margin - row, W, row};
    int bottom = row_y + row_height;
    if (!sequence) {
        place_row(in, all, row_y, row_height, l);
        place_answers(in, row_y + row_height + margin, l);
        for (const Rect& label : l.label)
            bottom = std::max(bottom, label.y + label.height);
    } else if (in.show == ChoiceShow::answers) {
        int x = (W - boxes_width) / 2;
        const int y = row_y + (row_height - box_height) / 2;
        for (int k = 0; k < answers; ++k, x += box_width + in.group_gap)
            l.box.push_back({x, y, box_width, box_height});
        l.label = l.box;
        l.alternative = l.box;
    } else {
        place_row(in, choice_part(in.groups, in.show), row_y, row_height, l);
    }
    const int top = l.question.y;
    if (widest > W || bottom - top > H) return ChoiceLayout{.fits = false};
    if (top < 0)
        shift(l, -top);
    else if (bottom > H)
        shift(l, H - bottom);
    return l;
}

AdjustLayout compute_adjust_layout(int screen_width, int screen_height,
                                   PictureSize target, PictureSize match, int row_height,
                                   int gap) {
    ChoiceLayoutInput in;
    in.screen_width = screen_width;
    in.screen_height = screen_height;
    in.show = ChoiceShow::all;  // laid out as a pair: {0}, {1}
    in.pictures = {target, match};
    in.row_height = row_height;
    in.gap = gap;
    const ChoiceLayout pair = compute_choice_layout(in);
    if (!pair.fits) return AdjustLayout{.fits = false};
    AdjustLayout l;
    l.target = pair.picture[0];
    l.match = pair.picture[1];
    l.question = pair.question;
    l.hint = {0, pair.label[0].y, screen_width, row_height};
    return l;
}

}  // namespace lucent::study

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

std::vector<int> choice_part(Task task, ChoiceShow show) {
    switch (show) {
        case ChoiceShow::all:
            return task == Task::pair    ? std::vector<int>{0, 1}
                   : task == Task::triad ? std::vector<int>{0, 1, 2}
                                         : std::vector<int>{0, 1, 2, 3};
        case ChoiceShow::first_part:
            return task == Task::pair ? std::vector<int>{0} : std::vector<int>{0, 1};
        case ChoiceShow::second_part:
            return task == Task::pair    ? std::vector<int>{1}
                   : task == Task::triad ? std::vector<int>{1, 2}
                                         : std::vector<int>{2, 3};
        case ChoiceShow::nothing:
        case ChoiceShow::answers:
            break;
    }
    return {};
}

namespace {

Rect bounding(const Rect& a, const Rect& b) {
    const int x0 = std::min(a.x, b.x), y0 = std::min(a.y, b.y);
    const int x1 = std::max(a.x + a.width, b.x + b.width);
    const int y1 = std::max(a.y + a.height, b.y + b.height);
    return {x0, y0, x1 - x0, y1 - y0};
}

// The pictures `indices` in a row starting at x, vertically centred in [row_y, row_y +
// row_height); a quadruple's pictures 1 and 2 `group_gap` apart, others `gap`.
int row_width(const ChoiceLayoutInput& in, const std::vector<int>& indices) {
    int width = 0;
    for (size_t k = 0; k < indices.size(); ++k) {
        if (k > 0)
            width += in.task == Task::quadruple && indices[k] == 2 && indices[k - 1] == 1
                         ? in.group_gap
                         : in.gap;
        width += in.pictures[indices[k]].width;
    }
    return width;
}

void place_row(const ChoiceLayoutInput& in, const std::vector<int>& indices, int row_y,
               int row_height, ChoiceLayout& l) {
    int x = (in.screen_width - row_width(in, indices)) / 2;
    for (size_t k = 0; k < indices.size(); ++k) {
        if (k > 0)
            x += in.task == Task::quadruple && indices[k] == 2 && indices[k - 1] == 1
                     ? in.group_gap
                     : in.gap;
        const PictureSize& p = in.pictures[indices[k]];
        l.picture.push_back({x, row_y + (row_height - p.height) / 2, p.width, p.height});
        l.index.push_back(indices[k]);
        x += p.width;
    }
}

void shift(ChoiceLayout& l, int dy) {
    auto move = [dy](Rect& r) {
        if (r.width > 0 || r.height > 0) r.y += dy;
    };
    for (Rect& r : l.picture) move(r);
    move(l.question);
    for (int k = 0; k < 2; ++k) {
        move(l.label[k]);
        move(l.bracket[k]);
        move(l.box[k]);
        move(l.alternative[k]);
    }
}

}  // namespace

ChoiceLayout compute_choice_layout(const ChoiceLayoutInput& in) {
    ChoiceLayout l;
    const int W = in.screen_width, H = in.screen_height, row = in.row_height;
    const int margin = row / 2;
    const bool sequence = in.show != ChoiceShow::all;
    // The row of pictures: every picture side by side; in sequence the tallest of them
    // (every part and the answer boxes centred on the same line, so the question stays
    // put through the sequence).
    int picture_height = 0;
    for (const PictureSize& p : in.pictures)
        picture_height = std::max(picture_height, p.height);
    const int box_width = 6 * row, box_height = 2 * row;
    const int row_height =
        sequence ? std::max(picture_height, box_height) : picture_height;
    int widest = 0;
    if (sequence) {
        for (ChoiceShow part : {ChoiceShow::first_part, ChoiceShow::second_part})
            widest = std::max(widest, row_width(in, choice_part(in.task, part)));
        widest = std::max(widest, 2 * box_width + in.group_gap);
    } else {
        widest = row_width(in, choice_part(in.task, ChoiceShow::all));
    }
    const int row_y = (H - row_height) / 2;
    l.question = {0, row_y - margin - row, W, row};
    int bottom = row_y + row_height;
    if (!sequence) {
        place_row(in, choice_part(in.task, ChoiceShow::all), row_y, row_height, l);
        const int below = row_y + row_height + margin;
        const std::vector<Rect>& p = l.picture;
        if (in.task == Task::pair) {
            for (int k = 0; k < 2; ++k) {
                l.label[k] = {p[k].x, below, p[k].width, row};
                l.alternative[k] = bounding(p[k], l.label[k]);
            }
        } else {
            const int tick = margin;
            if (in.task == Task::triad) {
                const int c0 = p[0].x + p[0].width / 2, c1 = p[1].x + p[1].width / 2,
                          c2 = p[2].x + p[2].width / 2;
                l.bracket[0] = {c0, below, c1 - c0, tick};
                l.bracket[1] = {c1, below, c2 - c1, tick};
            } else {
                l.bracket[0] = {p[0].x, below, p[1].x + p[1].width - p[0].x, tick};
                l.bracket[1] = {p[2].x, below, p[3].x + p[3].width - p[2].x, tick};
            }
            for (int k = 0; k < 2; ++k)
                l.label[k] = {l.bracket[k].x, below + tick, l.bracket[k].width, row};
            if (in.task == Task::triad) {
                const int x0 = p[0].x, x1 = l.bracket[1].x, x2 = p[2].x + p[2].width;
                const int y1 = l.label[0].y + row;
                l.alternative[0] = {x0, row_y, x1 - x0, y1 - row_y};
                l.alternative[1] = {x1, row_y, x2 - x1, y1 - row_y};
            } else {
                l.alternative[0] = bounding(bounding(p[0], p[1]), l.label[0]);
                l.alternative[1] = bounding(bounding(p[2], p[3]), l.label[1]);
            }
        }
        bottom = l.label[0].y + row;
    } else if (in.show == ChoiceShow::answers) {
        const int x0 = (W - (2 * box_width + in.group_gap)) / 2;
        const int y = row_y + (row_height - box_height) / 2;
        l.box[0] = {x0, y, box_width, box_height};
        l.box[1] = {x0 + box_width + in.group_gap, y, box_width, box_height};
        l.label = l.box;
        l.alternative = l.box;
    } else {
        place_row(in, choice_part(in.task, in.show), row_y, row_height, l);
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
    in.task = Task::pair;
    in.show = ChoiceShow::all;
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

OddityLayout compute_oddity_layout(int screen_width, int screen_height,
                                   const std::vector<PictureSize>& pictures,
                                   int row_height, int gap) {
    ChoiceLayoutInput in;
    in.screen_width = screen_width;
    in.screen_height = screen_height;
    in.task = Task::triad;
    in.show = ChoiceShow::all;
    in.pictures = pictures;
    in.row_height = row_height;
    in.gap = gap;
    const ChoiceLayout triad = compute_choice_layout(in);
    if (!triad.fits || pictures.size() != 3) return OddityLayout{.fits = false};
    OddityLayout l;
    l.picture = triad.picture;
    l.question = triad.question;
    // The names one row under the pictures, where a triad's brackets start.
    const int below = triad.bracket[0].y;
    for (const Rect& p : l.picture) {
        l.label.push_back({p.x, below, p.width, row_height});
        l.alternative.push_back(bounding(p, l.label.back()));
    }
    return l;
}

}  // namespace lucent::study

#pragma once
// Where the stimulus and the rating panel go on screen (GL-free, unit-tested).
namespace lucent::study {

struct Rect {
    int x = 0, y = 0, width = 0, height = 0;  // pixels, origin top-left
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

}  // namespace lucent::study

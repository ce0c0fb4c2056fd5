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

}  // namespace lucent::study

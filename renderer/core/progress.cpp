#include "renderer/core/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace lucent {

ProgressBar::ProgressBar(std::string label, std::size_t total, ProgressBarOptions options)
    : label_(std::move(label)),
      total_(total),
      options_(options),
      enabled_(options.force || isatty(STDERR_FILENO)),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

ProgressBar::~ProgressBar() { finish(); }

void ProgressBar::update(std::size_t done) {
    if (!enabled_ || finished_) return;
    const auto now = std::chrono::steady_clock::now();
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    if (elapsed < options_.show_after_seconds) return;
    if (shown_ && now - last_draw_ < std::chrono::milliseconds(100)) return;
    last_draw_ = now;
    draw(done, elapsed);
}

void ProgressBar::finish() {
    if (finished_) return;
    finished_ = true;
    if (!shown_) return;
    draw(
        total_,
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count());
    std::fputc('\n', stderr);
    std::fflush(stderr);
}

std::function<void(std::size_t, std::size_t)> ProgressBar::callback() {
    return [this](std::size_t done, std::size_t) { update(done); };
}

void ProgressBar::draw(std::size_t done, double elapsed) {
    constexpr int kWidth = 30;
    const double fraction =
        total_ == 0 ? 1.0 : std::min(1.0, double(done) / double(total_));
    const int filled = static_cast<int>(fraction * kWidth);
    std::string bar(filled, '#');
    bar.append(kWidth - filled, '.');
    // \r returns to the line start; trailing spaces clear a longer previous line.
    std::fprintf(stderr, "\r%s [%s] %3d%%  %.1f s   ", label_.c_str(), bar.c_str(),
                 static_cast<int>(fraction * 100.0), elapsed);
    std::fflush(stderr);
    shown_ = true;
}

}  // namespace lucent

#pragma once
// A one-line progress bar on stderr for long work, e.g.
//   AO bake torus_knot:240k [##########..........]  52%  1.3 s
// Redraws at most ~10 times a second, only on a terminal (unless forced), and only once
// the work has run for `show_after_seconds`, so short jobs print nothing.
#include <chrono>
#include <cstddef>
#include <functional>
#include <string>

namespace lucent {

struct ProgressBarOptions {
    double show_after_seconds = 0.5;  // stay silent for work shorter than this
    bool force = false;               // draw even when stderr is not a terminal
};

class ProgressBar {
public:
    ProgressBar(std::string label, std::size_t total, ProgressBarOptions options = {});
    ~ProgressBar();  // finishes the line if anything was drawn
    ProgressBar(const ProgressBar&) = delete;
    ProgressBar& operator=(const ProgressBar&) = delete;

    // Call from one thread with the amount done so far.
    void update(std::size_t done);
    // Draws 100% and ends the line (if the bar was ever shown). Idempotent.
    void finish();
    // For APIs taking a (done, total) callback, such as AoBakeOptions::progress. The
    // bar must outlive the callback's uses.
    std::function<void(std::size_t, std::size_t)> callback();

private:
    void draw(std::size_t done, double elapsed);

    std::string label_;
    std::size_t total_;
    ProgressBarOptions options_;
    bool enabled_;
    bool shown_ = false;
    bool finished_ = false;
    std::chrono::steady_clock::time_point start_;
    std::chrono::steady_clock::time_point last_draw_;
};

}  // namespace lucent

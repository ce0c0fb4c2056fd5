#pragma once
// The session's state machine, GL-free so tests drive it with synthetic, timestamped
// keys and a fake clock: consent, instructions, practice, trials with blanks and breaks,
// debrief, and the pause screen over any of them. The runner (runner.cpp) only draws
// what it says and feeds it keys, clicks, clock ticks and presentation times.
//
// Two rules hold on every screen:
// - A key counts only on a screen that was on the display when the key went down: keys
//   stamped before the screen's first presented frame are dropped as stale, so a quick
//   double Enter cannot skip a break screen it never showed.
// - The last trial's ratings and the status `completed` are one transaction
//   (StudyStore::record_trial), and nothing turns a completed session back into paused.
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "study/adaptive/staircase_block.h"
#include "study/protocol.h"
#include "study/session/adjust_input.h"
#include "study/session/autopilot.h"
#include "study/session/rating_input.h"
#include "study/sqlite/sqlite_store.h"
#include "study/web_series.h"

namespace lucent::study {

enum class Screen {
    Consent,
    Instructions,
    PracticeDone,
    Blank,
    Trial,
    Break,
    Debrief,
    Done
};

// A forced choice on the Trial screen. Side by side: Answer from the onset (every
// picture on screen with the two answers). In sequence: the first picture (a pair's
// first, an MLDS trial's first pair) for the block's duration_ms, a blank for
// blank_ms, the second for duration_ms, then Answer (the two answers only).
enum class ChoicePhase { First, Gap, Second, Answer };

// Where a flow stands between two actions of a browser's page (`lucent serve`): the
// screen (never Trial: a trial's screen lasts only within the request answering it),
// its view number, when it began on the page's clock, and the first open trial (0: none).
struct FlowPosition {
    Screen screen = Screen::Blank;
    int serial = 0;
    int64_t entered_ns = 0;
    int64_t trial_id = 0;
};

// How a session ended, mapped to exit codes by the caller.
enum class RunResult { Completed, SavedAndQuit, Declined, UsageError, Failure };

// The keys a session listens to (from X key events or GLFW, see runner.cpp).
enum class Key { Digit, Enter, Escape, Left, Right, Up, Down, Quit, Resume, Decline };

struct TimedKey {
    Key key = Key::Enter;
    int digit = 0;       // 1..9 for Key::Digit
    int64_t t_ns = 0;    // steady clock, when the key went down
    bool shift = false;  // held with Shift (an adjustment's fine step)
};

// The flow's key for one of the autopilot's key names (ScheduledKey::key: "1".."9",
// "Enter", "Escape", "Left", "Right", "Up", "Down", "Q", "R", "Shift+ARROW"), pressed at
// `t_ns`: what a GL-free driver of a simulated participant feeds SessionFlow::key (the
// runner sends the names as X key events instead). Unknown names give Enter.
TimedKey autopilot_key(const std::string& name, int64_t t_ns);

class SessionFlow {
public:
    // `trials`: the session's planned trials as stored; `consented`: consent already
    // recorded (a resumed session). Starts at the first unanswered trial.
    SessionFlow(const Protocol& protocol, StudyStore& store, int64_t session_id,
                std::vector<TrialRow> trials, bool consented, int64_t now_ns);

    // ---- input -----------------------------------------------------------------------
    // A key, or an on-screen button standing for one (clicked at `t_ns`).
    void key(const TimedKey& press);
    // The mouse on the rating screen: a point on a scale, the "Next" button.
    void click_point(int question, int value, int64_t t_ns);
    void click_next(int64_t t_ns);
    // A click on a forced choice's alternative (1 or 2: a picture, or a pair's group):
    // picks it and confirms at once.
    void click_choice(int alternative, int64_t t_ns);
    // An adjust trial's match: wheel notches (positive: up), a horizontal drag of dx
    // pixels across a match `width_px` wide (AdjustInput).
    void wheel(double notches, int64_t t_ns);
    void drag(double dx_px, double width_px, int64_t t_ns);
    void window_closed();  // by the window manager; saves and quits unless completed
    // Time passes: the blank between trials gives way to the stimulus.
    void tick(int64_t now_ns);
    // A frame drawn while serial() was `serial` reached the display at `t_ns` (right
    // after the swap, after glFinish). The first one is the screen's appearance, and on
    // a trial the stimulus onset; later ones are the trial's frame times.
    void presented(int serial, int64_t t_ns);
    // The display's refresh rate, once measured: trials then record dropped frames.
    void set_refresh_hz(std::optional<double> hz) { refresh_hz_ = hz; }
    // `lucent serve`: an adjust block's match moves over its pre-rendered series (the
    // value is the nearest picture's) and a staircase delta is shown, answered and
    // stored as its ladder's nearest rung (web_series.h). Null (the default): the lab's
    // continuous values. `series` must outlive the flow and its copies.
    void show_series(const WebSeries* series) { series_ = series; }
    // `lucent serve`: continues a page where a request (perhaps of another serve process)
    // left it. Applied only when it fits the trials as stored: the same first open trial,
    // and a screen that can stand before it (instructions before any answer, a break or
    // practice-done before an open trial, the debrief after the last, consent only
    // before consent was recorded); false, and nothing changed, otherwise.
    bool restore(const FlowPosition& position);
    // Where the flow stands now (at a request's end: nothing presented yet).
    FlowPosition position() const;

    // ---- state -----------------------------------------------------------------------
    Screen screen() const { return screen_; }
    bool paused() const { return paused_; }
    bool finished() const { return finished_; }
    RunResult result() const { return result_; }
    // Increases whenever what is on screen changes (screen, pause, stimulus onset).
    int serial() const { return serial_; }
    bool awaiting_presentation() const { return !presented_ns_.has_value(); }
    // The trial on a Blank or Trial screen; the rating input once the stimulus is shown.
    const TrialRow* trial() const;
    const RatingInput* rating() const { return input_ ? &*input_ : nullptr; }
    // An adjust trial's input once the target is shown (its value is the match's knob;
    // the same screen goes on while it moves: its revision() says when to redraw).
    const AdjustInput* adjustment() const { return adjust_ ? &*adjust_ : nullptr; }
    // A staircase slot on a Blank or Trial screen: the delta its procedure chose (the
    // comparison is the standard with the block's knob moved by it, Block::direction),
    // and the comparison's value of the knob.
    std::optional<adaptive::Proposal> staircase_delta() const;
    std::optional<double> comparison_value() const;
    // The value of a block's knob for a stimulus (its parameter, else the knob's
    // default): an adjust target's, a staircase standard's.
    double knob_value(const std::string& stimulus, const std::string& knob) const;
    // The block of the trial on screen (nullptr between trials).
    const Block* block() const;
    // The scales of the trial on screen, when its kind answers on the scales screen (a
    // rating's [[questions]]; a kind's own question); none otherwise.
    // Computed once per trial: the lab draws them every frame.
    const std::vector<Question>& questions() const;
    // On a forced choice's Trial screen, what it shows now; nullopt otherwise.
    std::optional<ChoicePhase> choice_phase() const;
    const std::string& text()
        const;  // Consent, Instructions, PracticeDone, Break, Debrief
    size_t answered_trials() const { return current_; }
    size_t total_trials() const { return trials_.size(); }
    int main_trials_done() const;
    int main_trials_total() const;
    ScreenView view() const;  // what the autopilot sees

private:
    void enter(Screen screen, int64_t t_ns);
    void changed();
    void begin_trial_or_debrief(int64_t t_ns);
    void finish_trial();
    void quit_saving();
    bool choice_trial() const;
    void start_trial_presentation();  // phase and input back to the trial's start
    // Past answered and skipped trials; a staircase slot gets its delta (skipped when
    // its procedure has finished).
    void advance_to_open_trial();
    adaptive::StaircaseBlock& staircase_block(const Block& block);
    AdjustView adjust_view() const;

    const Protocol& protocol_;
    StudyStore& store_;
    int64_t session_id_;
    bool consented_ = false;  // on record when the flow was made, or recorded by it
    std::vector<TrialRow> trials_;
    size_t current_ = 0;                       // the first unanswered trial
    mutable std::vector<Question> questions_;  // of trial questions_of_
    mutable size_t questions_of_ = SIZE_MAX;
    Screen screen_ = Screen::Consent;
    bool paused_ = false;
    bool finished_ = false;
    RunResult result_ = RunResult::Completed;
    int serial_ = 0;
    int64_t entered_ns_ = 0;
    std::optional<int64_t> presented_ns_;
    std::optional<RatingInput> input_;
    std::optional<AdjustInput> adjust_;
    // The staircase blocks' procedures by block id, rebuilt from trials_ when first
    // needed; a copy of the flow starts without them and rebuilds its own (a procedure
    // is state that two flows must not share).
    struct StaircaseCache {
        std::map<std::string, adaptive::StaircaseBlock> blocks;
        StaircaseCache() = default;
        StaircaseCache(const StaircaseCache&) {}
        StaircaseCache(StaircaseCache&&) = default;
        StaircaseCache& operator=(const StaircaseCache&) {
            blocks.clear();
            return *this;
        }
        StaircaseCache& operator=(StaircaseCache&&) = default;
    };
    StaircaseCache staircases_;
    std::optional<adaptive::Proposal> delta_;  // the current staircase slot's
    ChoicePhase phase_ = ChoicePhase::Answer;
    std::optional<int64_t> trial_onset_ns_;  // the trial's first picture on the display
    std::vector<int64_t> trial_frames_ns_;
    std::optional<double> refresh_hz_;
    const WebSeries* series_ = nullptr;
};

}  // namespace lucent::study

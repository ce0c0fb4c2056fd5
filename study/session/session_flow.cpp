#include "study/session/session_flow.h"

#include <algorithm>
#include <variant>

#include "renderer/techniques/registry.h"
#include "study/session/frame_timing.h"

namespace lucent::study {

TimedKey autopilot_key(const std::string& name, int64_t t_ns) {
    TimedKey press;
    press.t_ns = t_ns;
    std::string key = name;
    press.shift = key.rfind("Shift+", 0) == 0;
    if (press.shift) key = key.substr(6);
    if (key.size() == 1 && key[0] >= '1' && key[0] <= '9') {
        press.key = Key::Digit;
        press.digit = key[0] - '0';
    } else if (key == "Escape") {
        press.key = Key::Escape;
    } else if (key == "Left") {
        press.key = Key::Left;
    } else if (key == "Right") {
        press.key = Key::Right;
    } else if (key == "Up") {
        press.key = Key::Up;
    } else if (key == "Down") {
        press.key = Key::Down;
    } else if (key == "Q") {
        press.key = Key::Quit;
    } else if (key == "R") {
        press.key = Key::Resume;
    } else {
        press.key = Key::Enter;
    }
    return press;
}

SessionFlow::SessionFlow(const Protocol& protocol, StudyStore& store, int64_t session_id,
                         std::vector<TrialRow> trials, bool consented, int64_t now_ns)
    : protocol_(protocol),
      store_(store),
      session_id_(session_id),
      consented_(consented),
      trials_(std::move(trials)) {
    advance_to_open_trial();
    // A resumed session continues at its first open trial once consent is on record.
    if (current_ == trials_.size())
        enter(Screen::Debrief, now_ns);
    else if (current_ > 0 && consented)
        enter(Screen::Blank, now_ns);
    else
        enter(protocol_.screens.consent.empty() ? Screen::Instructions : Screen::Consent,
              now_ns);
}

bool SessionFlow::restore(const FlowPosition& p) {
    const int64_t open = current_ < trials_.size() ? trials_[current_].id : 0;
    if (p.trial_id != open || finished_ || paused_) return false;
    bool answered_any = false;
    for (const TrialRow& t : trials_) answered_any = answered_any || t.answered;
    const bool before_trial = consented_ && current_ < trials_.size();
    bool fits = false;
    switch (p.screen) {
        case Screen::Consent:
            fits = !consented_;
            break;
        case Screen::Instructions:
            fits = before_trial && !answered_any;
            break;
        case Screen::PracticeDone:
        case Screen::Break:
        case Screen::Blank:
            fits = before_trial;
            break;
        case Screen::Debrief:
            fits = current_ == trials_.size();
            break;
        case Screen::Trial:
        case Screen::Done:
            fits = false;
            break;
    }
    if (!fits) return false;
    screen_ = p.screen;
    serial_ = p.serial;
    entered_ns_ = p.entered_ns;
    start_trial_presentation();
    presented_ns_.reset();
    return true;
}

FlowPosition SessionFlow::position() const {
    return {screen_, serial_, entered_ns_,
            current_ < trials_.size() ? trials_[current_].id : 0};
}

const TrialRow* SessionFlow::trial() const {
    if ((screen_ != Screen::Blank && screen_ != Screen::Trial) ||
        current_ >= trials_.size())
        return nullptr;
    return &trials_[current_];
}

const std::string& SessionFlow::text() const {
    static const std::string none;
    switch (screen_) {
        case Screen::Consent:
            return protocol_.screens.consent;
        case Screen::Instructions:
            return protocol_.screens.instructions;
        case Screen::PracticeDone:
            return protocol_.screens.practice_done;
        case Screen::Break:
            return protocol_.screens.break_text;
        case Screen::Debrief:
            return protocol_.screens.debrief;
        default:
            return none;
    }
}

const Block* SessionFlow::block() const {
    const TrialRow* t = trial();
    return t ? protocol_.find_block(t->block) : nullptr;
}

const std::vector<Question>& SessionFlow::questions() const {
    static const std::vector<Question> none;
    const TrialRow* t = trial();
    if (!t || t->task->screen() != TrialScreen::scales) return none;
    if (questions_of_ != current_) {
        questions_ = t->task->questions(protocol_, block());
        questions_of_ = current_;
    }
    return questions_;
}

bool SessionFlow::choice_trial() const {
    return current_ < trials_.size() && is_choice_task(trials_[current_].task);
}

adaptive::StaircaseBlock& SessionFlow::staircase_block(const Block& block) {
    auto it = staircases_.blocks.find(block.id);
    if (it == staircases_.blocks.end()) {
        it = staircases_.blocks.emplace(block.id, adaptive::StaircaseBlock(block)).first;
        try {
            it->second.replay(trials_);
        } catch (const std::exception& e) {
            staircases_.blocks.erase(it);
            throw StoreError(store_.name() + ": " + e.what());
        }
        // A slot on screen already has its delta: its procedure waits for the answer
        // again (the same proposal: the procedures are deterministic).
        if (delta_ && current_ < trials_.size() && trials_[current_].block == block.id &&
            trials_[current_].task->screen() == TrialScreen::staircase)
            it->second.propose(trials_[current_].staircase);
    }
    return it->second;
}

void SessionFlow::advance_to_open_trial() {
    delta_.reset();
    for (; current_ < trials_.size(); ++current_) {
        TrialRow& t = trials_[current_];
        if (t.answered || t.skipped) continue;
        if (t.task->screen() != TrialScreen::staircase) return;
        adaptive::StaircaseBlock& b = staircase_block(*protocol_.find_block(t.block));
        // A procedure that finished has its open slots skipped in the store, in the
        // transaction of its last answer; one that reached its cap has no slots left.
        if (b.finished(t.staircase)) {
            t.skipped = true;
            continue;
        }
        delta_ = b.propose(t.staircase);
        return;
    }
}

std::optional<adaptive::Proposal> SessionFlow::staircase_delta() const {
    if (!trial() || trials_[current_].task->screen() != TrialScreen::staircase || !delta_)
        return std::nullopt;
    const KnobSeries* ladder =
        series_ ? series_->find(trials_[current_].block, trials_[current_].stimulus)
                : nullptr;
    if (!ladder) return delta_;
    // The browser shows the ladder's nearest rung, and that is the delta answered.
    adaptive::Proposal shown = *delta_;
    shown.intensity = ladder->steps[nearest_step(ladder->steps, delta_->intensity)];
    return shown;
}

double SessionFlow::knob_value(const std::string& stimulus,
                               const std::string& knob) const {
    return stimulus_knob_value(protocol_, stimulus, knob);
}

std::optional<double> SessionFlow::comparison_value() const {
    const std::optional<adaptive::Proposal> d = staircase_delta();
    if (!d) return std::nullopt;
    const Block* b = block();
    const double standard = knob_value(trials_[current_].stimulus, b->knob);
    return b->direction == "down" ? standard - d->intensity : standard + d->intensity;
}

std::optional<ChoicePhase> SessionFlow::choice_phase() const {
    if (screen_ != Screen::Trial || !choice_trial()) return std::nullopt;
    return phase_;
}

void SessionFlow::start_trial_presentation() {
    input_.reset();
    adjust_.reset();
    trial_frames_ns_.clear();
    trial_onset_ns_.reset();
    const Block* b = current_ < trials_.size()
                         ? protocol_.find_block(trials_[current_].block)
                         : nullptr;
    phase_ = choice_trial() && b && b->presentation == Presentation::sequential
                 ? ChoicePhase::First
                 : ChoicePhase::Answer;
}

int SessionFlow::main_trials_done() const {
    int n = 0;
    for (size_t i = 0; i < current_; ++i) n += trials_[i].practice ? 0 : 1;
    return n;
}

int SessionFlow::main_trials_total() const {
    int n = 0;
    for (const TrialRow& t : trials_) n += t.practice ? 0 : 1;
    return n;
}

ScreenView SessionFlow::view() const {
    ScreenView v;
    v.serial = serial_;
    if (paused_) {
        v.kind = ScreenView::Kind::Pause;
        return v;
    }
    switch (screen_) {
        case Screen::Trial:
            v.is_catch = trials_[current_].is_catch;
            v.expected = trials_[current_].expected;
            switch (trials_[current_].task->screen()) {
                case TrialScreen::adjust:
                    v.kind = adjust_ ? ScreenView::Kind::Adjust : ScreenView::Kind::Blank;
                    if (adjust_) v.adjust = adjust_view();
                    break;
                case TrialScreen::staircase:
                    v.kind =
                        input_ ? ScreenView::Kind::Staircase : ScreenView::Kind::Blank;
                    v.staircase.delta = delta_ ? staircase_delta()->intensity : 0.0;
                    v.staircase.answers = block()->answers();
                    v.staircase.comparison_place = trials_[current_].expected;
                    break;
                case TrialScreen::choice:
                    v.kind = input_ ? ScreenView::Kind::Choice : ScreenView::Kind::Blank;
                    v.choice = choice_stimuli(protocol_, trials_[current_].block,
                                              trials_[current_].shown);
                    break;
                case TrialScreen::scales:
                    v.kind = input_ ? ScreenView::Kind::Rating : ScreenView::Kind::Blank;
                    for (const Question& q : questions()) v.points.push_back(q.points());
                    break;
            }
            break;
        case Screen::Blank:
        case Screen::Done:
            v.kind = ScreenView::Kind::Blank;
            break;
        default:
            v.kind = ScreenView::Kind::Text;
            break;
    }
    return v;
}

AdjustView SessionFlow::adjust_view() const {
    const Block& b = *block();
    AdjustView a;
    a.value = adjust_->value();
    a.lo = b.range_min;
    a.hi = b.range_max;
    a.step = b.step;
    a.fine_step = b.fine_step;
    a.log_scale = b.scale == "log";
    // The value the simulated observer's match centres on: the target's own value of
    // the knob when it is drawn by the match's technique; otherwise (a picture, another
    // technique: the built-in matching study's dipole targets) the simulation takes the
    // match stimulus's protocol value as what the target looks like, a known reference
    // the analysis's bias is checked against.
    const Stimulus* target = protocol_.find_stimulus(trials_[current_].stimulus);
    const Stimulus* match = protocol_.find_stimulus(b.match);
    if (target && match && target->live() && target->technique == match->technique)
        a.target = knob_value(target->id, b.knob);
    else if (match)
        a.target = std::clamp(knob_value(match->id, b.knob), b.range_min, b.range_max);
    return a;
}

void SessionFlow::changed() {
    ++serial_;
    presented_ns_.reset();
}

void SessionFlow::enter(Screen screen, int64_t t_ns) {
    screen_ = screen;
    entered_ns_ = t_ns;
    start_trial_presentation();
    changed();
}

void SessionFlow::begin_trial_or_debrief(int64_t t_ns) {
    enter(current_ < trials_.size() ? Screen::Blank : Screen::Debrief, t_ns);
}

void SessionFlow::tick(int64_t now_ns) {
    if (finished_ || paused_) return;
    if (screen_ == Screen::Blank) {
        if (now_ns - entered_ns_ >= protocol_.inter_trial_ms * 1'000'000LL)
            enter(Screen::Trial, now_ns);
        return;
    }
    // A sequence moves on once each part has been on the display for its duration,
    // counted from the frame that showed it.
    if (screen_ != Screen::Trial || phase_ == ChoicePhase::Answer || !presented_ns_)
        return;
    const Block* b = block();
    const int ms = phase_ == ChoicePhase::Gap ? b->blank_ms : b->duration_ms;
    if (now_ns - *presented_ns_ < ms * 1'000'000LL) return;
    phase_ = static_cast<ChoicePhase>(static_cast<int>(phase_) + 1);
    changed();
}

void SessionFlow::presented(int serial, int64_t t_ns) {
    if (finished_ || serial != serial_) return;  // a frame of a screen already left
    if (!presented_ns_) {
        presented_ns_ = t_ns;
        if (screen_ == Screen::Trial && !paused_) {
            if (!trial_onset_ns_) {  // the stimulus onset
                trial_onset_ns_ = t_ns;
                trial_frames_ns_.assign(1, t_ns);
            } else {
                trial_frames_ns_.push_back(t_ns);
            }
            if (phase_ != ChoicePhase::Answer) return;  // a sequence: not answerable yet
            const TrialRow& t = trials_[current_];
            switch (t.task->screen()) {
                case TrialScreen::adjust: {
                    const KnobSeries* series =
                        series_ ? series_->find(t.block, block()->match) : nullptr;
                    if (series)
                        adjust_.emplace(*block(), t.start_value.value_or(0.0), t_ns,
                                        series->steps);
                    else
                        adjust_.emplace(*block(), t.start_value.value_or(0.0), t_ns);
                    break;
                }
                case TrialScreen::choice:
                case TrialScreen::staircase:
                    input_.emplace(RatingInput::forced_choice(t_ns, block()->answers()));
                    break;
                case TrialScreen::scales: {
                    std::vector<int> points;
                    for (const Question& q : questions()) points.push_back(q.points());
                    input_.emplace(std::move(points), t_ns);
                    break;
                }
            }
            ++serial_;  // the answer screen is a new view (same presentation)
        }
        return;
    }
    if (screen_ == Screen::Trial && trial_onset_ns_ && !paused_)
        trial_frames_ns_.push_back(t_ns);
}

void SessionFlow::key(const TimedKey& press) {
    if (finished_) return;
    // Stale: the key went down before this screen reached the display (or it has not
    // yet), so it was meant for what was on screen before.
    if (!presented_ns_ || press.t_ns < *presented_ns_) return;
    if (paused_) {
        if (press.key == Key::Enter || press.key == Key::Resume) {
            paused_ = false;
            changed();
            // A trial starts again from a new onset, without answers: RTs skip the pause
            // (a sequence is shown again from its first part).
            if (screen_ == Screen::Trial) start_trial_presentation();
        } else if (press.key == Key::Quit) {
            quit_saving();
        }
        return;
    }
    if (press.key == Key::Escape) {
        // The debrief follows completion: nothing there can pause (or reopen) the
        // session.
        if (screen_ != Screen::Debrief && screen_ != Screen::Done) {
            paused_ = true;
            changed();
        }
        return;
    }
    switch (screen_) {
        case Screen::Consent:
            if (press.key == Key::Enter) {
                // Consent already on record (an online enrolment writes it in its own
                // transaction; a resumed session had it) keeps its time.
                if (!consented_) store_.set_consent(session_id_);
                consented_ = true;
                if (protocol_.screens.instructions.empty())
                    begin_trial_or_debrief(press.t_ns);
                else
                    enter(Screen::Instructions, press.t_ns);
            } else if (press.key == Key::Decline) {
                // Nothing of a person who declined is kept, only the count (as online);
                // a resumed session they had consented to or answered in is aborted.
                if (!store_.forget_declined_session(session_id_))
                    store_.set_status(session_id_, "aborted", true);
                result_ = RunResult::Declined;
                finished_ = true;
            }
            break;
        case Screen::Instructions:
        case Screen::PracticeDone:
        case Screen::Break:
            if (press.key == Key::Enter) begin_trial_or_debrief(press.t_ns);
            break;
        case Screen::Debrief:
            if (press.key == Key::Enter) {
                screen_ = Screen::Done;
                changed();
                finished_ = true;
            }
            break;
        case Screen::Trial: {
            if (adjust_) {
                const int64_t t = press.t_ns;
                if (press.key == Key::Right || press.key == Key::Up)
                    adjust_->step(true, press.shift, t);
                else if (press.key == Key::Left || press.key == Key::Down)
                    adjust_->step(false, press.shift, t);
                else if (press.key == Key::Enter)
                    adjust_->confirm(t);
                if (adjust_->confirmed()) finish_trial();
                break;
            }
            if (!input_) break;  // before onset: nothing to answer
            const int64_t t = press.t_ns;
            switch (press.key) {
                case Key::Digit:
                    input_->key(RatingKey::Digit, press.digit, t);
                    break;
                case Key::Left:
                    input_->key(RatingKey::Left, 0, t);
                    break;
                case Key::Right:
                    input_->key(RatingKey::Right, 0, t);
                    break;
                case Key::Up:
                    input_->key(RatingKey::Up, 0, t);
                    break;
                case Key::Down:
                    input_->key(RatingKey::Down, 0, t);
                    break;
                case Key::Enter:
                    input_->key(RatingKey::Enter, 0, t);
                    break;
                default:
                    break;
            }
            if (input_->confirmed()) finish_trial();
            break;
        }
        case Screen::Blank:
        case Screen::Done:
            break;
    }
}

void SessionFlow::click_point(int question, int value, int64_t t_ns) {
    if (finished_ || paused_ || !input_ || !presented_ns_ || t_ns < *presented_ns_)
        return;
    input_->click(question, value, t_ns);
}

void SessionFlow::click_next(int64_t t_ns) {
    if (finished_ || paused_ || !input_ || !presented_ns_ || t_ns < *presented_ns_)
        return;
    input_->click_next(t_ns);
    if (input_->confirmed()) finish_trial();
}

void SessionFlow::click_choice(int alternative, int64_t t_ns) {
    if (finished_ || paused_ || !input_ || !input_->is_choice() || !presented_ns_ ||
        t_ns < *presented_ns_)
        return;
    input_->click(0, alternative, t_ns);
    input_->click_next(t_ns);
    if (input_->confirmed()) finish_trial();
}

void SessionFlow::wheel(double notches, int64_t t_ns) {
    if (finished_ || paused_ || !adjust_ || !presented_ns_ || t_ns < *presented_ns_)
        return;
    adjust_->wheel(notches, t_ns);
}

void SessionFlow::drag(double dx_px, double width_px, int64_t t_ns) {
    if (finished_ || paused_ || !adjust_ || !presented_ns_ || t_ns < *presented_ns_)
        return;
    adjust_->drag(dx_px, width_px, t_ns);
}

void SessionFlow::window_closed() {
    if (finished_) return;
    if (screen_ == Screen::Debrief || screen_ == Screen::Done) {  // already completed
        finished_ = true;
        return;
    }
    quit_saving();
}

void SessionFlow::quit_saving() {
    store_.set_status(session_id_, "paused", false);
    result_ = RunResult::SavedAndQuit;
    finished_ = true;
}

void SessionFlow::finish_trial() {
    TrialRow& t = trials_[current_];
    const Block* b = protocol_.find_block(t.block);
    TrialOutcome outcome;
    if (t.task->screen() == TrialScreen::adjust) {
        outcome = adjust_->outcome(b->question_id);
    } else {
        std::vector<std::string> ids;
        if (t.task->screen() == TrialScreen::scales)
            for (const Question& q : questions()) ids.push_back(q.id);
        else
            ids.push_back(b->question_id);
        outcome.onset_ns = *trial_onset_ns_;
        outcome.confirm_ns = input_->confirm_ns();
        outcome.responses = input_->responses(ids);
    }
    outcome.onset_ns = *trial_onset_ns_;
    if (t.task->screen() == TrialScreen::staircase) {
        const int choice = outcome.responses.front().rating;
        outcome.intensity = staircase_delta()->intensity;
        outcome.finishes_staircase = staircase_block(*b).answer(
            t.staircase, choice == t.expected,
            outcome.intensity != delta_->intensity ? outcome.intensity : std::nullopt);
        t.choice = choice;
        t.intensity = outcome.intensity;
    }
    if (refresh_hz_)
        outcome.dropped_frames = dropped_frames(trial_frames_ns_, *refresh_hz_);
    // Committed before the next trial; the last one completes the session in the same
    // transaction.
    try {
        store_.record_trial(session_id_, t.id, outcome);
    } catch (...) {
        // Not stored: the block's procedures are rebuilt from what the store holds.
        staircases_.blocks.erase(t.block);
        t.choice.reset();
        t.intensity.reset();
        throw;
    }
    const int64_t confirmed_ns = outcome.confirm_ns;
    const bool was_practice = t.practice;
    t.answered = true;
    if (outcome.finishes_staircase)
        for (TrialRow& other : trials_)
            if (other.block == t.block && other.staircase == t.staircase &&
                !other.answered)
                other.skipped = true;
    ++current_;
    advance_to_open_trial();
    if (current_ >= trials_.size())
        enter(Screen::Debrief, confirmed_ns);
    else if (was_practice && !trials_[current_].practice)
        enter(Screen::PracticeDone, confirmed_ns);
    else if (trials_[current_].break_before)
        enter(Screen::Break, confirmed_ns);
    else
        enter(Screen::Blank, confirmed_ns);
}

}  // namespace lucent::study

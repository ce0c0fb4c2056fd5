// The session runner. [SECTIONS] setup (store, window, session) | input (GLFW key log,
// autopilot through XTest) | screens (ImGui) | the frame loop and its state machine.
#include "session/runner.h"

#include <epoxy/gl.h>
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <deque>
#include <map>
#include <random>
#include <thread>

#include "gl/readback.h"
#include "lucent/version.h"
#include "session/autopilot.h"
#include "session/frame_timing.h"
#include "session/layout.h"
#include "session/rating_input.h"
#include "session/x_keyboard.h"
#include "store.h"
#include "trial_plan.h"
#include "ui/imgui_window.h"

namespace lucent::study {
namespace {

int64_t now_ns() {
    return std::chrono::duration_cast<std::chrono::nanoseconds>(
               std::chrono::steady_clock::now().time_since_epoch()).count();
}

// ---- [SECTION] input: every key press, timestamped when GLFW delivers it -----------
struct KeyEvent {
    int key;
    int64_t t_ns;
};
struct KeyLog {
    std::deque<KeyEvent> events;
    GLFWkeyfun chained = nullptr;  // ImGui's callback, called after logging
};
void on_key(GLFWwindow* window, int key, int scancode, int action, int mods) {
    auto* log = static_cast<KeyLog*>(glfwGetWindowUserPointer(window));
    if (action == GLFW_PRESS) log->events.push_back({key, now_ns()});
    if (log->chained) log->chained(window, key, scancode, action, mods);
}

// ---- [SECTION] screens ---------------------------------------------------------------
enum class Screen { Consent, Instructions, PracticeDone, Blank, Trial, Break, Debrief, Done };

void centred_text_window(const char* id, const std::string& text, int w, int h) {
    ImGui::SetNextWindowPos(ImVec2(w * 0.5f, h * 0.45f), ImGuiCond_Always, ImVec2(0.5f, 0.5f));
    ImGui::SetNextWindowSize(ImVec2(std::min(1100.f, w * 0.85f), 0));
    ImGui::Begin(id, nullptr, ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                                  ImGuiWindowFlags_AlwaysAutoResize | ImGuiWindowFlags_NoSavedSettings);
    ImGui::PushTextWrapPos(0.f);
    ImGui::TextUnformatted(text.c_str());
    ImGui::PopTextWrapPos();
    ImGui::Spacing();
}

}  // namespace

// ---- [SECTION] the session -----------------------------------------------------------
class Session {
public:
    Session(const RunOptions& o, StimulusRenderer& s, std::ostream& log)
        : opt_(o), p_(o.protocol), stimuli_(s), log_(log) {}
    RunResult run();

private:
    RunResult prepare_store();
    void open_window();
    void start_or_resume_session();
    void prepare_stimuli();
    void enter(Screen s);
    void begin_trial_or_next();
    void handle_key(const KeyEvent& e);
    void draw(int w, int h);
    void draw_rating_panel(const ScreenLayout& layout, int w);
    void draw_pause(int w, int h);
    void finish_trial();
    void resume();
    ScreenView view() const;
    int main_trials_done() const;

    const RunOptions& opt_;
    const Protocol& p_;
    StimulusRenderer& stimuli_;
    std::ostream& log_;

    std::optional<Store> store_;
    int64_t study_id_ = 0, participant_id_ = 0;
    int participant_number_ = 0;
    std::optional<SessionRow> resumable_;
    SessionRow session_;
    std::vector<TrialRow> trials_;
    size_t current_ = 0;  // index into trials_

    std::unique_ptr<ui::ImGuiWindow> window_;
    KeyLog keys_;
    std::optional<XKeyboard> x_keyboard_;
    std::optional<Autopilot> autopilot_;
    SessionEnvironment env_;
    int mode_refresh_hz_ = 0;
    std::vector<int64_t> calibration_swaps_;
    bool calibrated_ = false;

    Screen screen_ = Screen::Consent;
    int serial_ = 0;
    bool paused_ = false;
    RunResult result_ = RunResult::Completed;
    bool quit_ = false;
    int64_t screen_start_ns_ = 0;
    std::map<std::string, StimulusTexture> textures_;  // by stimulus id; before window_ dies
    const StimulusTexture* texture_ = nullptr;
    bool onset_pending_ = false;
    std::optional<RatingInput> input_;
    int64_t onset_ns_ = 0;
    std::vector<int64_t> stimulus_swaps_;
    bool screenshot_done_ = false;
};

RunResult Session::prepare_store() {
    store_.emplace(opt_.db_path);
    study_id_ = store_->ensure_study(p_);
    resumable_ = store_->unfinished_session(opt_.participant);
    if (opt_.resume && !resumable_) {
        log_ << "lucent run: participant '" << opt_.participant
             << "' has no unfinished session to resume in " << opt_.db_path << "\n";
        return RunResult::UsageError;
    }
    if (!opt_.resume && resumable_) {
        log_ << "lucent run: participant '" << opt_.participant
             << "' has an unfinished session in " << opt_.db_path
             << "; add --resume to continue it\n";
        return RunResult::UsageError;
    }
    if (!opt_.resume && store_->has_completed_session(opt_.participant)) {
        log_ << "lucent run: participant '" << opt_.participant
             << "' already completed this study in " << opt_.db_path << "\n";
        return RunResult::UsageError;
    }
    return RunResult::Completed;
}

void Session::open_window() {
    ui::ImGuiWindowOptions w;
    w.window.fullscreen = !opt_.windowed;
    w.window.monitor = opt_.monitor;
    w.window.width = 1280;
    w.window.height = 1024;
    w.window.vsync = true;
    w.window.title = "Lucent study: " + p_.title;
    window_ = std::make_unique<ui::ImGuiWindow>(w);
    glfwSetWindowUserPointer(window_->glfw(), &keys_);
    keys_.chained = glfwSetKeyCallback(window_->glfw(), on_key);

    GLFWmonitor* monitor = glfwGetWindowMonitor(window_->glfw());
    if (!monitor) monitor = glfwGetPrimaryMonitor();
    const GLFWvidmode* mode = monitor ? glfwGetVideoMode(monitor) : nullptr;
    mode_refresh_hz_ = mode ? mode->refreshRate : 0;
    int fw = 0, fh = 0;
    window_->framebuffer_size(fw, fh);
    const gl::GlInfo info = window_->context().info();
    env_.machine_id = machine_id();
    env_.software_version = version_string();
    env_.build_hash = build_hash();
    env_.gl_vendor = info.vendor;
    env_.gl_renderer = info.renderer;
    env_.display_mode = std::to_string(fw) + "x" + std::to_string(fh) +
                        (opt_.windowed ? " windowed" : " fullscreen") + ", video mode " +
                        (mode ? std::to_string(mode->width) + "x" + std::to_string(mode->height) +
                                    " @ " + std::to_string(mode->refreshRate) + " Hz"
                              : std::string("unknown"));
    env_.display_refresh_hz = mode_refresh_hz_ > 0 ? std::optional<double>(mode_refresh_hz_)
                                                   : std::nullopt;
    if (!opt_.autopilot.empty()) {
        autopilot_ = Autopilot::from_argument(opt_.autopilot, opt_.autopilot_speed);
        x_keyboard_.emplace(window_->glfw());
        x_keyboard_->focus_window();
    }
}

void Session::start_or_resume_session() {
    if (resumable_) {
        session_ = *resumable_;
        store_->set_status(session_.id, "running", false);
        store_->begin_segment(session_.id, env_);  // a new row: earlier machines' kept
    } else {
        participant_id_ = store_->ensure_participant(study_id_, opt_.participant, &participant_number_);
        uint64_t seed = opt_.seed ? *opt_.seed : (uint64_t(std::random_device{}()) << 32 | std::random_device{}());
        seed &= 0x7FFFFFFFFFFFFFFFull;
        session_ = store_->create_session(study_id_, participant_id_,
                                          plan_trials(p_, seed, participant_number_), seed, env_);
    }
    trials_ = store_->trials(session_.id);
    current_ = 0;
    while (current_ < trials_.size() && trials_[current_].answered) ++current_;
    log_ << "lucent run: session " << session_.uuid << " for '" << opt_.participant << "', "
         << current_ << " of " << trials_.size() << " trials already answered\n";
    if (current_ == trials_.size()) enter(Screen::Debrief);
    else if (current_ > 0 && store_->has_consent(session_.id)) begin_trial_or_next();
    else enter(p_.screens.consent.empty() ? Screen::Instructions : Screen::Consent);
}

void Session::enter(Screen s) {
    screen_ = s;
    ++serial_;
    screen_start_ns_ = now_ns();
    if (s == Screen::Trial) {
        texture_ = &textures_.at(trials_[current_].stimulus);
        onset_pending_ = true;
        input_.reset();
        stimulus_swaps_.clear();
    }
}

// Renders (or loads) every picture still to be shown before the first trial, so no
// trial waits for the renderer; a progress line shows on screen and on stderr.
void Session::prepare_stimuli() {
    std::vector<std::string> ids;
    for (size_t i = current_; i < trials_.size(); ++i)
        if (std::find(ids.begin(), ids.end(), trials_[i].stimulus) == ids.end())
            ids.push_back(trials_[i].stimulus);
    for (size_t k = 0; k < ids.size(); ++k) {
        window_->begin_frame();
        int w = 0, h = 0;
        window_->framebuffer_size(w, h);
        glViewport(0, 0, w, h);
        glClearColor(p_.background[0], p_.background[1], p_.background[2], 1.f);
        glClear(GL_COLOR_BUFFER_BIT);
        const std::string line = "Preparing pictures: " + std::to_string(k) + " of " +
                                 std::to_string(ids.size());
        centred_text_window("preparing", line, w, h);
        ImGui::End();
        window_->render_imgui();
        window_->swap();
        log_ << "\rlucent run: preparing stimuli " << k + 1 << "/" << ids.size() << std::flush;
        textures_.emplace(ids[k], stimuli_.render(*p_.find_stimulus(ids[k]), p_.stimulus_width,
                                                  p_.stimulus_height));
    }
    if (!ids.empty()) log_ << "\n";
    keys_.events.clear();  // keys pressed while preparing belong to no screen
}

// After consent/instructions/breaks: the next unanswered trial, through its break
// screen when it starts one, or the debrief when none is left.
void Session::begin_trial_or_next() {
    if (current_ >= trials_.size()) {
        store_->set_status(session_.id, "completed", true);
        enter(Screen::Debrief);
        return;
    }
    enter(Screen::Blank);
}

int Session::main_trials_done() const {
    int n = 0;
    for (size_t i = 0; i < current_ && i < trials_.size(); ++i) n += trials_[i].practice ? 0 : 1;
    return n;
}

void Session::finish_trial() {
    const TrialRow& t = trials_[current_];
    std::vector<std::string> ids;
    for (const Question& q : p_.questions) ids.push_back(q.id);
    TrialOutcome outcome;
    outcome.onset_ns = onset_ns_;
    outcome.confirm_ns = input_->confirm_ns();
    outcome.responses = input_->responses(ids);
    if (env_.measured_refresh_hz) outcome.dropped_frames = dropped_frames(stimulus_swaps_, *env_.measured_refresh_hz);
    store_->record_trial(session_.id, t.id, outcome);  // committed before the next trial
    input_.reset();
    trials_[current_].answered = true;
    const bool was_practice = t.practice;
    ++current_;
    if (current_ >= trials_.size()) {
        store_->set_status(session_.id, "completed", true);
        enter(Screen::Debrief);
    } else if (was_practice && !trials_[current_].practice) {
        enter(Screen::PracticeDone);
    } else if (trials_[current_].break_before) {
        enter(Screen::Break);
    } else {
        enter(Screen::Blank);
    }
}

// Leaves the pause screen. A trial interrupted by the pause starts again from a new
// onset with no answers, so its response times never include the pause.
void Session::resume() {
    paused_ = false;
    ++serial_;
    if (screen_ == Screen::Trial) {
        input_.reset();
        onset_pending_ = true;
        stimulus_swaps_.clear();
    }
}

void Session::handle_key(const KeyEvent& e) {
    if (e.key == GLFW_KEY_ESCAPE && screen_ != Screen::Done) {
        paused_ = true;
        ++serial_;
        return;
    }
    if (paused_) {
        if (e.key == GLFW_KEY_ENTER || e.key == GLFW_KEY_KP_ENTER || e.key == GLFW_KEY_R) resume(); else if (e.key == GLFW_KEY_Q) {
            result_ = RunResult::SavedAndQuit;
            quit_ = true;
        }
        return;
    }
    const bool is_enter = e.key == GLFW_KEY_ENTER || e.key == GLFW_KEY_KP_ENTER;
    switch (screen_) {
    case Screen::Consent:
        if (is_enter) {
            store_->set_consent(session_.id);
            if (p_.screens.instructions.empty()) begin_trial_or_next();
            else enter(Screen::Instructions);
        } else if (e.key == GLFW_KEY_N) {
            result_ = RunResult::Declined;
            quit_ = true;
        }
        break;
    case Screen::Instructions:
    case Screen::PracticeDone:
    case Screen::Break:
        if (is_enter) begin_trial_or_next();
        break;
    case Screen::Debrief:
        if (is_enter) quit_ = true;
        break;
    case Screen::Trial: {
        if (!input_ || e.t_ns < onset_ns_) break;  // keys before onset do not count
        if (e.key >= GLFW_KEY_1 && e.key <= GLFW_KEY_9) input_->key(RatingKey::Digit, e.key - GLFW_KEY_0, e.t_ns);
        else if (e.key >= GLFW_KEY_KP_1 && e.key <= GLFW_KEY_KP_9) input_->key(RatingKey::Digit, e.key - GLFW_KEY_KP_0, e.t_ns);
        else if (e.key == GLFW_KEY_LEFT) input_->key(RatingKey::Left, 0, e.t_ns);
        else if (e.key == GLFW_KEY_RIGHT) input_->key(RatingKey::Right, 0, e.t_ns);
        else if (e.key == GLFW_KEY_UP) input_->key(RatingKey::Up, 0, e.t_ns);
        else if (e.key == GLFW_KEY_DOWN) input_->key(RatingKey::Down, 0, e.t_ns);
        else if (is_enter) input_->key(RatingKey::Enter, 0, e.t_ns);
        if (input_->confirmed()) finish_trial();
        break;
    }
    case Screen::Blank:
    case Screen::Done:
        break;
    }
}

ScreenView Session::view() const {
    ScreenView v;
    v.serial = serial_;
    if (paused_) { v.kind = ScreenView::Kind::Pause; return v; }
    switch (screen_) {
    case Screen::Trial:
        v.kind = input_ ? ScreenView::Kind::Rating : ScreenView::Kind::Blank;
        v.questions = static_cast<int>(p_.questions.size());
        v.points = p_.questions.front().points();
        v.is_catch = trials_[current_].is_catch;
        v.expected = trials_[current_].expected;
        break;
    case Screen::Blank: case Screen::Done: v.kind = ScreenView::Kind::Blank; break;
    default: v.kind = ScreenView::Kind::Text; break;
    }
    return v;
}

void Session::draw_rating_panel(const ScreenLayout& layout, int w) {
    const TrialRow& t = trials_[current_];
    ImGui::SetNextWindowPos(ImVec2(float(layout.panel.x), float(layout.panel.y)));
    ImGui::SetNextWindowSize(ImVec2(float(layout.panel.width), float(layout.panel.height)));
    ImGui::Begin("rating", nullptr, ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                                        ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoBackground);
    if (t.is_catch) ImGui::TextColored(ImVec4(1, 0.85f, 0.3f, 1), "%s", t.prompt.c_str());
    else ImGui::TextUnformatted(t.practice ? "Practice" : "");
    const float button = ImGui::GetFrameHeight() * 1.4f;
    for (size_t q = 0; q < p_.questions.size(); ++q) {
        const Question& question = p_.questions[q];
        ImGui::PushID(static_cast<int>(q));
        const bool focused = input_ && input_->focus() == static_cast<int>(q);
        ImGui::SetCursorPosX(layout.panel.width * 0.5f -
                             ImGui::CalcTextSize(question.text.c_str()).x * 0.5f);
        ImGui::TextColored(focused ? ImVec4(1, 1, 1, 1) : ImVec4(0.6f, 0.6f, 0.6f, 1), "%s",
                           question.text.c_str());
        // The scale, centred: left label, points 1..n, right label.
        const ImGuiStyle& style = ImGui::GetStyle();
        const float scale_width = ImGui::CalcTextSize(question.labels.front().c_str()).x +
                                  ImGui::CalcTextSize(question.labels.back().c_str()).x +
                                  question.points() * (button + style.ItemSpacing.x) +
                                  style.ItemSpacing.x;
        ImGui::SetCursorPosX(std::max(0.f, layout.panel.width * 0.5f - scale_width * 0.5f));
        ImGui::TextDisabled("%s", question.labels.front().c_str());
        for (int v = 1; v <= question.points(); ++v) {
            ImGui::SameLine();
            const bool chosen = input_ && input_->rating(static_cast<int>(q)) == v;
            ImGui::PushStyleColor(ImGuiCol_Button, chosen ? ImVec4(0.9f, 0.6f, 0.1f, 1)
                                                          : ImVec4(0.25f, 0.25f, 0.3f, 1));
            if (ImGui::Button(std::to_string(v).c_str(), ImVec2(button, 0)) && input_)
                input_->click(static_cast<int>(q), v, now_ns());
            ImGui::PopStyleColor();
        }
        ImGui::SameLine();
        ImGui::TextDisabled("%s", question.labels.back().c_str());
        ImGui::PopID();
    }
    const bool ready = input_ && input_->all_answered();
    ImGui::SetCursorPosX(layout.panel.width * 0.5f - 60);
    if (!ready) ImGui::BeginDisabled();
    if (ImGui::Button("Next", ImVec2(120, 0)) && input_) input_->click_next(now_ns());
    if (!ready) ImGui::EndDisabled();
    ImGui::End();
    (void)w;
}

void Session::draw_pause(int w, int h) {
    centred_text_window("pause", "Paused. Your answers so far are saved.\n\n"
                                 "Enter or R: resume      Q: save and quit", w, h);
    if (ImGui::Button("Resume")) resume();
    ImGui::SameLine();
    if (ImGui::Button("Save and quit")) { result_ = RunResult::SavedAndQuit; quit_ = true; }
    ImGui::End();
}

void Session::draw(int w, int h) {
    // Progress over the rated trials, top left, on every screen of the session.
    int total = 0;
    for (const TrialRow& t : trials_) total += t.practice ? 0 : 1;
    if (screen_ != Screen::Consent && screen_ != Screen::Done) {
        ImGui::SetNextWindowPos(ImVec2(20, 12));
        ImGui::SetNextWindowSize(ImVec2(320, 0));
        ImGui::Begin("progress", nullptr, ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoSavedSettings |
                                              ImGuiWindowFlags_NoBackground | ImGuiWindowFlags_NoInputs);
        const int done = main_trials_done();
        ImGui::ProgressBar(total ? float(done) / total : 0.f, ImVec2(-1, 0),
                           (std::to_string(done) + " of " + std::to_string(total)).c_str());
        ImGui::End();
    }
    if (paused_) { draw_pause(w, h); return; }
    switch (screen_) {
    case Screen::Consent:
        centred_text_window("consent", p_.screens.consent, w, h);
        if (ImGui::Button("I agree (Enter)")) handle_key({GLFW_KEY_ENTER, now_ns()});
        ImGui::SameLine();
        if (ImGui::Button("I do not agree (N)")) handle_key({GLFW_KEY_N, now_ns()});
        ImGui::End();
        break;
    case Screen::Instructions:
    case Screen::PracticeDone:
    case Screen::Break:
    case Screen::Debrief: {
        const std::string& text = screen_ == Screen::Instructions ? p_.screens.instructions
                                  : screen_ == Screen::PracticeDone ? p_.screens.practice_done
                                  : screen_ == Screen::Break ? p_.screens.break_text
                                  : p_.screens.debrief;
        centred_text_window("text", text.empty() ? std::string("Press Enter.") : text, w, h);
        if (ImGui::Button("Continue (Enter)")) handle_key({GLFW_KEY_ENTER, now_ns()});
        ImGui::End();
        break;
    }
    case Screen::Trial: {
        const ScreenLayout layout = compute_layout(w, h, texture_->width, texture_->height,
                                                   static_cast<int>(p_.questions.size()),
                                                   static_cast<int>(ImGui::GetFrameHeightWithSpacing() * 1.25f));
        ImGui::GetBackgroundDrawList()->AddImage(
            ui::imgui_texture(texture_->texture), ImVec2(float(layout.image.x), float(layout.image.y)),
            ImVec2(float(layout.image.x + layout.image.width), float(layout.image.y + layout.image.height)));
        draw_rating_panel(layout, w);
        break;
    }
    case Screen::Blank:
    case Screen::Done:
        break;
    }
}

RunResult Session::run() {
    if (RunResult r = prepare_store(); r != RunResult::Completed) return r;
    try {
        stimuli_.check(p_);
        // What will be shown, recorded with the session; refused when it differs from
        // what this database's earlier sessions showed.
        env_.stimuli = stimuli_.provenance(p_);
        store_->check_stimulus_values(env_.stimuli);
    } catch (const StimulusError& e) {
        log_ << "lucent run: " << e.what() << "\n";
        return RunResult::UsageError;
    } catch (const StoreError& e) {
        log_ << "lucent run: " << e.what() << "\n";
        return RunResult::UsageError;
    }
    if (!std::getenv("DISPLAY") && !std::getenv("WAYLAND_DISPLAY")) {
        log_ << "lucent run: no display (DISPLAY is not set): run under 'xvfb-run -a lucent run "
                "...' or use the headless commands (lucent render, lucent export)\n";
        return RunResult::Failure;
    }
    try {
        open_window();
    } catch (const std::exception& e) {
        log_ << "lucent run: cannot open the session window: " << e.what() << "\n";
        return RunResult::Failure;
    }
    start_or_resume_session();
    try {
        prepare_stimuli();
    } catch (const std::exception& e) {
        log_ << "\nlucent run: " << e.what() << "\n";
        store_->set_status(session_.id, "paused", false);
        return RunResult::Failure;
    }
    enter(screen_);  // restart the first screen's clock after preparing

    int64_t last_swap = now_ns();
    while (!quit_) {
        window_->begin_frame();
        if (glfwWindowShouldClose(window_->glfw())) {  // closed by the window manager
            result_ = RunResult::SavedAndQuit;
            break;
        }
        const int64_t now = now_ns();
        if (autopilot_) {
            const std::vector<std::string> keys = autopilot_->due(now, view());
            // Take the focus back first: another window on the same X server may hold it.
            if (!keys.empty()) x_keyboard_->focus_window();
            for (const std::string& key : keys) x_keyboard_->tap(key);
        }
        while (!keys_.events.empty() && !quit_) {
            const KeyEvent e = keys_.events.front();
            keys_.events.pop_front();
            handle_key(e);
        }
        if (screen_ == Screen::Blank && now - screen_start_ns_ >= p_.inter_trial_ms * 1000000LL)
            enter(Screen::Trial);
        if (screen_ == Screen::Trial && input_ && input_->confirmed())
            finish_trial();  // confirmed with the mouse

        int w = 0, h = 0;
        window_->framebuffer_size(w, h);
        glViewport(0, 0, w, h);
        glClearColor(p_.background[0], p_.background[1], p_.background[2], 1.f);
        glClear(GL_COLOR_BUFFER_BIT);
        draw(w, h);
        window_->render_imgui();

        if (screen_ == Screen::Trial && onset_pending_ && !paused_) {
            // Onset: the first swap showing the stimulus, after the GPU has finished it.
            glFinish();
            if (!opt_.screenshot_path.empty() && !screenshot_done_) {
                std::vector<uint8_t> pixels = gl::read_framebuffer_rgba8(w, h);
                CpuImage shot{w, h, std::vector<uint8_t>(pixels.size())};
                const size_t row = static_cast<size_t>(w) * 4;
                for (int y = 0; y < h; ++y)  // GL rows run bottom-up; files top-down
                    std::copy_n(&pixels[(h - 1 - y) * row], row, &shot.rgba[y * row]);
                save_image_rgba8(opt_.screenshot_path, shot);
                screenshot_done_ = true;
            }
            window_->swap();
            glFinish();
            onset_ns_ = now_ns();
            onset_pending_ = false;
            input_.emplace(static_cast<int>(p_.questions.size()), p_.questions.front().points(), onset_ns_);
            ++serial_;
        } else {
            window_->swap();
        }
        const int64_t swapped = now_ns();
        if (screen_ == Screen::Trial) stimulus_swaps_.push_back(swapped);
        if (!calibrated_) {
            calibration_swaps_.push_back(swapped);
            if (calibration_swaps_.size() >= 90 || mode_refresh_hz_ <= 0) {
                const RefreshEstimate r = estimate_refresh(mode_refresh_hz_, calibration_swaps_);
                env_.measured_refresh_hz = r.measured_hz;
                env_.refresh_note = r.note;
                store_->update_environment(session_.id, env_);
                log_ << "lucent run: " << r.note << "\n";
                calibrated_ = true;
            }
        }
        // Without a paced display (Xvfb), cap the loop near 60 Hz instead of spinning.
        if (mode_refresh_hz_ <= 0) {
            const int64_t next = last_swap + 16'666'667;
            if (next > swapped) std::this_thread::sleep_for(std::chrono::nanoseconds(next - swapped));
        }
        last_swap = now_ns();
    }
    if (result_ == RunResult::SavedAndQuit) {
        store_->set_status(session_.id, "paused", false);
        log_ << "lucent run: saved after " << current_ << " of " << trials_.size()
             << " trials; continue with --resume\n";
    } else if (result_ == RunResult::Declined) {
        store_->set_status(session_.id, "aborted", true);
        log_ << "lucent run: consent declined; session closed\n";
    } else {
        log_ << "lucent run: session complete (" << trials_.size() << " trials)\n";
    }
    return result_;
}

RunResult run_session(const RunOptions& options, StimulusRenderer& stimuli, std::ostream& log) {
    Session session(options, stimuli, log);
    return session.run();
}

}  // namespace lucent::study

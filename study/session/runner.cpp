// The session runner: the window, drawing and timing around the GL-free state machine
// (session_flow.h). [SECTIONS] keys (X key thread, GLFW fallback) | setup (store,
// window, session, stimuli) | drawing (ImGui) | the frame loop.
#include "study/session/runner.h"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <imgui.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdlib>
#include <functional>
#include <map>
#include <random>
#include <thread>

#include "lucent/version.h"
#include "renderer/gl/present.h"
#include "renderer/gl/readback.h"
#include "renderer/ui/imgui_window.h"
#include "study/session/autopilot.h"
#include "study/session/frame_timing.h"
#include "study/session/layout.h"
#include "study/session/live_knob.h"
#include "study/session/live_stimuli.h"
#include "study/session/session_flow.h"
#include "study/session/x_key_events.h"
#include "study/session/x_keyboard.h"
#include "study/sqlite/sqlite_store.h"
#include "study/trial_plan.h"

namespace lucent::study {
namespace {

// ---- [SECTION] keys -------------------------------------------------------------------
// Keys come from XKeyEvents (stamped by its thread when the X server sends them). Only
// without X11 (GLFW on Wayland) do they come from GLFW's callback, stamped when
// glfwPollEvents delivers them, up to a frame late; the runner says so in the log.
struct GlfwKeyLog {
    std::vector<TimedKey> presses;
    GLFWkeyfun chained = nullptr;  // ImGui's callback, called after logging
};

std::optional<Key> key_for_glfw(int key, int* digit) {
    if (key >= GLFW_KEY_1 && key <= GLFW_KEY_9)
        return *digit = key - GLFW_KEY_0, Key::Digit;
    if (key >= GLFW_KEY_KP_1 && key <= GLFW_KEY_KP_9)
        return *digit = key - GLFW_KEY_KP_0, Key::Digit;
    switch (key) {
        case GLFW_KEY_ENTER:
        case GLFW_KEY_KP_ENTER:
            return Key::Enter;
        case GLFW_KEY_ESCAPE:
            return Key::Escape;
        case GLFW_KEY_LEFT:
            return Key::Left;
        case GLFW_KEY_RIGHT:
            return Key::Right;
        case GLFW_KEY_UP:
            return Key::Up;
        case GLFW_KEY_DOWN:
            return Key::Down;
        case GLFW_KEY_Q:
            return Key::Quit;
        case GLFW_KEY_R:
            return Key::Resume;
        case GLFW_KEY_N:
            return Key::Decline;
        default:
            return std::nullopt;
    }
}

void on_glfw_key(GLFWwindow* window, int key, int scancode, int action, int mods) {
    auto* log = static_cast<GlfwKeyLog*>(glfwGetWindowUserPointer(window));
    int digit = 0;
    if (action == GLFW_PRESS)
        if (const auto k = key_for_glfw(key, &digit))
            log->presses.push_back(
                {*k, digit, steady_now_ns(), (mods & GLFW_MOD_SHIFT) != 0});
    if (log->chained) log->chained(window, key, scancode, action, mods);
}

void centred_text_window(const char* id, const std::string& text, int w, int h) {
    ImGui::SetNextWindowPos(ImVec2(w * 0.5f, h * 0.45f), ImGuiCond_Always,
                            ImVec2(0.5f, 0.5f));
    ImGui::SetNextWindowSize(ImVec2(std::min(1100.f, w * 0.85f), 0));
    ImGui::Begin(id, nullptr,
                 ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                     ImGuiWindowFlags_AlwaysAutoResize |
                     ImGuiWindowFlags_NoSavedSettings);
    ImGui::PushTextWrapPos(0.f);
    ImGui::TextUnformatted(text.c_str());
    ImGui::PopTextWrapPos();
    ImGui::Spacing();
}

}  // namespace

// ---- [SECTION] the session ------------------------------------------------------------
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
    void feed_keys();
    void draw(int w, int h);
    void draw_rating_panel(const ScreenLayout& layout);
    void draw_choice(int w, int h);
    // ---- adjust and staircase trials (issue 31)
    std::string check_live_blocks() const;
    LiveKnobRenderer& knob_renderer(const std::string& stimulus, const std::string& knob);
    void prepare_live();  // the match (or the comparison) for what is on screen next
    const StimulusTexture& shown_texture(size_t place) const;
    std::optional<AdjustLayout> adjust_layout(int w, int h) const;
    void draw_adjust(int w, int h);
    std::optional<ChoiceLayout> choice_layout(ChoiceShow show, int w, int h) const;
    bool waits_for_a_larger_window(int w, int h);
    void present(int w, int h);
    void calibrate(int64_t swapped);

    const RunOptions& opt_;
    const Protocol& p_;
    StimulusRenderer& stimuli_;
    std::ostream& log_;

    std::unique_ptr<StudyStore> store_;
    int64_t study_id_ = 0;
    std::optional<SessionRow> resumable_;
    SessionRow session_;
    std::optional<SessionFlow> flow_;

    std::unique_ptr<ui::ImGuiWindow> window_;
    std::optional<XKeyEvents> x_keys_;
    GlfwKeyLog glfw_keys_;
    std::optional<XKeyboard> x_keyboard_;
    std::optional<Autopilot> autopilot_;
    bool script_sent_ = false;
    SessionEnvironment env_;
    int mode_refresh_hz_ = 0;
    std::vector<int64_t> calibration_swaps_;
    bool calibrated_ = false;

    std::map<std::string, StimulusTexture>
        textures_;  // by stimulus id; before window_ dies
    // Clicks and buttons seen while drawing, applied once the frame is drawn, so the
    // screen never changes half way through drawing it.
    std::vector<std::function<void()>> ui_actions_;
    // Live renderers of a stimulus with one knob turned (an adjust trial's match, a
    // staircase's comparison), by "stimulus/knob"; before window_ dies.
    std::map<std::string, std::unique_ptr<LiveKnobRenderer>> knob_renderers_;
    // What the match's (the comparison's) texture shows now: the trial and the value.
    std::optional<std::pair<int64_t, double>> live_shown_;
    const StimulusTexture* live_texture_ = nullptr;
    bool dragging_ = false;  // a drag that started on the match
    int64_t frame_ns_ = 0;   // when this frame's events were polled
    bool screenshot_done_ = false;
    bool too_small_logged_ = false;
};

RunResult Session::prepare_store() {
    store_ = open_study_store(opt_.db_path);
    study_id_ = store_->ensure_study(p_);
    // Before anything of the participant is read: a second station running this code
    // now is refused here, with one line.
    store_->claim_participant(opt_.participant);
    resumable_ = store_->unfinished_session(opt_.participant);
    // Every trial answered but still open: left so by a build where completion was not
    // atomic. It is complete; mark it so instead of reopening it.
    const bool repaired =
        resumable_ && store_->complete_session_if_answered(resumable_->id);
    if (repaired) resumable_.reset();
    if (!resumable_ && store_->has_completed_session(opt_.participant)) {
        log_ << "lucent run: participant '" << opt_.participant
             << "' already completed this study in " << opt_.db_path
             << (repaired ? " (every trial answered; session now marked completed)" : "")
             << "; nothing to " << (opt_.resume ? "resume" : "run")
             << " (a new participant code starts a new session)\n";
        return RunResult::UsageError;
    }
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
    try {
        x_keys_.emplace(window_->glfw(), opt_.key_trace_path);
    } catch (const std::exception& e) {
        log_ << "lucent run: " << e.what()
             << "; key times are taken per frame (up to one frame late)\n";
        glfwSetWindowUserPointer(window_->glfw(), &glfw_keys_);
        glfw_keys_.chained = glfwSetKeyCallback(window_->glfw(), on_glfw_key);
    }

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
    env_.display_mode =
        std::to_string(fw) + "x" + std::to_string(fh) +
        (opt_.windowed ? " windowed" : " fullscreen") + ", video mode " +
        (mode ? std::to_string(mode->width) + "x" + std::to_string(mode->height) + " @ " +
                    std::to_string(mode->refreshRate) + " Hz"
              : std::string("unknown"));
    env_.display_refresh_hz =
        mode_refresh_hz_ > 0 ? std::optional<double>(mode_refresh_hz_) : std::nullopt;
    if (!opt_.autopilot.empty()) {
        autopilot_ = Autopilot::from_argument(opt_.autopilot, opt_.autopilot_speed,
                                              opt_.autopilot_observer);
        autopilot_->set_threshold_observers(opt_.autopilot_detection,
                                            opt_.autopilot_match);
        autopilot_->set_adjust_by(opt_.autopilot_adjust);
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
        int number = 0;
        const int64_t participant_id =
            store_->ensure_participant(study_id_, opt_.participant, &number);
        uint64_t seed =
            opt_.seed ? *opt_.seed
                      : (uint64_t(std::random_device{}()) << 32 | std::random_device{}());
        seed &= 0x7FFFFFFFFFFFFFFFull;
        session_ = store_->create_session(study_id_, participant_id,
                                          plan_trials(p_, seed, number), seed, env_);
    }
    const std::vector<TrialRow> trials = store_->trials(session_.id);
    log_ << "lucent run: session " << session_.uuid << " for '" << opt_.participant
         << "', "
         << std::count_if(trials.begin(), trials.end(),
                          [](const TrialRow& t) { return t.answered; })
         << " of " << trials.size() << " trials already answered\n";
}

// Renders (or loads) every picture still to be shown before the first trial, so no
// trial waits for the renderer; a progress line shows on screen and on stderr.
void Session::prepare_stimuli() {
    const std::vector<TrialRow> trials = store_->trials(session_.id);
    std::vector<std::string> ids;
    // A choice trial's every picture (`shown`), so a pair or a triad is on screen
    // complete from its onset.
    auto add = [&ids](const std::string& id) {
        if (std::find(ids.begin(), ids.end(), id) == ids.end()) ids.push_back(id);
    };
    for (const TrialRow& t : trials) {
        if (t.answered) continue;
        add(t.stimulus);
        for (const std::string& id : t.shown) add(id);
    }
    for (size_t k = 0; k < ids.size(); ++k) {
        window_->begin_frame();
        int w = 0, h = 0;
        window_->framebuffer_size(w, h);
        gl::clear_frame(w, h, p_.background);
        const std::string line = "Preparing pictures: " + std::to_string(k) + " of " +
                                 std::to_string(ids.size());
        centred_text_window("preparing", line, w, h);
        ImGui::End();
        window_->render_imgui();
        window_->swap();
        log_ << "\rlucent run: preparing stimuli " << k + 1 << "/" << ids.size()
             << std::flush;
        textures_.emplace(ids[k], stimuli_.render(*p_.find_stimulus(ids[k]),
                                                  p_.stimulus_width, p_.stimulus_height));
    }
    if (!ids.empty()) log_ << "\n";
}

void Session::feed_keys() {
    std::vector<TimedKey> presses;
    if (x_keys_)
        presses = x_keys_->take();
    else
        presses.swap(glfw_keys_.presses);
    for (const TimedKey& k : presses) {
        if (flow_->finished()) break;
        flow_->key(k);
    }
}

// ---- [SECTION] drawing ----------------------------------------------------------------
void Session::draw_rating_panel(const ScreenLayout& layout) {
    const TrialRow& t = *flow_->trial();
    const RatingInput* input = flow_->rating();
    ImGui::SetNextWindowPos(ImVec2(float(layout.panel.x), float(layout.panel.y)));
    ImGui::SetNextWindowSize(
        ImVec2(float(layout.panel.width), float(layout.panel.height)));
    ImGui::Begin("rating", nullptr,
                 ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoMove |
                     ImGuiWindowFlags_NoSavedSettings | ImGuiWindowFlags_NoBackground);
    if (t.is_catch)
        ImGui::TextColored(ImVec4(1, 0.85f, 0.3f, 1), "%s", t.prompt.c_str());
    else
        ImGui::TextUnformatted(t.practice ? "Practice" : "");
    const float button = ImGui::GetFrameHeight() * 1.4f;
    const std::vector<Question>& questions = flow_->questions();
    for (size_t q = 0; q < questions.size(); ++q) {
        const Question& question = questions[q];
        ImGui::PushID(static_cast<int>(q));
        const bool focused = input && input->focus() == static_cast<int>(q);
        ImGui::SetCursorPosX(layout.panel.width * 0.5f -
                             ImGui::CalcTextSize(question.text.c_str()).x * 0.5f);
        ImGui::TextColored(focused ? ImVec4(1, 1, 1, 1) : ImVec4(0.6f, 0.6f, 0.6f, 1),
                           "%s", question.text.c_str());
        // The question's own scale, centred: left label, points 1..n, right label.
        const ImGuiStyle& style = ImGui::GetStyle();
        const float scale_width = ImGui::CalcTextSize(question.labels.front().c_str()).x +
                                  ImGui::CalcTextSize(question.labels.back().c_str()).x +
                                  question.points() * (button + style.ItemSpacing.x) +
                                  style.ItemSpacing.x;
        ImGui::SetCursorPosX(
            std::max(0.f, layout.panel.width * 0.5f - scale_width * 0.5f));
        ImGui::TextDisabled("%s", question.labels.front().c_str());
        for (int v = 1; v <= question.points(); ++v) {
            ImGui::SameLine();
            const bool chosen = input && input->rating(static_cast<int>(q)) == v;
            ImGui::PushStyleColor(ImGuiCol_Button, chosen
                                                       ? ImVec4(0.9f, 0.6f, 0.1f, 1)
                                                       : ImVec4(0.25f, 0.25f, 0.3f, 1));
            if (ImGui::Button(std::to_string(v).c_str(), ImVec2(button, 0))) {
                const int64_t t_ns = steady_now_ns();
                ui_actions_.push_back(
                    [this, q, v, t_ns] { flow_->click_point(int(q), v, t_ns); });
            }
            ImGui::PopStyleColor();
        }
        ImGui::SameLine();
        ImGui::TextDisabled("%s", question.labels.back().c_str());
        ImGui::PopID();
    }
    const bool ready = input && input->all_answered();
    ImGui::SetCursorPosX(layout.panel.width * 0.5f - 60);
    if (!ready) ImGui::BeginDisabled();
    if (ImGui::Button("Next", ImVec2(120, 0))) {
        const int64_t t_ns = steady_now_ns();
        ui_actions_.push_back([this, t_ns] { flow_->click_next(t_ns); });
    }
    if (!ready) ImGui::EndDisabled();
    ImGui::End();
}

// ---- forced choices (issue 30)
// ---------------------------------------------------------
namespace {

ChoiceShow choice_show(const Block& block, std::optional<ChoicePhase> phase) {
    if (block.presentation == Presentation::side_by_side) return ChoiceShow::all;
    switch (phase.value_or(ChoicePhase::First)) {
        case ChoicePhase::First:
            return ChoiceShow::first_part;
        case ChoicePhase::Gap:
            return ChoiceShow::nothing;
        case ChoicePhase::Second:
            return ChoiceShow::second_part;
        case ChoicePhase::Answer:
            break;
    }
    return ChoiceShow::answers;
}

ImU32 colour(float r, float g, float b) {
    return ImGui::ColorConvertFloat4ToU32(ImVec4(r, g, b, 1));
}

void centred_text(ImDrawList* list, const Rect& r, ImU32 col, const std::string& text) {
    const ImVec2 size = ImGui::CalcTextSize(text.c_str());
    list->AddText(
        ImVec2(r.x + (r.width - size.x) * 0.5f, r.y + (r.height - size.y) * 0.5f), col,
        text.c_str());
}

}  // namespace

// The layout of the current (or, on the blank before it, the next) choice trial.
std::optional<ChoiceLayout> Session::choice_layout(ChoiceShow show, int w, int h) const {
    const TrialRow* t = flow_->trial();
    const Block* b = flow_->block();
    if (!t || !b || !b->is_choice() || t->shown.empty()) return std::nullopt;
    ChoiceLayoutInput in;
    in.screen_width = w;
    in.screen_height = h;
    in.groups = b->task->answer_groups(*b);
    in.show = show;
    for (const std::string& id : t->shown) {
        const StimulusTexture& texture = textures_.at(id);
        in.pictures.push_back({texture.width, texture.height});
    }
    in.row_height = static_cast<int>(ImGui::GetFrameHeightWithSpacing() * 1.25f);
    return compute_choice_layout(in);
}

// Before a choice trial starts (on the blank before it): a window too small for its
// pictures at their true size keeps it from starting, with a message, until it grows.
bool Session::waits_for_a_larger_window(int w, int h) {
    if (flow_->screen() != Screen::Blank || flow_->paused()) return false;
    const Block* b = flow_->block();
    if (!b || b->task->screen() == TrialScreen::scales) return false;
    const bool fits = b->task->screen() == TrialScreen::adjust
                          ? adjust_layout(w, h).value_or(AdjustLayout{}).fits
                          : choice_layout(choice_show(*b, std::nullopt), w, h)
                                .value_or(ChoiceLayout{})
                                .fits;
    if (fits) {
        too_small_logged_ = false;
        return false;
    }
    if (!too_small_logged_) {
        const StimulusTexture& t = textures_.at(flow_->trial()->stimulus);
        log_ << "lucent run: the window (" << w << " x " << h
             << ") is too small to show a " << task_name(b->task) << " of " << t.width
             << " x " << t.height
             << " pictures at their true size; the trial waits for a larger window\n";
        too_small_logged_ = true;
    }
    return true;
}

void Session::draw_choice(int w, int h) {
    const TrialRow& t = *flow_->trial();
    const Block& b = *flow_->block();
    const std::optional<ChoiceLayout> l =
        choice_layout(choice_show(b, flow_->choice_phase()), w, h);
    if (!l || !l->fits) return;  // a window made smaller mid-trial: nothing half-drawn
    ImDrawList* list = ImGui::GetBackgroundDrawList();
    for (size_t k = 0; k < l->picture.size(); ++k) {
        const Rect& r = l->picture[k];
        list->AddImage(ui::imgui_texture(shown_texture(l->index[k]).texture),
                       ImVec2(float(r.x), float(r.y)),
                       ImVec2(float(r.x + r.width), float(r.y + r.height)));
    }
    // The question (no catch prompt: a choice block's catch trials are hidden checks).
    const ImU32 text = colour(1, 1, 1), dim = colour(0.75f, 0.75f, 0.75f),
                chosen_colour = colour(0.9f, 0.6f, 0.1f);
    centred_text(list, l->question, text, b.question);
    if (t.practice) {
        Rect above = l->question;
        above.y -= above.height;
        centred_text(list, above, dim, "Practice");
    }
    // The answers: from the first frame of the Answer phase (the flow's input follows
    // that frame), none in a sequence's parts and its blank.
    if (l->alternative.empty()) return;
    const RatingInput* input = flow_->rating();
    const std::optional<int> chosen = input ? input->rating(0) : std::nullopt;
    const int answers = static_cast<int>(std::min(l->label.size(), b.labels.size()));
    for (int k = 0; k < answers; ++k) {
        const bool on = chosen == k + 1;
        const ImU32 col = on ? chosen_colour : dim;
        if (k < static_cast<int>(l->box.size())) {  // in sequence, the Answer phase
            const Rect& box = l->box[k];
            list->AddRectFilled(
                ImVec2(float(box.x), float(box.y)),
                ImVec2(float(box.x + box.width), float(box.y + box.height)),
                on ? chosen_colour : colour(0.25f, 0.25f, 0.3f), 6.f);
            centred_text(list, box, on ? colour(0, 0, 0) : text, b.labels[k]);
            continue;
        }
        if (k < static_cast<int>(l->bracket.size()) && l->bracket[k].width > 0) {
            const Rect& br = l->bracket[k];
            const float x0 = br.x + 0.5f, x1 = br.x + br.width - 0.5f, y0 = float(br.y),
                        y1 = br.y + br.height - 0.5f;
            const ImVec2 points[4] = {{x0, y0}, {x0, y1}, {x1, y1}, {x1, y0}};
            list->AddPolyline(points, 4, col, ImDrawFlags_None, on ? 3.f : 1.5f);
        }
        centred_text(list, l->label[k], on ? chosen_colour : text, b.labels[k]);
    }
    // A click on an alternative picks it and confirms it (the flow's click_choice).
    if (input && ImGui::IsMouseClicked(ImGuiMouseButton_Left) &&
        !ImGui::GetIO().WantCaptureMouse) {
        const ImVec2 m = ImGui::GetIO().MousePos;
        for (int k = 0; k < answers; ++k)
            if (l->alternative[k].contains(int(m.x), int(m.y))) {
                const int64_t t_ns = steady_now_ns();
                ui_actions_.push_back(
                    [this, k, t_ns] { flow_->click_choice(k + 1, t_ns); });
            }
    }
}

// ---- adjust and staircase trials (issue 31) -------------------------------------------
// Why the protocol's adjust and staircase blocks cannot be presented live ("" when they
// can): their match and standards must be rendered here, not loaded from files.
std::string Session::check_live_blocks() const {
    const auto* live = dynamic_cast<const LiveOrPrerenderedStimuli*>(&stimuli_);
    auto not_live = [&](const Block& b, const std::string& id) -> std::string {
        const Stimulus* spec = p_.find_stimulus(id);
        if (live && spec && live->live_scene(*spec)) return "";
        return "block '" + b.id + "': stimulus '" + id +
               "' must be rendered live (its knob '" + b.knob +
               "' is turned during the session), not taken from a picture file";
    };
    for (const Block& b : p_.blocks) {
        if (b.task->screen() == TrialScreen::adjust) {
            if (std::string why = not_live(b, b.match); !why.empty()) return why;
        } else if (b.task->screen() == TrialScreen::staircase) {
            if (b.pictures() == 3 && b.presentation == Presentation::sequential)
                return "block '" + b.id +
                       "': an odd-one-out staircase in sequence is not presented by "
                       "this build (use presentation = \"side_by_side\")";
            for (const std::string& id : b.stimuli)
                if (std::string why = not_live(b, id); !why.empty()) return why;
        }
    }
    return "";
}

LiveKnobRenderer& Session::knob_renderer(const std::string& stimulus,
                                         const std::string& knob) {
    std::unique_ptr<LiveKnobRenderer>& slot = knob_renderers_[stimulus + "/" + knob];
    if (!slot) {
        const auto& live = dynamic_cast<const LiveOrPrerenderedStimuli&>(stimuli_);
        slot = std::make_unique<LiveKnobRenderer>(
            "stimulus '" + stimulus + "'", *live.live_scene(*p_.find_stimulus(stimulus)),
            knob, p_.stimulus_width, p_.stimulus_height);
    }
    return *slot;
}

// On the blank before an adjust trial and while it runs: the match at the participant's
// value (the planned start until the input exists), re-rendered only when the value
// moved. On the blank before a staircase slot: the comparison, once.
void Session::prepare_live() {
    const TrialRow* t = flow_->trial();
    const Block* b = flow_->block();
    const TrialScreen screen = b ? b->task->screen() : TrialScreen::scales;
    if (!t || (screen != TrialScreen::adjust && screen != TrialScreen::staircase)) {
        live_shown_.reset();
        live_texture_ = nullptr;
        return;
    }
    double value = 0;
    std::string stimulus;
    if (screen == TrialScreen::adjust) {
        const AdjustInput* input = flow_->adjustment();
        value = input ? input->value()
                      : std::clamp(t->start_value.value_or(b->range_min), b->range_min,
                                   b->range_max);
        stimulus = b->match;
    } else {
        const std::optional<double> v = flow_->comparison_value();
        if (!v) return;
        value = *v;
        stimulus = t->stimulus;
    }
    if (live_shown_ && live_shown_->first == t->id && live_shown_->second == value)
        return;
    if (!live_shown_ || live_shown_->first != t->id) dragging_ = false;  // a new trial
    live_texture_ = &knob_renderer(stimulus, b->knob).render(value);
    live_shown_ = std::make_pair(t->id, value);
}

// The picture at `place` (0-based) of a choice trial: a staircase's comparison at its
// place, else the stimulus shown there.
const StimulusTexture& Session::shown_texture(size_t place) const {
    const TrialRow& t = *flow_->trial();
    if (t.task->screen() == TrialScreen::staircase &&
        static_cast<int>(place) + 1 == t.expected && live_texture_)
        return *live_texture_;
    return textures_.at(t.shown[place]);
}

std::optional<AdjustLayout> Session::adjust_layout(int w, int h) const {
    const TrialRow* t = flow_->trial();
    if (!t) return std::nullopt;
    const StimulusTexture& target = textures_.at(t->stimulus);
    return compute_adjust_layout(
        w, h, {target.width, target.height}, {p_.stimulus_width, p_.stimulus_height},
        static_cast<int>(ImGui::GetFrameHeightWithSpacing() * 1.25f));
}

void Session::draw_adjust(int w, int h) {
    const TrialRow& t = *flow_->trial();
    const Block& b = *flow_->block();
    const std::optional<AdjustLayout> l = adjust_layout(w, h);
    if (!l || !l->fits || !live_texture_) return;
    ImDrawList* list = ImGui::GetBackgroundDrawList();
    auto image = [list](const StimulusTexture& texture, const Rect& r) {
        list->AddImage(ui::imgui_texture(texture.texture), ImVec2(float(r.x), float(r.y)),
                       ImVec2(float(r.x + r.width), float(r.y + r.height)));
    };
    image(textures_.at(t.stimulus), l->target);
    image(*live_texture_, l->match);
    // The question and the keys; never the knob's value (the match is made by eye).
    centred_text(list, l->question, colour(1, 1, 1), b.question);
    if (t.practice) {
        Rect above = l->question;
        above.y -= above.height;
        centred_text(list, above, colour(0.75f, 0.75f, 0.75f), "Practice");
    }
    centred_text(list, l->hint, colour(0.75f, 0.75f, 0.75f),
                 "Left/Right: adjust (Shift: fine), wheel or drag, Enter: confirm");
    if (!flow_->adjustment()) return;
    // The wheel anywhere, a horizontal drag that starts on the match.
    const ImGuiIO& io = ImGui::GetIO();
    if (io.WantCaptureMouse) return;
    // The wheel and the drag happened before this frame's poll (AdjustInput keeps the
    // changes in time order against keys stamped with their own X event times).
    const int64_t t_ns = frame_ns_;
    if (io.MouseWheel != 0.f) {
        const double notches = io.MouseWheel;
        ui_actions_.push_back([this, notches, t_ns] { flow_->wheel(notches, t_ns); });
    }
    if (ImGui::IsMouseClicked(ImGuiMouseButton_Left))
        dragging_ = l->match.contains(int(io.MousePos.x), int(io.MousePos.y));
    if (!ImGui::IsMouseDown(ImGuiMouseButton_Left)) dragging_ = false;
    // The press frame's motion came before the button went down: not part of the drag.
    if (dragging_ && !ImGui::IsMouseClicked(ImGuiMouseButton_Left) &&
        io.MouseDelta.x != 0.f) {
        const double dx = io.MouseDelta.x, width = l->match.width;
        ui_actions_.push_back([this, dx, width, t_ns] { flow_->drag(dx, width, t_ns); });
    }
}

// An odd one out side by side: three pictures, the comparison at its place, each
// picture's name under it; 1..3 (or the arrows) and Enter, or a click, answer.
void Session::draw(int w, int h) {
    auto button_key = [this](const char* label, Key key) {
        if (ImGui::Button(label)) {
            const int64_t t_ns = steady_now_ns();
            ui_actions_.push_back([this, key, t_ns] { flow_->key({key, 0, t_ns}); });
        }
    };
    const Screen screen = flow_->screen();
    // Progress over the rated trials, top left, on every screen of the session.
    if (screen != Screen::Consent && screen != Screen::Done) {
        ImGui::SetNextWindowPos(ImVec2(20, 12));
        ImGui::SetNextWindowSize(ImVec2(320, 0));
        ImGui::Begin("progress", nullptr,
                     ImGuiWindowFlags_NoDecoration | ImGuiWindowFlags_NoSavedSettings |
                         ImGuiWindowFlags_NoBackground | ImGuiWindowFlags_NoInputs);
        const int done = flow_->main_trials_done(), total = flow_->main_trials_total();
        ImGui::ProgressBar(
            total ? float(done) / total : 0.f, ImVec2(-1, 0),
            (std::to_string(done) + " of " + std::to_string(total)).c_str());
        ImGui::End();
    }
    if (flow_->paused()) {
        centred_text_window("pause",
                            "Paused. Your answers so far are saved.\n\n"
                            "Enter or R: resume      Q: save and quit",
                            w, h);
        button_key("Resume", Key::Resume);
        ImGui::SameLine();
        button_key("Save and quit", Key::Quit);
        ImGui::End();
        return;
    }
    switch (screen) {
        case Screen::Consent:
            centred_text_window("consent", flow_->text(), w, h);
            button_key("I agree (Enter)", Key::Enter);
            ImGui::SameLine();
            button_key("I do not agree (N)", Key::Decline);
            ImGui::End();
            break;
        case Screen::Instructions:
        case Screen::PracticeDone:
        case Screen::Break:
        case Screen::Debrief:
            centred_text_window(
                "text",
                flow_->text().empty() ? std::string("Press Enter.") : flow_->text(), w,
                h);
            button_key("Continue (Enter)", Key::Enter);
            ImGui::End();
            break;
        case Screen::Trial: {
            const TrialScreen screen = flow_->trial()->task->screen();
            if (screen == TrialScreen::adjust) {
                draw_adjust(w, h);
                break;
            }
            if (screen == TrialScreen::choice || screen == TrialScreen::staircase) {
                draw_choice(w, h);
                break;
            }
            const StimulusTexture& texture = textures_.at(flow_->trial()->stimulus);
            const ScreenLayout layout = compute_layout(
                w, h, texture.width, texture.height,
                static_cast<int>(flow_->questions().size()),
                static_cast<int>(ImGui::GetFrameHeightWithSpacing() * 1.25f));
            ImGui::GetBackgroundDrawList()->AddImage(
                ui::imgui_texture(texture.texture),
                ImVec2(float(layout.image.x), float(layout.image.y)),
                ImVec2(float(layout.image.x + layout.image.width),
                       float(layout.image.y + layout.image.height)));
            draw_rating_panel(layout);
            break;
        }
        case Screen::Blank:
            if (waits_for_a_larger_window(w, h)) {
                centred_text_window(
                    "too small",
                    "This window is too small to show the pictures at their true size "
                    "(" +
                        std::to_string(w) + " x " + std::to_string(h) +
                        " pixels now). Please make it larger (or full screen) to go on.",
                    w, h);
                ImGui::End();
            }
            break;
        case Screen::Done:
            break;
    }
}

// ---- [SECTION] the frame loop ---------------------------------------------------------
// Draws and presents one frame, and tells the flow when it reached the display. A
// screen's first frame is finished on the GPU before and after the swap, so its time is
// when it appeared (on a trial: the stimulus onset).
void Session::present(int w, int h) {
    const int serial = flow_->serial();
    const bool first = flow_->awaiting_presentation();
    gl::clear_frame(w, h, p_.background);
    draw(w, h);
    window_->render_imgui();
    if (first) {
        gl::wait_for_gpu();
        if (flow_->screen() == Screen::Trial && !flow_->paused() &&
            !opt_.screenshot_path.empty() && !screenshot_done_) {
            std::vector<uint8_t> pixels = gl::read_framebuffer_rgba8(w, h);
            CpuImage shot{w, h, std::vector<uint8_t>(pixels.size())};
            const size_t row = static_cast<size_t>(w) * 4;
            for (int y = 0; y < h; ++y)  // GL rows run bottom-up; files top-down
                std::copy_n(&pixels[(h - 1 - y) * row], row, &shot.rgba[y * row]);
            save_image_rgba8(opt_.screenshot_path, shot);
            screenshot_done_ = true;
        }
    }
    window_->swap();
    if (first) gl::wait_for_gpu();
    const int64_t swapped = steady_now_ns();
    for (const auto& action : ui_actions_) action();
    ui_actions_.clear();
    flow_->presented(serial, swapped);
    calibrate(swapped);
}

void Session::calibrate(int64_t swapped) {
    if (calibrated_) return;
    calibration_swaps_.push_back(swapped);
    if (calibration_swaps_.size() >= 90 || mode_refresh_hz_ <= 0) {
        const RefreshEstimate r = estimate_refresh(mode_refresh_hz_, calibration_swaps_);
        env_.measured_refresh_hz = r.measured_hz;
        env_.refresh_note = r.note;
        flow_->set_refresh_hz(r.measured_hz);
        store_->update_environment(session_.id, env_);
        log_ << "lucent run: " << r.note << "\n";
        calibrated_ = true;
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
    if (const std::string why = check_live_blocks(); !why.empty()) {
        log_ << "lucent run: " << p_.source << ": " << why << "\n";
        return RunResult::UsageError;
    }
    if (!std::getenv("DISPLAY") && !std::getenv("WAYLAND_DISPLAY")) {
        log_ << "lucent run: no display (DISPLAY is not set): run under 'xvfb-run -a "
                "lucent run "
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
    // The first screen's clock starts now; keys pressed while preparing count for
    // nothing.
    flow_.emplace(p_, *store_, session_.id, store_->trials(session_.id),
                  store_->has_consent(session_.id), steady_now_ns());
    if (x_keys_) x_keys_->take();
    glfw_keys_.presses.clear();

    int64_t last_swap = steady_now_ns();
    while (!flow_->finished()) {
        window_->begin_frame();
        if (glfwWindowShouldClose(window_->glfw())) {  // closed by the window manager
            flow_->window_closed();
            break;
        }
        const int64_t now = steady_now_ns();
        frame_ns_ = now;
        if (autopilot_ && autopilot_->scripted() && !script_sent_) {
            x_keyboard_->play(
                autopilot_->script());  // the whole script, timed by the server
            script_sent_ = true;
        } else if (autopilot_ && !autopilot_->scripted()) {
            ScreenView view = flow_->view();
            if (view.kind == ScreenView::Kind::Adjust) {  // where a drag must start
                int w = 0, h = 0;
                window_->framebuffer_size(w, h);
                const std::optional<AdjustLayout> l = adjust_layout(w, h);
                if (l && l->fits) view.adjust.match = l->match;
            }
            const int pressed_again = autopilot_->presses_again();
            const std::vector<std::string> keys = autopilot_->due(now, view);
            if (autopilot_->presses_again() > pressed_again)
                log_ << "lucent run: autopilot: screen " << view.serial << " still shown "
                     << Autopilot::kPatienceNs / 1'000'000'000
                     << " s after its keys; pressing them again\n";
            // Take the focus back first: another window on the same X server may hold it.
            if (!keys.empty()) x_keyboard_->focus_window();
            for (const std::string& key : keys) x_keyboard_->tap(key);
        }
        feed_keys();
        if (flow_->finished()) break;
        int w = 0, h = 0;
        window_->framebuffer_size(w, h);
        // A choice trial too large for the window does not start (see draw()).
        if (!waits_for_a_larger_window(w, h)) flow_->tick(steady_now_ns());
        // The live match or comparison, before the frame that shows it.
        try {
            prepare_live();
        } catch (const std::exception& e) {
            log_ << "lucent run: " << e.what() << "\n";
            store_->set_status(session_.id, "paused", false);
            return RunResult::Failure;
        }
        present(w, h);
        // Without a paced display (Xvfb), cap the loop near 60 Hz instead of spinning.
        const int64_t swapped = steady_now_ns();
        if (mode_refresh_hz_ <= 0) {
            const int64_t next = last_swap + 16'666'667;
            if (next > swapped)
                std::this_thread::sleep_for(std::chrono::nanoseconds(next - swapped));
        }
        last_swap = steady_now_ns();
    }
    const RunResult result = flow_->result();
    if (result == RunResult::SavedAndQuit) {
        log_ << "lucent run: saved after " << flow_->answered_trials() << " of "
             << flow_->total_trials() << " trials; continue with --resume\n";
    } else if (result == RunResult::Declined) {
        log_ << "lucent run: consent declined; session closed\n";
    } else {
        log_ << "lucent run: session complete (" << flow_->total_trials() << " trials)\n";
    }
    // A server store: one last send of what the journal holds; what the server still
    // lacks stays journaled for `lucent store sync`.
    if (store_->pending_trials() > 0) {
        try {
            store_->sync();
        } catch (const StoreError& e) {
            log_ << "lucent run: " << e.what() << "\n";
        }
        if (const int left = store_->pending_trials(); left > 0)
            log_ << "lucent run: " << left
                 << " trials are kept in the local journal until " << store_->name()
                 << " confirms them; send them with 'lucent store sync --db "
                 << store_->name() << "'\n";
    }
    return result;
}

RunResult run_session(const RunOptions& options, StimulusRenderer& stimuli,
                      std::ostream& log) {
    Session session(options, stimuli, log);
    return session.run();
}

}  // namespace lucent::study

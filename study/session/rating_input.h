#pragma once
// The rating screen's input rules, GL-free so they are unit-tested: keys 1-7, arrows and
// Enter, or clicks; no answer is preselected; every change is counted and timed. Each
// question has its own scale length (2 to 7 points). A forced choice is one question
// of two alternatives, picked directly by the arrows.
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "study/sqlite/sqlite_store.h"

namespace lucent::study {

enum class RatingKey { Digit, Left, Right, Up, Down, Enter };

class RatingInput {
public:
    // points[q]: the scale length of question q.
    RatingInput(std::vector<int> points, int64_t onset_ns);
    // A forced choice (pair, triad, quadruple, a staircase's pair): one "question" of 2
    // alternatives; Left and Right (or 1 and 2) pick the first or the second, Enter
    // confirms, a click on an alternative picks it (the flow confirms it at once). An
    // odd one out of 3: digits pick, the arrows move the pick (the first picks the
    // middle), as on a rating scale.
    static RatingInput forced_choice(int64_t onset_ns, int alternatives = 2);
    bool is_choice() const { return choice_; }
    // `questions` questions on the same `points`-point scale.
    RatingInput(int questions, int points, int64_t onset_ns)
        : RatingInput(std::vector<int>(questions, points), onset_ns) {}

    // digit: 1..9 for RatingKey::Digit (values above the focused question's points are
    // ignored).
    void key(RatingKey key, int digit, int64_t t_ns);
    void click(int question, int value, int64_t t_ns);  // a point on a scale
    void click_next(int64_t t_ns);                      // the "Next" button

    int focus() const { return focus_; }
    std::optional<int> rating(int question) const { return state_[question].rating; }
    bool all_answered() const;
    bool confirmed() const { return confirmed_; }
    int64_t confirm_ns() const { return confirm_ns_; }
    // One Response per question (requires all_answered()); rt from onset to final choice.
    std::vector<Response> responses(const std::vector<std::string>& question_ids) const;

private:
    struct State {
        std::optional<int> rating;
        int changes = 0;
        int64_t first_ns = 0, final_ns = 0;
    };
    void set(int question, int value, int64_t t_ns);

    std::vector<State> state_;
    std::vector<int> points_;
    int64_t onset_ns_;
    bool choice_ = false;
    int focus_ = 0;
    bool confirmed_ = false;
    int64_t confirm_ns_ = 0;
};

}  // namespace lucent::study

#pragma once
// Paired comparisons scaled by Bradley-Terry (logit) or Thurstone's Case V (probit): one
// ability per stimulus, fitted as BradleyTerry2::BTm fits it, a binomial GLM without
// intercept on the win counts of each pair (design +1 for the first stimulus, -1 for the
// second, the reference stimulus's column dropped so its ability is 0). The hard cases
// (a stimulus that wins or loses every comparison, a comparison graph in parts, a
// participant who always picks one side, choices at chance) come back as sentences in
// `notes`; no NaN or infinity is ever reported.
#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "analysis/data/choice_table.h"
#include "analysis/scaling/binomial_glm.h"

namespace lucent::analysis {

// Wins of the first and of the second stimulus of a pair, `first` the one shown first
// (left) when the rows keep screen order; indices into PairedData::stimuli.
struct PairCount {
    std::size_t first = 0, second = 0;
    double first_wins = 0, second_wins = 0;
};

struct PairedData {
    std::vector<std::string> stimuli;  // the order: the default reference is the first
    std::vector<PairCount> counts;
};

struct PairedOptions {
    BinomialLink link = BinomialLink::logit;
    // The stimulus whose ability is 0; empty: the first of the order.
    std::string reference;
    // The position effect ("home advantage" in BTm's baseball example): a coefficient
    // added to the first-shown stimulus's ability. Implies screen_order_rows.
    bool order_effect = false;
    // One GLM row per ordered (first, second) pair as given, instead of one per
    // unordered pair. The abilities are the same; the deviance, its degrees of freedom
    // and the AIC are those of the rows (BTm on baseball: 42 rows, deviance on 36 df).
    bool screen_order_rows = false;
};

struct StimulusAbility {
    std::string stimulus;
    std::optional<double> ability, se;  // empty: unbounded (see `unbounded`, `notes`)
    // +1: won every comparison linking it to the rest (ability runs to +infinity);
    // -1: lost every one; 0: finite.
    int unbounded = 0;
    std::size_t group = 0;  // connected part of the comparison graph (0: the largest)
    bool reference = false;
    double wins = 0, comparisons = 0;
};

// A participant who picks the first-shown stimulus more often than chance: the share of
// first-shown choices and the two-sided exact binomial test against 1/2.
struct PositionBias {
    double first_chosen = 0, trials = 0;
    std::optional<double> share, p;
};

struct PairedFit {
    std::string model;  // "Bradley-Terry (logit)" or "Thurstone Case V (probit)"
    std::vector<StimulusAbility> abilities;  // in the order of PairedData::stimuli
    std::optional<double> order_effect, order_effect_se;
    std::optional<double> deviance, null_deviance, aic, log_likelihood;
    int df_residual = 0, parameters = 0, rows = 0;
    // Goodness of fit: the deviance against chi-square on df_residual (empty when no
    // residual df).
    std::optional<double> fit_p;
    // Against the all-equal model (every ability 0, no order effect): likelihood-ratio
    // chi-square on `parameters` df.
    std::optional<double> lr_chi2, lr_p;
    PositionBias position;
    bool converged = false;
    int groups = 0;                  // connected parts of the comparison graph
    std::vector<std::string> notes;  // the hard cases in words, one sentence each
};

PairedFit fit_paired_comparison(const PairedData& data,
                                const PairedOptions& options = {});

// ---- From choices ------------------------------------------------------------------

// The stimuli of a block in series order: `order` when given (stimuli not in it follow
// in order of first appearance), else by the value columns when every stimulus has one,
// else in order of first appearance.
std::vector<std::string> series_order(const std::vector<const ChoiceRow*>& rows,
                                      const std::vector<std::string>& order = {});

// The rows of one (block, question) of a choices table, as a scaling takes them: every
// row (catch trials included), the block's series in order with each stimulus's value,
// the judged rows (catch trials left out) of each participant in order of first
// appearance, and the catch trials counted with their wrong answers.
struct ChoiceBlock {
    std::string block, question;
    std::vector<const ChoiceRow*> rows;
    std::vector<std::string> stimuli;
    std::vector<std::optional<double>> values;
    std::vector<std::pair<std::string, std::vector<const ChoiceRow*>>> participants;
    std::size_t catch_trials = 0, catch_failed = 0;
};
// The pair blocks (`pairs`) or the MLDS blocks (triads, quadruples) of `table`, in order
// of first appearance; `orders`: block -> its series (see series_order).
std::vector<ChoiceBlock> choice_blocks(
    const ChoiceTable& table, bool pairs,
    const std::map<std::string, std::vector<std::string>>& orders);

// Counts of one set of pair rows (catch trials left out), screen order kept.
PairedData paired_data(const std::vector<const ChoiceRow*>& rows,
                       const std::vector<std::string>& stimuli);

struct PairedBlockFits {
    std::string block, question;
    std::vector<std::string> stimuli;           // series order
    std::vector<std::optional<double>> values;  // physical value per stimulus
    PairedFit pooled;
    // The pooled fit with the other link (Thurstone Case V beside Bradley-Terry, and
    // the other way round), so the report shows both scales.
    PairedFit pooled_other_link;
    std::vector<std::pair<std::string, PairedFit>> participants;  // in input order
    std::size_t catch_trials = 0, catch_failed = 0;
};

// Every pair block (block, question) of the table, pooled and per participant.
// `orders`: block -> stimulus order (e.g. the protocol's `stimuli`).
std::vector<PairedBlockFits> fit_paired_blocks(
    const ChoiceTable& table, const PairedOptions& options = {},
    const std::map<std::string, std::vector<std::string>>& orders = {});

}  // namespace lucent::analysis

// Per-question scale lengths in the store and in what the analysis reads: a rating must
// lie within 1..points of its own question, whatever the other questions allow.
#include "study/question_scales.h"

#include <gtest/gtest.h>

#include "study/sqlite/sqlite_store.h"
#include "tests/study/study_fixtures.h"
#include "tests/support/test_paths.h"

namespace lucent::study {
namespace {

struct MixedStudy {
    std::string path;
    Protocol protocol = lucent::test::mixed_scale_protocol();
    SessionRow session;
    std::vector<TrialRow> trials;
};

MixedStudy mixed_study(const std::string& name) {
    MixedStudy m;
    m.path = (lucent::test::scratch_dir(name) / "s.db").string();
    Store store(m.path);
    const int64_t study = store.ensure_study(m.protocol);
    const int64_t pid = store.ensure_participant(study, "P1", nullptr);
    m.session = store.create_session(study, pid, plan_trials(m.protocol, 1, 1), 1, {});
    m.trials = store.trials(m.session.id);
    return m;
}

TrialOutcome outcome(int translucent, int realistic) {
    TrialOutcome o;
    o.onset_ns = 1;
    o.confirm_ns = 2;
    for (const auto& [q, v] :
         {std::pair{"translucent", translucent}, {"realistic", realistic}})
        o.responses.push_back({q, v, 100.0, 0, 1, 1});
    return o;
}

TEST(QuestionScales, PointsComeFromEachQuestion) {
    const QuestionPoints points = question_points(lucent::test::mixed_scale_protocol());
    EXPECT_EQ(points, (QuestionPoints{{"translucent", 7}, {"realistic", 5}}));
}

TEST(QuestionScales, TheStoreRefusesARatingBeyondItsQuestionsScale) {
    MixedStudy m = mixed_study("scales_store");
    Store store(m.path);
    // 7 is on the 7-point scale, and refused on the 5-point one; nothing is kept.
    store.record_trial(m.session.id, m.trials[0].id, outcome(7, 5));
    try {
        store.record_trial(m.session.id, m.trials[1].id, outcome(4, 6));
        ADD_FAILURE() << "a 6 on a 5-point scale was stored";
    } catch (const StoreError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("'realistic'"), std::string::npos) << message;
        EXPECT_NE(message.find("1..5"), std::string::npos) << message;
    }
    EXPECT_THROW(store.record_trial(m.session.id, m.trials[1].id, outcome(0, 3)),
                 StoreError);
    TrialOutcome unknown = outcome(3, 3);
    unknown.responses[1].question = "varnished";
    EXPECT_THROW(store.record_trial(m.session.id, m.trials[1].id, unknown), StoreError);
    TrialOutcome missing = outcome(3, 3);
    missing.responses.pop_back();  // 'realistic' unanswered
    EXPECT_THROW(store.record_trial(m.session.id, m.trials[1].id, missing), StoreError);
    EXPECT_EQ(store.db().scalar_int("SELECT count(*) FROM responses"), 2);
    EXPECT_FALSE(store.trials(m.session.id)[1].answered);
    store.record_trial(m.session.id, m.trials[1].id, outcome(1, 1));
    EXPECT_EQ(store.db().scalar_int("SELECT count(*) FROM responses"), 4);
}

TEST(QuestionScales, StoredImpossibleRatingsAreFoundAndNamed) {
    MixedStudy m = mixed_study("scales_check");
    {
        Store store(m.path);
        store.record_trial(m.session.id, m.trials[0].id, outcome(7, 5));
        Database& db = store.db();
        // All on their scales; each rated question's scale comes back (the mixed study
        // asks 'translucent' on 7 points and 'realistic' on 5).
        EXPECT_EQ(check_stored_ratings(db),
                  (QuestionPoints{{"realistic", 5}, {"translucent", 7}}));
        // What a build before per-question scales could store: 7 on the 5-point scale.
        db.exec("UPDATE responses SET rating = 7 WHERE question = 'realistic'");
    }
    Database db(m.path, SQLITE_OPEN_READONLY);
    try {
        check_stored_ratings(db);
        ADD_FAILURE() << "an impossible stored rating passed";
    } catch (const StoreError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find("participant 'P1'"), std::string::npos) << message;
        EXPECT_NE(message.find(m.session.uuid), std::string::npos) << message;
        EXPECT_NE(message.find("rating 7 for question 'realistic'"), std::string::npos)
            << message;
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
}

}  // namespace
}  // namespace lucent::study

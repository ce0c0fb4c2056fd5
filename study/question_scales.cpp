#include "study/question_scales.h"

#include <algorithm>

#include "study/sqlite/sqlite_store.h"

namespace lucent::study {

QuestionPoints question_points(const Protocol& protocol) {
    QuestionPoints out;
    for (const Question& q : protocol.questions) out[q.id] = q.points();
    for (const Block& b : protocol.blocks)
        if (b.task != Task::rating) out[b.question_id] = b.answers();
    return out;
}

StudyQuestions study_questions(const Protocol& protocol) {
    StudyQuestions out;
    for (const Question& q : protocol.questions) out.rating[q.id] = q.points();
    for (const Block& b : protocol.blocks)
        if (b.task != Task::rating)
            out.block_question[b.id] = {b.question_id, b.answers()};
    return out;
}

QuestionPoints StudyQuestions::of_block(const std::string& block) const {
    const auto it = block_question.find(block);
    if (it == block_question.end()) return rating;
    return {{it->second.first, it->second.second}};
}

namespace {
Protocol stored_protocol(Database& db, int64_t study_id) {
    Statement s = db.prepare("SELECT name, protocol_text FROM studies WHERE id = ?");
    s.bind(1, study_id);
    if (!s.step()) throw StoreError(db.path() + ": no study " + std::to_string(study_id));
    try {
        return parse_protocol(s.text(1), db.path() + " (study '" + s.text(0) + "')", "",
                              KnobCheck::lenient);
    } catch (const ProtocolError& e) {
        throw StoreError(db.path() +
                         ": the stored protocol no longer parses: " + e.what());
    }
}
}  // namespace

QuestionPoints stored_question_points(Database& db, int64_t study_id) {
    return question_points(stored_protocol(db, study_id));
}

StudyQuestions stored_study_questions(Database& db, int64_t study_id) {
    return study_questions(stored_protocol(db, study_id));
}

void check_rating_on_scale(const QuestionPoints& points, const std::string& question,
                           int rating, const std::string& where) {
    const auto it = points.find(question);
    if (it == points.end())
        throw StoreError(where + ": question '" + question +
                         "' is not in the study's protocol");
    if (rating < 1 || rating > it->second)
        throw StoreError(where + ": rating " + std::to_string(rating) +
                         " for question '" + question + "' is outside its scale 1.." +
                         std::to_string(it->second));
}

QuestionPoints check_stored_ratings(Database& db) {
    std::map<int64_t, QuestionPoints> by_study;
    QuestionPoints rated;
    Statement s = db.prepare(
        "SELECT se.study_id, p.code, se.uuid, t.position, r.question, r.rating "
        "FROM responses r JOIN trials t ON t.id = r.trial_id "
        "JOIN sessions se ON se.id = r.session_id "
        "JOIN participants p ON p.id = se.participant_id ORDER BY se.id, t.position, "
        "r.id");
    while (s.step()) {
        const int64_t study = s.integer(0);
        auto it = by_study.find(study);
        if (it == by_study.end())
            it = by_study.emplace(study, stored_question_points(db, study)).first;
        check_rating_on_scale(it->second, s.text(4), static_cast<int>(s.integer(5)),
                              db.path() + ": participant '" + s.text(1) + "', session " +
                                  s.text(2) + ", trial " + std::to_string(s.integer(3)));
        int& points = rated[s.text(4)];
        points = std::max(points, it->second.at(s.text(4)));
    }
    return rated;
}

QuestionPoints check_stored_ratings(const std::string& path) {
    check_database_file(path);
    Database db(path, SQLITE_OPEN_READONLY);
    if (db.scalar_int("SELECT count(*) FROM sqlite_schema WHERE name = 'responses'") == 0)
        return {};
    return check_stored_ratings(db);
}

}  // namespace lucent::study

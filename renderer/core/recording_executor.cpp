#include "renderer/core/recording_executor.h"

#include <stdexcept>

namespace lucent {

std::vector<std::string> RecordingExecutor::execute(const FramePlan& plan,
                                                    const std::string& mesh_key) {
    const std::vector<bool> run = reuse_state_.schedule(plan, mesh_key, reuse_);
    for (const auto& name : reuse_state_.reallocated()) uploaded_hash_.erase(name);
    last_run_.clear();
    std::size_t index = 0;
    try {
        for_each_pass(plan, [&](const Pass& pass) {
            if (!run[index++]) return;
            last_run_.push_back(pass.name);
            if (pass.kind != PassKind::upload) return;
            const std::string& target = pass.writes.at(0);
            if (uploaded_hash_[target] == pass.data.content_hash) return;
            const std::string problem =
                check_texture_data(*plan.resource(target), producer_(pass));
            if (!problem.empty())
                throw std::runtime_error("pass '" + pass.name + "': data for '" + target +
                                         "': " + problem);
            uploaded_hash_[target] = pass.data.content_hash;
            ++uploads_;
        });
    } catch (...) {
        reuse_state_.forget();
        uploaded_hash_.clear();
        throw;
    }
    return last_run_;
}

}  // namespace lucent

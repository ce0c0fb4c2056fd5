#pragma once
// Runs a frame plan with no GL, recording which passes ran: the planner's tests use it
// the way Filament's tests use its no-op driver. It allocates, reuses passes and uploads
// exactly as renderer/gl/frame_executor does (the same PassReuse; a producer is called
// only when its content hash differs from the last upload into a resource that was not
// reallocated since) and checks produced data against the resource, so every pass kind
// can be tested without a context.
#include <cstddef>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "renderer/core/frame_plan.h"
#include "renderer/core/pass_reuse.h"

namespace lucent {

class RecordingExecutor {
public:
    // `reuse_unchanged_passes` as FrameExecutor::set_reuse_unchanged_passes.
    explicit RecordingExecutor(bool reuse_unchanged_passes = true)
        : reuse_(reuse_unchanged_passes) {}
    // As FrameExecutor::set_upload_producer: called for every upload performed.
    void set_upload_producer(UploadProducer producer) { producer_ = std::move(producer); }

    // Runs `plan` and returns the names of the passes that ran, in order. Throws
    // std::runtime_error (naming the pass and resource) for data that does not fit.
    std::vector<std::string> execute(const FramePlan& plan,
                                     const std::string& mesh_key = "mesh");
    const std::vector<std::string>& last_run() const { return last_run_; }
    std::size_t uploads_performed() const { return uploads_; }

private:
    bool reuse_;
    UploadProducer producer_ = produce_upload;
    PassReuse reuse_state_;
    std::map<std::string, std::string> uploaded_hash_;
    std::vector<std::string> last_run_;
    std::size_t uploads_ = 0;
};

}  // namespace lucent

#pragma once
// Which passes of a frame must run, given what the previous frames left in the
// resources: a pass whose inputs (its own description with uniforms and defines, the
// versions of what it reads, its upload's content hash, the mesh) match the last time
// it ran, and whose outputs still hold what it wrote then, is not run again. GL-free, so
// the GL executor and the recording test executor decide identically.
//
// Versions are kept per (resource, mip level): a pass's version is the hash of its
// inputs, and running it stamps that version on what it writes. A pass runs when its
// version differs from its last run's, or when a running pass (or the end of the frame)
// needs its output and the resource no longer holds it (a later pass of the previous
// frame overwrote it or composited onto it). A texture allocated anew (first use, a new
// size or format, or absent from the previous plan, which frees it) holds a fresh
// version no pass has, so its writers run.
#include <cstdint>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "renderer/core/frame_plan.h"

namespace lucent {

class PassReuse {
public:
    // One entry per pass of `plan`, in order: true = run it. Records the frame as if the
    // passes marked true ran (call forget() if running them then fails). `mesh_key`
    // identifies the mesh for draw_mesh passes and uploads into vertex streams. With
    // `reuse` false every pass runs (benchmarks) while versions are still kept.
    std::vector<bool> schedule(const FramePlan& plan, const std::string& mesh_key,
                               bool reuse = true);
    // Resources the last schedule() found newly allocated (their contents undefined).
    const std::vector<std::string>& reallocated() const { return reallocated_; }
    // Forgets every version: the next frame runs every pass.
    void forget();

private:
    using Subresource = std::pair<std::string, int>;  // (resource, level)
    std::map<std::string, ResourceDesc> storage_;     // what the executor has allocated
    // Version each subresource holds after the last frame.
    std::map<Subresource, std::uint64_t> physical_;
    std::map<std::string, std::uint64_t> last_run_;  // pass name -> its input hash
    std::vector<std::string> reallocated_;
    std::uint64_t fresh_ = 0;
};

// Hash of everything in `pass` that decides its output, except the resources' contents.
std::uint64_t pass_description_hash(const Pass& pass);

}  // namespace lucent

#pragma once
// Runs a FramePlan with OpenGL: allocates exactly the resources the plan names (textures
// of each resource's shape and levels, vertex streams), uploads CPU-made data through an
// UploadProducer, compiles each pass's shader variant once, binds reads to samplers (and
// streams to attributes) and writes to a framebuffer, and draws. Optional per-pass GPU
// timer queries feed `lucent bench frame` and the explorer's status bar. Needs a current
// GL 4.5 context; every GL object is owned by an RAII wrapper held here.
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "renderer/core/frame_plan.h"
#include "renderer/core/image.h"
#include "renderer/core/scene.h"
#include "renderer/gl/objects.h"

namespace lucent::gl {

struct PassTiming {
    std::string pass;
    double milliseconds = 0.0;
    bool cached = false;  // not re-run: its inputs had not changed since the last frame
};

struct FrameTimings {
    // One per pass of the last frame; without time_passes the times are 0 but `cached`
    // still says which passes ran.
    std::vector<PassTiming> passes;
    double total_milliseconds = 0.0;
    // True: GL_TIME_ELAPSED queries; false: wall time around glFinish (no timer queries).
    // Upload passes are CPU work and always wall time.
    bool gpu_timer = false;
};

class FrameExecutor {
public:
    FrameExecutor();
    ~FrameExecutor();
    FrameExecutor(const FrameExecutor&) = delete;
    FrameExecutor& operator=(const FrameExecutor&) = delete;

    // Produces the data of every upload performed (core/frame_plan.h UploadProducer);
    // the default calls the pass's producer. Forgets what was uploaded, so the next frame
    // uploads through the new producer.
    void set_upload_producer(UploadProducer producer);
    // On: a pass whose inputs (description, uniforms, versions of what it reads, upload
    // hash, mesh) are those of its last run, and whose outputs still hold that run's
    // results, is not run again (core/pass_reuse.h); last_timings() marks it cached. For
    // the explorer. Off (the default): every pass runs every frame, as benchmarks need.
    void set_reuse_unchanged_passes(bool reuse);

    // Runs every pass of `plan` for `scene`. With `time_passes`, last_timings() holds
    // per-pass times afterwards (this waits for the GPU). Throws ShaderError, GlError
    // naming the pass whose GL calls failed (gl/errors.h; checked after every pass,
    // upload and read-back), std::logic_error naming the pass and a uniform, sampler or
    // vertex stream its shaders do not declare (declared but inactive in the variant is
    // fine), or std::runtime_error.
    void execute(const Scene& scene, const FramePlan& plan, bool time_passes = false);
    // The plan's output after execute(), top row first.
    Image read_output(const FramePlan& plan) const;
    // Every texel of `level` of a texture resource (any shape), in upload order: x
    // fastest, row y = 0 (GL's bottom row) first, format_channels floats per texel.
    TextureData read_texture(const std::string& resource, int level = 0) const;
    // A frame-sized single-channel resource (a depth layer, the smoothed layer), top row
    // first: for tests and the explorer's buffer view.
    std::vector<float> read_channel(const std::string& resource) const;
    // execute() then read_output().
    Image render(const Scene& scene, const FramePlan& plan);

    const FrameTimings& last_timings() const { return timings_; }
    // How many times an upload pass called its producer and uploaded (a pass whose
    // content hash equals the resource's last upload costs nothing).
    std::size_t uploads_performed() const;
    // Names of the frame resources currently allocated (textures and vertex streams).
    std::vector<std::string> allocated_resources() const;

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
    FrameTimings timings_;
};

}  // namespace lucent::gl

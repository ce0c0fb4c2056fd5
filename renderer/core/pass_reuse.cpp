#include "renderer/core/pass_reuse.h"

#include <cstring>

#include "common/content_hash.h"

namespace lucent {
namespace {

// FNV-1a, 64 bit, over the values' bytes (in-process keys); texts are fed with their
// size so fields cannot run into each other.
using Hasher = common::ContentHash;

bool same_storage(const ResourceDesc& a, const ResourceDesc& b) {
    return a.format == b.format && a.shape == b.shape && a.size == b.size &&
           a.levels == b.levels;
}

// Mesh passes, and uploads into a vertex stream, whose elements are the mesh's vertices.
bool uses_mesh(const Pass& pass, const FramePlan& plan) {
    if (pass.kind == PassKind::draw_mesh) return true;
    for (const auto& w : pass.writes)
        if (const ResourceDesc* desc = plan.resource(w))
            if (desc->shape == ResourceShape::vertex_stream) return true;
    return false;
}

}  // namespace

std::uint64_t pass_description_hash(const Pass& pass) {
    Hasher h;
    h.value(pass.kind);
    h.text(pass.shader.vertex);
    h.text(pass.shader.fragment);
    h.value(pass.shader.defines.size());
    for (const auto& d : pass.shader.defines) h.text(d);
    h.value(pass.reads.size());
    for (const auto& r : pass.reads) {
        h.text(r.resource);
        h.text(r.sampler);
        h.value(r.sampling.filter);
        h.value(r.sampling.mip);
        h.value(r.sampling.wrap);
        h.value(r.sampling.border);
    }
    h.value(pass.writes.size());
    for (const auto& w : pass.writes) h.text(w);
    h.value(pass.uniforms.size());
    for (const auto& u : pass.uniforms) {
        h.text(u.name);
        h.value(u.value.index());
        std::visit([&](const auto& v) { h.value(v); }, u.value);
    }
    h.value(pass.clear_colour);
    h.value(pass.level);
    h.value(pass.clear);
    h.value(pass.blend);
    h.value(pass.cull);
    h.text(pass.data.content_hash);
    return h.result();
}

std::vector<bool> PassReuse::schedule(const FramePlan& plan, const std::string& mesh_key,
                                      bool reuse) {
    // Storage as the executor will allocate it: kept when unchanged, new otherwise,
    // freed when the plan does not name it. New storage holds a version no pass has.
    reallocated_.clear();
    std::map<std::string, ResourceDesc> storage;
    for (const auto& r : plan.resources) {
        auto it = storage_.find(r.name);
        if (it == storage_.end() || !same_storage(it->second, r)) {
            reallocated_.push_back(r.name);
            for (int level = 0; level < r.levels; ++level)
                physical_[{r.name, level}] = ++fresh_;  // small numbers: no pass hash
        }
        storage.emplace(r.name, r);
    }
    storage_ = std::move(storage);

    // What each pass reads and writes, and its version: the hash of its description and
    // of the versions of its inputs as this frame produces them ("logical" versions).
    struct Step {
        std::vector<std::pair<Subresource, std::uint64_t>> inputs;  // with the version
        std::vector<Subresource> writes;
        std::uint64_t version = 0;
    };
    const std::size_t count = plan.passes.size();
    std::vector<Step> steps(count);
    std::map<Subresource, std::uint64_t> logical = physical_;
    for (std::size_t i = 0; i < count; ++i) {
        const Pass& pass = plan.passes[i];
        Step& step = steps[i];
        std::vector<Subresource> inputs;
        for (const auto& r : pass.reads) {
            const ResourceDesc* desc = plan.resource(r.resource);
            for (int level = 0; level < (desc ? desc->levels : 1); ++level)
                inputs.push_back({r.resource, level});
        }
        for (const auto& w : pass.writes) {
            const ResourceDesc* desc = plan.resource(w);
            const int levels = desc ? desc->levels : 1;
            if (pass.kind == PassKind::build_mips) {
                inputs.push_back({w, 0});
                for (int level = 1; level < levels; ++level)
                    step.writes.push_back({w, level});
            } else if (pass.kind == PassKind::upload) {
                for (int level = 0; level < levels; ++level)
                    step.writes.push_back({w, level});
            } else {
                step.writes.push_back({w, pass.level});
                if (!pass.clear) inputs.push_back({w, pass.level});
            }
        }
        Hasher h;
        h.value(pass_description_hash(pass));
        if (uses_mesh(pass, plan)) h.text(mesh_key);
        for (const auto& s : inputs) {
            const std::uint64_t v = logical[s];
            h.value(v);
            step.inputs.push_back({s, v});
        }
        for (const auto& w : pass.writes)
            if (const ResourceDesc* desc = plan.resource(w)) {
                h.value(desc->size);
                h.value(desc->format);
                h.value(desc->levels);
            }
        step.version = h.result();
        for (const auto& s : step.writes) logical[s] = step.version;
    }

    // Run what changed; then, until nothing more is needed, also run a skipped pass whose
    // output a running pass reads (or that the frame must end with) but that the
    // resource no longer holds, because a later pass overwrote or composited onto it.
    std::vector<bool> run(count);
    for (std::size_t i = 0; i < count; ++i) {
        auto last = last_run_.find(plan.passes[i].name);
        run[i] = !reuse || last == last_run_.end() || last->second != steps[i].version;
    }
    std::map<Subresource, std::uint64_t> physical;
    for (bool settled = false; !settled;) {
        settled = true;
        physical = physical_;
        std::map<Subresource, std::size_t> writer;
        for (std::size_t i = 0; i < count && settled; ++i) {
            if (run[i])
                for (const auto& [s, v] : steps[i].inputs)
                    if (physical[s] != v && writer.count(s)) {
                        run[writer[s]] = true;
                        settled = false;
                        break;
                    }
            for (const auto& s : steps[i].writes) {
                writer[s] = i;
                if (run[i]) physical[s] = steps[i].version;
            }
        }
        if (!settled) continue;
        for (const auto& [s, i] : writer)
            if (physical[s] != logical[s]) {
                run[i] = true;
                settled = false;
            }
    }
    physical_ = std::move(physical);
    for (std::size_t i = 0; i < count; ++i)
        if (run[i]) last_run_[plan.passes[i].name] = steps[i].version;
    return run;
}

void PassReuse::forget() {
    storage_.clear();
    physical_.clear();
    last_run_.clear();
}

}  // namespace lucent

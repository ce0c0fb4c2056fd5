#include "core/frame_plan.h"

#include <algorithm>
#include <set>
#include <stdexcept>

namespace lucent {

bool is_depth_format(ResourceFormat format) {
    return format == ResourceFormat::depth16 || format == ResourceFormat::depth24 ||
           format == ResourceFormat::depth32f;
}

const char* format_name(ResourceFormat format) {
    switch (format) {
        case ResourceFormat::depth16:
            return "depth16";
        case ResourceFormat::depth24:
            return "depth24";
        case ResourceFormat::depth32f:
            return "depth32f";
        case ResourceFormat::r32f:
            return "r32f";
        case ResourceFormat::rgba32f:
            return "rgba32f";
        case ResourceFormat::vertex_float:
            return "vertex float";
    }
    return "?";
}

const ResourceDesc* FramePlan::resource(const std::string& name) const {
    for (const auto& r : resources)
        if (r.name == name) return &r;
    return nullptr;
}

std::string FramePlan::explain() const {
    std::string text;
    for (const auto& pass : passes) {
        std::string reads, writes;
        for (const auto& r : pass.reads)
            reads += (reads.empty() ? "" : ", ") + r.resource;
        for (const auto& w : pass.writes) {
            const ResourceDesc* desc = resource(w);
            writes += (writes.empty() ? "" : ", ") + w + " (" +
                      (desc ? format_name(desc->format) : "?") + ")";
        }
        text += pass.name + ": " + (reads.empty() ? "-" : reads) + " -> " + writes;
        if (!pass.shader.defines.empty()) {
            std::string defines;
            for (const auto& d : pass.shader.defines)
                defines += (defines.empty() ? "" : " ") + d;
            text += "  {" + defines + "}";
        }
        text += "  [" + pass.purpose + "]\n";
    }
    for (const auto& name : culled) text += "culled: " + name + "\n";
    return text;
}

PlanBuilder::PlanBuilder(PlanMode mode, int width, int height)
    : mode_(mode), width_(width), height_(height) {}

void PlanBuilder::create(std::string name, ResourceFormat format) {
    for (const auto& r : resources_)
        if (r.name == name)
            throw std::logic_error("frame plan: resource '" + name + "' created twice");
    resources_.push_back({std::move(name), format});
}

void PlanBuilder::add(Pass pass) {
    for (const auto& p : passes_)
        if (p.name == pass.name)
            throw std::logic_error("frame plan: pass '" + pass.name + "' added twice");
    passes_.push_back(std::move(pass));
}

void PlanBuilder::set_output(std::string resource) { output_ = std::move(resource); }

FramePlan PlanBuilder::compile() const {
    const auto created = [&](const std::string& name) {
        return std::any_of(resources_.begin(), resources_.end(),
                           [&](const ResourceDesc& r) { return r.name == name; });
    };
    // Validate the declared data flow: reads follow writes, writes name created
    // resources.
    std::set<std::string> written;
    for (const auto& pass : passes_) {
        for (const auto& read : pass.reads)
            if (!written.count(read.resource))
                throw std::logic_error("frame plan: pass '" + pass.name + "' reads '" +
                                       read.resource + "' before any pass writes it");
        for (const auto& w : pass.writes) {
            if (!created(w))
                throw std::logic_error("frame plan: pass '" + pass.name +
                                       "' writes undeclared '" + w + "'");
            written.insert(w);
        }
    }
    if (output_.empty() || !written.count(output_))
        throw std::logic_error("frame plan: no pass writes the output '" + output_ + "'");

    // Cull: walk backwards from the output, keeping a pass only when something needed
    // later reads one of its writes; a kept pass makes its reads needed.
    std::set<std::string> needed{output_};
    std::vector<bool> keep(passes_.size(), false);
    for (std::size_t i = passes_.size(); i-- > 0;) {
        const Pass& pass = passes_[i];
        const bool used =
            std::any_of(pass.writes.begin(), pass.writes.end(),
                        [&](const std::string& w) { return needed.count(w) > 0; });
        keep[i] = used || full();
        if (keep[i])
            for (const auto& read : pass.reads) needed.insert(read.resource);
    }

    FramePlan plan;
    plan.width = width_;
    plan.height = height_;
    plan.output = output_;
    std::set<std::string> touched;
    for (std::size_t i = 0; i < passes_.size(); ++i) {
        if (!keep[i]) {
            plan.culled.push_back(passes_[i].name);
            continue;
        }
        plan.passes.push_back(passes_[i]);
        for (const auto& r : passes_[i].reads) touched.insert(r.resource);
        for (const auto& w : passes_[i].writes) touched.insert(w);
    }
    for (const auto& r : resources_)
        if (touched.count(r.name)) plan.resources.push_back(r);
    return plan;
}

void for_each_pass(const FramePlan& plan, const std::function<void(const Pass&)>& visit) {
    for (const auto& pass : plan.passes) visit(pass);
}

}  // namespace lucent

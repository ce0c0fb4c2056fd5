#include "renderer/core/frame_plan.h"

#include <algorithm>
#include <glm/gtc/matrix_inverse.hpp>
#include <set>
#include <stdexcept>

namespace lucent {

std::vector<Uniform> mesh_transform_uniforms(const glm::mat4& view,
                                             const glm::mat4& projection) {
    return {{"u_model_view", view},
            {"u_projection", projection},
            {"u_normal_matrix", glm::inverseTranspose(glm::mat3(view))}};
}

std::vector<Uniform> with_uniforms(std::vector<Uniform> a,
                                   const std::vector<Uniform>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
}

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
        case ResourceFormat::r8:
            return "r8";
        case ResourceFormat::r32f:
            return "r32f";
        case ResourceFormat::rg32f:
            return "rg32f";
        case ResourceFormat::rgba8:
            return "rgba8";
        case ResourceFormat::rgba16f:
            return "rgba16f";
        case ResourceFormat::rgba32f:
            return "rgba32f";
    }
    return "?";
}

int format_channels(ResourceFormat format) {
    switch (format) {
        case ResourceFormat::depth16:
        case ResourceFormat::depth24:
        case ResourceFormat::depth32f:
        case ResourceFormat::r8:
        case ResourceFormat::r32f:
            return 1;
        case ResourceFormat::rg32f:
            return 2;
        case ResourceFormat::rgba8:
        case ResourceFormat::rgba16f:
        case ResourceFormat::rgba32f:
            return 4;
    }
    return 0;
}

const char* pass_kind_name(PassKind kind) {
    switch (kind) {
        case PassKind::draw_mesh:
            return "draw_mesh";
        case PassKind::fullscreen:
            return "fullscreen";
        case PassKind::upload:
            return "upload";
        case PassKind::build_mips:
            return "build_mips";
    }
    return "?";
}

ResourceDesc frame_texture(std::string name, ResourceFormat format, int levels) {
    return {std::move(name), format, ResourceShape::frame, {0, 0, 1}, levels};
}

ResourceDesc texture_2d(std::string name, ResourceFormat format, int width, int height,
                        int levels) {
    return {std::move(name), format, ResourceShape::fixed_2d, {width, height, 1}, levels};
}

ResourceDesc texture_3d(std::string name, ResourceFormat format, int width, int height,
                        int depth) {
    return {std::move(name), format, ResourceShape::fixed_3d, {width, height, depth}, 1};
}

ResourceDesc vertex_stream(std::string name, ResourceFormat format, int vertex_count,
                           int attribute) {
    return {std::move(name),      format, ResourceShape::vertex_stream,
            {vertex_count, 1, 1}, 1,      attribute};
}

bool is_bake(const Pass& pass) {
    return pass.kind == PassKind::upload && pass.data.cost == ProductionCost::bake;
}

TextureData produce_upload(const Pass& upload) { return upload.data.produce({}); }

glm::ivec3 mip_size(glm::ivec3 base, int level, bool three_d) {
    glm::ivec3 size = base;
    for (int l = 0; l < level; ++l) {
        size.x = std::max(1, size.x / 2);
        size.y = std::max(1, size.y / 2);
        if (three_d) size.z = std::max(1, size.z / 2);
    }
    if (!three_d) size.z = 1;
    return size;
}

int full_mip_levels(glm::ivec3 base, bool three_d) {
    int largest = std::max(base.x, base.y);
    if (three_d) largest = std::max(largest, base.z);
    int levels = 1;
    while (largest > 1) largest /= 2, ++levels;
    return levels;
}

namespace {

std::string size_text(glm::ivec3 size, bool three_d) {
    // Appended piecewise: "x" + std::to_string trips GCC 12's -Wrestrict false positive.
    std::string text = std::to_string(size.x);
    text.append("x").append(std::to_string(size.y));
    if (three_d) text.append("x").append(std::to_string(size.z));
    return text;
}

bool is_3d(const ResourceDesc& desc) { return desc.shape == ResourceShape::fixed_3d; }
bool is_stream(const ResourceDesc& desc) {
    return desc.shape == ResourceShape::vertex_stream;
}

// Passes whose attachments keep their earlier contents depend on them like on a read.
bool reads_own_writes(const Pass& pass) {
    return !pass.clear || pass.kind == PassKind::build_mips;
}

}  // namespace

std::string check_texture_data(const ResourceDesc& desc, const TextureData& data) {
    if (data.size != desc.size)
        return "data is " + size_text(data.size, true) + ", the resource " +
               size_text(desc.size, true);
    if (data.levels.empty() || data.levels.size() > static_cast<std::size_t>(desc.levels))
        return std::to_string(data.levels.size()) + " data levels for a resource of " +
               std::to_string(desc.levels);
    for (std::size_t l = 0; l < data.levels.size(); ++l) {
        const glm::ivec3 s = mip_size(desc.size, static_cast<int>(l), is_3d(desc));
        const std::size_t expected =
            static_cast<std::size_t>(s.x) * s.y * s.z *
            static_cast<std::size_t>(format_channels(desc.format));
        if (data.levels[l].size() != expected)
            return "level " + std::to_string(l) + " has " +
                   std::to_string(data.levels[l].size()) + " floats, expected " +
                   std::to_string(expected);
    }
    return "";
}

std::string describe(const Sampling& sampling) {
    std::string text = sampling.filter == TexelFilter::nearest ? "nearest" : "linear";
    if (sampling.mip == MipFilter::nearest) text += "/mip nearest";
    if (sampling.mip == MipFilter::linear) text += "/mip linear";
    switch (sampling.wrap) {
        case Wrap::clamp_to_edge:
            return text + " clamp";
        case Wrap::repeat:
            return text + " repeat";
        case Wrap::clamp_to_border:
            break;
    }
    const glm::vec4& b = sampling.border;
    auto number = [](float v) {
        std::string s = std::to_string(v);
        s.erase(s.find_last_not_of('0') + 1);
        if (!s.empty() && s.back() == '.') s.pop_back();
        return s;
    };
    return text + " border(" + number(b.r) + "," + number(b.g) + "," + number(b.b) + "," +
           number(b.a) + ")";
}

const ResourceDesc* FramePlan::resource(const std::string& name) const {
    for (const auto& r : resources)
        if (r.name == name) return &r;
    return nullptr;
}

glm::ivec2 FramePlan::viewport(const Pass& pass) const {
    for (const auto& w : pass.writes)
        if (const ResourceDesc* desc = resource(w))
            if (!is_stream(*desc))
                return glm::ivec2(mip_size(desc->size, pass.level, is_3d(*desc)));
    return {width, height};
}

std::string FramePlan::explain() const {
    std::string text;
    for (const auto& r : resources) {
        text += "resource " + r.name + ": ";
        if (is_stream(r)) {
            text += std::to_string(r.size.x) + " vertices x " + format_name(r.format) +
                    " at attribute " + std::to_string(r.attribute) + "\n";
            continue;
        }
        text += size_text(r.size, is_3d(r)) + " " + format_name(r.format);
        if (r.levels > 1) text += ", " + std::to_string(r.levels) + " levels";
        if (r.shape == ResourceShape::frame) text += " (frame)";
        text += "\n";
    }
    for (const auto& pass : passes) {
        std::string reads, writes;
        for (const auto& r : pass.reads) {
            reads += (reads.empty() ? "" : ", ") + r.resource;
            const ResourceDesc* desc = resource(r.resource);
            const Sampling defaults{};
            if (desc && !is_stream(*desc) &&
                (r.sampling.filter != defaults.filter || r.sampling.mip != defaults.mip ||
                 r.sampling.wrap != defaults.wrap))
                reads += " (" + describe(r.sampling) + ")";
        }
        for (const auto& w : pass.writes) {
            const ResourceDesc* desc = resource(w);
            writes += (writes.empty() ? "" : ", ") + w + " (" +
                      (desc ? format_name(desc->format) : "?") + ")";
        }
        text += pass.name + ": " + (reads.empty() ? "-" : reads) + " -> " + writes;
        if (pass.kind == PassKind::upload)
            text += "  <upload, data " + pass.data.content_hash + ">";
        if (pass.kind == PassKind::build_mips) text += "  <2x2 box mips>";
        if (pass.level > 0) text += "  <level " + std::to_string(pass.level) + ">";
        if (!pass.clear) text += "  <keeps contents>";
        if (pass.blend == Blend::additive) text += "  <blend additive>";
        if (pass.blend == Blend::premultiplied_over) text += "  <blend over>";
        if (pass.blend == Blend::premultiplied_under) text += "  <blend under>";
        if (pass.cull == FaceCulling::back) text += "  <culls back faces>";
        if (pass.cull == FaceCulling::front) text += "  <culls front faces>";
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
    create(frame_texture(std::move(name), format));
}

void PlanBuilder::create(ResourceDesc desc) {
    for (const auto& r : resources_)
        if (r.name == desc.name)
            throw std::logic_error("frame plan: resource '" + desc.name +
                                   "' created twice");
    resources_.push_back(std::move(desc));
}

void PlanBuilder::add(Pass pass) {
    const std::string where = "frame plan: pass '" + pass.name + "'";
    for (const auto& p : passes_)
        if (p.name == pass.name) throw std::logic_error(where + " added twice");
    const auto created = [&](const std::string& name) {
        return std::any_of(resources_.begin(), resources_.end(),
                           [&](const ResourceDesc& r) { return r.name == name; });
    };
    const auto written = [&](const std::string& name) {
        return std::find(written_.begin(), written_.end(), name) != written_.end();
    };
    for (const auto& read : pass.reads) {
        if (!created(read.resource))
            throw std::logic_error(where + " reads '" + read.resource +
                                   "', which no create() declared");
        if (!written(read.resource))
            throw std::logic_error(where + " reads '" + read.resource +
                                   "' before any pass writes it");
        if (std::find(pass.writes.begin(), pass.writes.end(), read.resource) !=
            pass.writes.end())
            throw std::logic_error(where + " reads '" + read.resource +
                                   "' while writing it");
    }
    for (const auto& w : pass.writes) {
        if (!created(w)) throw std::logic_error(where + " writes undeclared '" + w + "'");
        if (reads_own_writes(pass) && !written(w))
            throw std::logic_error(where + " keeps the contents of '" + w +
                                   "' before any pass writes it");
    }
    for (const auto& w : pass.writes)
        if (!written(w)) written_.push_back(w);
    passes_.push_back(std::move(pass));
}

void PlanBuilder::set_output(std::string resource) { output_ = std::move(resource); }

void PlanBuilder::also_keep(std::string resource) {
    also_keep_.push_back(std::move(resource));
}

namespace {

// compile(), stage 1: every resource's size and level count resolved and checked.
std::vector<ResourceDesc> resolve_resources(std::vector<ResourceDesc> resolved, int width,
                                            int height) {
    for (auto& r : resolved) {
        const std::string where = "frame plan: resource '" + r.name + "'";
        if (r.shape == ResourceShape::frame) r.size = {width, height, 1};
        if (r.shape == ResourceShape::fixed_2d) r.size.z = 1;
        if (is_stream(r)) {
            r.size = {r.size.x, 1, 1};
            r.levels = 1;
            if (r.size.x <= 0)
                throw std::logic_error(where + " has " + std::to_string(r.size.x) +
                                       " vertices");
            if (r.format != ResourceFormat::r32f && r.format != ResourceFormat::rg32f &&
                r.format != ResourceFormat::rgba32f)
                throw std::logic_error(where +
                                       ": a vertex stream is r32f, rg32f or "
                                       "rgba32f, not " +
                                       std::string(format_name(r.format)));
            const bool taken =
                std::find(std::begin(kMeshAttributes), std::end(kMeshAttributes),
                          r.attribute) != std::end(kMeshAttributes);
            if (r.attribute < 0 || r.attribute > 15 || taken)
                throw std::logic_error(where + ": attribute " +
                                       std::to_string(r.attribute) +
                                       " is not a free vertex attribute location");
            continue;
        }
        if (r.size.x <= 0 || r.size.y <= 0 || r.size.z <= 0)
            throw std::logic_error(where + " has size " + size_text(r.size, is_3d(r)));
        const int full_chain = full_mip_levels(r.size, is_3d(r));
        if (r.levels == 0) r.levels = full_chain;
        if (r.levels < 0 || r.levels > full_chain)
            throw std::logic_error(where + ": " + std::to_string(r.levels) +
                                   " levels, a full chain has " +
                                   std::to_string(full_chain));
        if (is_3d(r) && r.levels != 1)
            throw std::logic_error(where + ": 3D resources have one level");
        if (is_3d(r) && is_depth_format(r.format))
            throw std::logic_error(where + ": a depth format cannot be 3D");
    }
    return resolved;
}

// compile(), stage 2: what add() could not check of one pass: attachments agree, special
// passes write one fitting resource, vertex streams are uploaded and read by mesh passes.
// (add() checked that every name is created and that reads follow writes.)
void check_pass(const Pass& pass,
                const std::function<const ResourceDesc*(const std::string&)>& find) {
    const std::string where = "frame plan: pass '" + pass.name + "'";
    for (const auto& read : pass.reads)
        if (is_stream(*find(read.resource)) && pass.kind != PassKind::draw_mesh)
            throw std::logic_error(where + " reads the vertex stream '" + read.resource +
                                   "' but draws no mesh");
    glm::ivec3 attachment_size{0};
    std::string first_attachment;
    int depth_attachments = 0;
    for (const auto& w : pass.writes) {
        const ResourceDesc* desc = find(w);
        if (is_stream(*desc)) {
            if (pass.kind != PassKind::upload)
                throw std::logic_error(where + " draws into the vertex stream '" + w +
                                       "'; streams are uploaded");
            continue;
        }
        if (pass.level < 0 || pass.level >= desc->levels)
            throw std::logic_error(where + " writes level " + std::to_string(pass.level) +
                                   " of '" + w + "', which has " +
                                   std::to_string(desc->levels));
        if (is_depth_format(desc->format)) ++depth_attachments;
        const glm::ivec3 size = mip_size(desc->size, pass.level, is_3d(*desc));
        if (first_attachment.empty()) {
            attachment_size = size;
            first_attachment = w;
        } else if (size != attachment_size) {
            throw std::logic_error(where + " writes '" + first_attachment + "' (" +
                                   size_text(attachment_size, true) + ") and '" + w +
                                   "' (" + size_text(size, true) +
                                   "): attachments differ in size");
        }
        if (is_3d(*desc) && pass.kind != PassKind::upload)
            throw std::logic_error(where + " renders into the 3D resource '" + w +
                                   "'; volumes are uploaded");
    }
    if (depth_attachments > 1)
        throw std::logic_error(where + " writes " + std::to_string(depth_attachments) +
                               " depth attachments");
    if (pass.kind == PassKind::upload || pass.kind == PassKind::build_mips) {
        const ResourceDesc* desc =
            pass.writes.size() == 1 ? find(pass.writes[0]) : nullptr;
        if (!desc || is_depth_format(desc->format) ||
            (is_stream(*desc) && pass.kind != PassKind::upload))
            throw std::logic_error(where + " (" + pass_kind_name(pass.kind) +
                                   ") must write exactly one colour resource");
        if (!pass.reads.empty())
            throw std::logic_error(where + " (" + pass_kind_name(pass.kind) +
                                   ") reads nothing");
        if (pass.kind == PassKind::upload &&
            (pass.data.content_hash.empty() || !pass.data.produce))
            throw std::logic_error(where +
                                   " uploads data without a content hash or producer");
        if (pass.kind == PassKind::build_mips &&
            (desc->levels < 2 || is_3d(*desc) || pass.level != 0))
            throw std::logic_error(where + " builds mips of '" + desc->name +
                                   "', which needs a 2D resource of several levels");
    }
}

// compile(), stage 3: walk backwards from the output, keeping a pass only when something
// needed later reads one of its writes; a kept pass makes its reads needed.
std::vector<bool> passes_to_keep(const std::vector<Pass>& passes,
                                 const std::string& output,
                                 const std::vector<std::string>& also_keep, bool full) {
    std::set<std::string> needed{output};
    needed.insert(also_keep.begin(), also_keep.end());
    std::vector<bool> keep(passes.size(), false);
    for (std::size_t i = passes.size(); i-- > 0;) {
        const Pass& pass = passes[i];
        const bool used =
            std::any_of(pass.writes.begin(), pass.writes.end(),
                        [&](const std::string& w) { return needed.count(w) > 0; });
        keep[i] = used || full;
        if (!keep[i]) continue;
        for (const auto& read : pass.reads) needed.insert(read.resource);
        if (reads_own_writes(pass))
            for (const auto& w : pass.writes) needed.insert(w);
    }

    return keep;
}

}  // namespace

FramePlan PlanBuilder::compile() const {
    const std::vector<ResourceDesc> resolved =
        resolve_resources(resources_, width_, height_);
    const auto find = [&](const std::string& name) -> const ResourceDesc* {
        for (const auto& r : resolved)
            if (r.name == name) return &r;
        return nullptr;
    };
    for (const auto& pass : passes_) check_pass(pass, find);
    if (output_.empty() ||
        std::find(written_.begin(), written_.end(), output_) == written_.end())
        throw std::logic_error("frame plan: no pass writes the output '" + output_ + "'");
    const std::vector<bool> keep = passes_to_keep(passes_, output_, also_keep_, full());

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
    for (const auto& r : resolved)
        if (touched.count(r.name)) plan.resources.push_back(r);
    return plan;
}

void for_each_pass(const FramePlan& plan, const std::function<void(const Pass&)>& visit) {
    for (const auto& pass : plan.passes) visit(pass);
}

}  // namespace lucent

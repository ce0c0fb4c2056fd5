// OcclusionCounter on Embree 3: a static, robust scene of paired quads (or triangles).
#include "renderer/cpu/occlusion_counter.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "renderer/cpu/embree_support.h"

namespace lucent {

PairedTriangles pair_triangles(const std::vector<glm::uvec3>& triangles) {
    // Directed edges (from, to) with their triangle and the corner opposite them,
    // sorted so that an edge's reverse is found by binary search.
    struct Edge {
        std::uint64_t key;  // from << 32 | to
        std::uint32_t triangle;
        std::uint32_t corner;  // 0..2: the edge runs from corner+1 to corner+2
    };
    std::vector<Edge> edges;
    edges.reserve(3 * triangles.size());
    for (std::uint32_t t = 0; t < triangles.size(); ++t)
        for (std::uint32_t c = 0; c < 3; ++c)
            edges.push_back({std::uint64_t(triangles[t][(c + 1) % 3]) << 32 |
                                 triangles[t][(c + 2) % 3],
                             t, c});
    std::sort(edges.begin(), edges.end(), [](const Edge& a, const Edge& b) {
        return a.key != b.key ? a.key < b.key : a.triangle < b.triangle;
    });
    PairedTriangles out;
    out.quads.reserve(triangles.size());
    std::vector<bool> used(triangles.size(), false);
    for (std::uint32_t t = 0; t < triangles.size(); ++t) {
        if (used[t]) continue;
        used[t] = true;
        const glm::uvec3 tri = triangles[t];
        bool paired = false;
        for (std::uint32_t c = 0; c < 3 && !paired; ++c) {
            // Edge (p, q) of t, opposite its corner r; a partner runs (q, p), opposite s.
            const std::uint32_t r = tri[c], p = tri[(c + 1) % 3], q = tri[(c + 2) % 3];
            const std::uint64_t reverse = std::uint64_t(q) << 32 | p;
            auto it = std::lower_bound(
                edges.begin(), edges.end(), reverse,
                [](const Edge& e, std::uint64_t key) { return e.key < key; });
            for (; it != edges.end() && it->key == reverse; ++it) {
                if (used[it->triangle]) continue;
                const std::uint32_t s = triangles[it->triangle][it->corner];
                if (s == r) continue;  // the same triangle wound backwards: a sliver
                // (v0, v1, v3) = (r, p, q), a rotation of t; (v2, v3, v1) = (s, q, p),
                // a rotation of the partner (q, p, s).
                out.quads.push_back({r, p, s, q});
                used[it->triangle] = true;
                out.paired += 2;
                paired = true;
                break;
            }
        }
        if (!paired) out.quads.push_back({tri.x, tri.y, tri.z, tri.z});
    }
    return out;
}

namespace {

bool has_avx() {
#if defined(__x86_64__) || defined(__i386__)
    return __builtin_cpu_supports("avx");
#else
    return false;
#endif
}

}  // namespace

struct OcclusionCounter::Impl {
    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    std::size_t primitives = 0;
    std::size_t paired = 0;

    ~Impl() {
        if (scene) rtcReleaseScene(scene);
        if (device) rtcReleaseDevice(device);
    }
};

OcclusionCounter::OcclusionCounter(const Mesh& mesh, OcclusionScene layout)
    : impl_(std::make_unique<Impl>()) {
    embree::check_indices(mesh);
    // Quads stored with their vertices in 8-wide nodes (AVX) traced fastest; Embree's
    // robust default stores indices (quad4i), 1.3x slower here. Same answers either way.
    const bool quads = layout == OcclusionScene::paired_quads;
    impl_->device = embree::new_device(!quads      ? nullptr
                                       : has_avx() ? "quad_accel=bvh8.quad4v"
                                                   : "quad_accel=bvh4.quad4v");
    if (quads) {
        const PairedTriangles paired = pair_triangles(mesh.triangles);
        impl_->scene = embree::build_scene(impl_->device, mesh, &paired.quads);
        impl_->primitives = paired.quads.size();
        impl_->paired = paired.paired;
    } else {
        impl_->scene = embree::build_scene(impl_->device, mesh);
        impl_->primitives = mesh.triangles.size();
    }
}

OcclusionCounter::~OcclusionCounter() = default;
OcclusionCounter::OcclusionCounter(OcclusionCounter&&) noexcept = default;
OcclusionCounter& OcclusionCounter::operator=(OcclusionCounter&&) noexcept = default;

std::size_t OcclusionCounter::primitives() const { return impl_->primitives; }
std::size_t OcclusionCounter::paired_triangles() const { return impl_->paired; }

std::size_t OcclusionCounter::count_escaping(glm::vec3 origin,
                                             const std::vector<glm::vec3>& directions,
                                             float t_min, OcclusionQuery query) const {
    if (!embree::finite(origin))
        return directions.size();  // an unusable ray hits nothing
    const embree::FlushDenormals flush;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);  // incoherent: the rays fan out over a hemisphere
    // Embree's tnear is inclusive; the count excludes t_min itself.
    const float near =
        std::nextafter(std::max(t_min, 0.0f), std::numeric_limits<float>::infinity());
    constexpr float kFar = std::numeric_limits<float>::infinity();
    constexpr float kBlocked = -std::numeric_limits<float>::infinity();  // Embree's mark
    std::size_t escaped = 0;
    switch (query) {
        case OcclusionQuery::single:
            for (const glm::vec3& direction : directions) {
                RTCRay ray = embree::make_ray(origin, direction, near, kFar);
                rtcOccluded1(impl_->scene, &context, &ray);
                if (ray.tfar != kBlocked) ++escaped;
            }
            break;
        case OcclusionQuery::packet8:
            for (std::size_t first = 0; first < directions.size(); first += 8) {
                alignas(32) int valid[8];
                RTCRay8 packet{};
                for (std::size_t k = 0; k < 8; ++k) {
                    const bool used = first + k < directions.size();
                    valid[k] = used ? -1 : 0;
                    const glm::vec3 d = used ? directions[first + k] : glm::vec3(0, 0, 1);
                    packet.org_x[k] = origin.x;
                    packet.org_y[k] = origin.y;
                    packet.org_z[k] = origin.z;
                    packet.dir_x[k] = d.x;
                    packet.dir_y[k] = d.y;
                    packet.dir_z[k] = d.z;
                    packet.tnear[k] = near;
                    packet.tfar[k] = kFar;
                    packet.mask[k] = ~0u;
                }
                rtcOccluded8(valid, impl_->scene, &context, &packet);
                for (std::size_t k = 0; k < 8 && first + k < directions.size(); ++k)
                    if (packet.tfar[k] != kBlocked) ++escaped;
            }
            break;
        case OcclusionQuery::stream: {
            // Reused per thread: the bake calls this once per vertex.
            thread_local std::vector<RTCRay> rays;
            rays.resize(directions.size());
            for (std::size_t i = 0; i < directions.size(); ++i)
                rays[i] = embree::make_ray(origin, directions[i], near, kFar);
            rtcOccluded1M(impl_->scene, &context, rays.data(),
                          static_cast<unsigned>(rays.size()), sizeof(RTCRay));
            for (const RTCRay& ray : rays)
                if (ray.tfar != kBlocked) ++escaped;
            break;
        }
    }
    return escaped;
}

}  // namespace lucent

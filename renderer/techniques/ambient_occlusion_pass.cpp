#include "renderer/techniques/ambient_occlusion_pass.h"

#include <utility>

#include "renderer/core/ambient_occlusion.h"

namespace lucent {

std::string ambient_occlusion_hash(const Mesh& mesh, int rays) {
    const std::string hash = mesh.content_hash.empty()
                                 ? compute_content_hash(mesh.positions, mesh.triangles)
                                 : mesh.content_hash;
    return "ao-" + hash + "-r" + std::to_string(rays) + "-a" +
           std::to_string(kAoAlgorithmVersion);
}

void add_ambient_occlusion(PlanBuilder& plan, const Scene& scene, int rays,
                           std::string purpose) {
    const int vertices = static_cast<int>(scene.mesh->vertex_count());
    plan.create(vertex_stream(kAmbientOcclusionStream, ResourceFormat::r32f, vertices,
                              kAmbientOcclusionAttribute));
    Pass ao{"ambient_occlusion", std::move(purpose), PassKind::upload};
    ao.writes = {kAmbientOcclusionStream};
    ao.data.content_hash = ambient_occlusion_hash(*scene.mesh, rays);
    ao.data.cost = ProductionCost::bake;
    ao.data.produce = [mesh = scene.mesh, rays](const ProduceOptions& produce) {
        AoBakeOptions options;
        options.rays = rays;
        options.progress = produce.progress;
        std::vector<float> values = produce.use_caches
                                        ? load_or_bake_ambient_occlusion(*mesh, options)
                                        : bake_ambient_occlusion(*mesh, options);
        const int count = static_cast<int>(values.size());
        return TextureData{{count, 1, 1}, {std::move(values)}};
    };
    ao.data.stand_in = [vertices] {
        return TextureData{
            {vertices, 1, 1},
            {std::vector<float>(static_cast<std::size_t>(vertices), 1.0f)}};
    };
    plan.add(std::move(ao));
}

}  // namespace lucent

// lucent bench truth: what the path technique's accuracy costs. For a small and a larger
// image of one scene: a converged reference (many paths, another seed), then the error
// (linear RMSE on object pixels) and time at 1, 4, 16, ... paths, beside the standard
// error the estimate reports of itself (they should agree: the estimate is honest); then
// the walk's rates (scattering events and boundary rays per CPU-second) against
// Embree's own closest-hit rate on random rays through the same mesh on this machine,
// measured in the same run.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <memory>
#include <random>

#include "app/bench_results.h"
#include "app/commands.h"
#include "common/cpu_time.h"
#include "renderer/cpu/ray_caster.h"
#include "renderer/render.h"
#include "renderer/techniques/path/path.h"

namespace lucent::app {
namespace {

struct TruthOptions {
    std::string mesh = "torus_knot:30k";
    std::string material = "marble";
    double model_size = 30.0;
    std::vector<int> sizes{32, 96};
    std::vector<int> paths{1, 4, 16, 64, 256};
    int reference_paths = 1024;
    std::string csv;
};

struct Comparison {
    double rmse = 0.0, reported = 0.0;  // reported: RMS of the estimate's own errors
};

// RMSE of `image` against `reference` over the reference's object pixels, and the RMS of
// the standard errors both estimates report there (the expected RMSE if they are honest).
Comparison compare(const EstimatedImage& image, const EstimatedImage& reference) {
    double squares = 0.0, reported = 0.0;
    std::size_t n = 0;
    for (std::size_t p = 0; p < reference.mean.rgba.size() / 4; ++p) {
        if (reference.mean.rgba[p * 4 + 3] < 0.5f) continue;
        for (int c = 0; c < 3; ++c) {
            const double d =
                double(image.mean.rgba[p * 4 + c]) - reference.mean.rgba[p * 4 + c];
            squares += d * d;
            reported += std::pow(double(image.standard_error.rgba[p * 4 + c]), 2) +
                        std::pow(double(reference.standard_error.rgba[p * 4 + c]), 2);
            ++n;
        }
    }
    return n ? Comparison{std::sqrt(squares / double(n)), std::sqrt(reported / double(n))}
             : Comparison{};
}

// Embree's closest-hit rays per CPU-second on this thread: random rays from points in
// the mesh's bounding sphere in random directions (the walk's kind of query).
double embree_rate(const Mesh& mesh, int rays) {
    const RayCaster caster(mesh);
    const BoundingSphere sphere = mesh.bounding_sphere();
    std::mt19937 engine(7);
    std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
    std::vector<std::pair<glm::vec3, glm::vec3>> queries;
    while (int(queries.size()) < rays) {
        const glm::vec3 p(unit(engine), unit(engine), unit(engine)),
            d(unit(engine), unit(engine), unit(engine));
        if (glm::dot(p, p) > 1.0f || glm::dot(d, d) > 1.0f || glm::dot(d, d) < 1e-4f)
            continue;
        queries.push_back({sphere.centre + sphere.radius * p, glm::normalize(d)});
    }
    std::size_t hits = 0;
    const double start = common::thread_cpu_seconds();
    for (const auto& [origin, direction] : queries)
        hits += caster.first_hit(origin, direction, 1e-6f, 1e30f).has_value();
    const double seconds = common::thread_cpu_seconds() - start;
    return hits > 0 && seconds > 0 ? double(rays) / seconds : 0.0;
}

int run_bench_truth(const TruthOptions& options) {
    BenchResults results;
    std::printf(
        "bench truth: path on %s, %s at %g mm; reference %d paths per pixel and "
        "channel (seed 1000)\n",
        options.mesh.c_str(), options.material.c_str(), options.model_size,
        options.reference_paths);
    path::TraceStatistics reference_statistics;
    Mesh mesh;
    for (const int size : options.sizes) {
        RenderRequest request;
        request.mesh = options.mesh;
        request.technique = "path";
        request.width = request.height = size;
        request.settings = {{"material", options.material},
                            {"model_size", std::to_string(options.model_size)},
                            {"light_radius", "10"},
                            {"paths", std::to_string(options.reference_paths)},
                            {"seed", "1000"}};
        Scene scene;
        try {
            scene = build_scene(request);
        } catch (const std::exception& e) {
            std::cerr << "lucent bench truth: " << e.what() << "\n";
            return kExitUsage;
        }
        mesh = *scene.mesh;
        std::fprintf(stderr, "%dx%d: the reference (%d paths)...\n", size, size,
                     options.reference_paths);
        const EstimatedImage reference =
            path::render_path(scene, {}, &reference_statistics);
        std::printf("\n%dx%d: reference in %.1f s (%.1f CPU s)\n", size, size,
                    reference_statistics.wall_seconds, reference_statistics.cpu_seconds);
        std::printf("  %8s %10s %10s %12s %12s %8s\n", "paths", "wall s", "CPU s", "RMSE",
                    "reported SE", "ratio");
        const std::string section = std::to_string(size) + "x" + std::to_string(size);
        for (const int paths : options.paths) {
            if (paths >= options.reference_paths) break;
            request.settings[3] = {"paths", std::to_string(paths)};
            request.settings[4] = {"seed", "0"};
            const Scene sweep = build_scene(request);
            path::TraceStatistics statistics;
            const EstimatedImage image = path::render_path(sweep, {}, &statistics);
            const Comparison c = compare(image, reference);
            // One path has no standard error of its own (a variance needs two samples).
            if (paths > 1)
                std::printf("  %8d %10.3f %10.3f %12.5f %12.5f %8.2f\n", paths,
                            statistics.wall_seconds, statistics.cpu_seconds, c.rmse,
                            c.reported, c.reported > 0 ? c.rmse / c.reported : 0.0);
            else
                std::printf("  %8d %10.3f %10.3f %12.5f %12s %8s\n", paths,
                            statistics.wall_seconds, statistics.cpu_seconds, c.rmse, "-",
                            "-");
            const std::string name = "paths=" + std::to_string(paths);
            results.add(section, name + " RMSE", c.rmse, "linear");
            results.add(section, name + " reported standard error", c.reported, "linear");
            results.add(section, name + " wall time", statistics.wall_seconds, "s");
            results.add(section, name + " CPU time", statistics.cpu_seconds, "s");
        }
    }
    const path::WalkCounters& n = reference_statistics.counters;
    const double cpu = reference_statistics.cpu_seconds;
    const double events_rate = cpu > 0 ? double(n.scattering_events) / cpu : 0.0;
    const double rays_rate = cpu > 0 ? double(n.boundary_queries) / cpu : 0.0;
    std::fprintf(stderr, "Embree's own rate...\n");
    const double embree = embree_rate(mesh, 2'000'000);
    std::printf(
        "\nrates (the last reference): %.3g scattering events and %.3g boundary rays "
        "per CPU-second; Embree closest hits on random rays through the mesh: %.3g "
        "per CPU-second; the walk's rays at %.2f of Embree's rate\n",
        events_rate, rays_rate, embree, embree > 0 ? rays_rate / embree : 0.0);
    results.add("rates", "scattering events", events_rate, "per CPU-second");
    results.add("rates", "boundary rays", rays_rate, "per CPU-second");
    results.add("rates", "Embree closest hits", embree, "per CPU-second");
    results.add("rates", "boundary rays / Embree", embree > 0 ? rays_rate / embree : 0.0,
                "ratio");
    std::printf(
        "ratio: RMSE over the RMS of both estimates' own standard errors (about 1 "
        "when the reported errors are honest)\n");
    if (!options.csv.empty() && !results.write_csv(options.csv)) {
        std::cerr << "lucent bench truth: --csv: cannot write " << options.csv << "\n";
        return kExitFailure;
    }
    return kExitOk;
}

}  // namespace

void register_bench_truth(CLI::App& bench, int& exit_code) {
    auto options = std::make_shared<TruthOptions>();
    auto* cmd = bench.add_subcommand(
        "truth",
        "The path technique's cost: error against paths and time for a small and a "
        "larger image, and its rates against Embree's on this machine");
    cmd->add_option("--mesh", options->mesh, "mesh")->capture_default_str();
    cmd->add_option("--material", options->material, "Jensen et al. 2001 material")
        ->capture_default_str();
    cmd->add_option("--model-size", options->model_size, "the mesh's diagonal in mm")
        ->capture_default_str();
    cmd->add_option("--sizes", options->sizes, "image sides")->delimiter(',');
    cmd->add_option("--paths", options->paths, "paths per pixel and channel to sweep")
        ->delimiter(',');
    cmd->add_option("--reference-paths", options->reference_paths,
                    "paths of the converged reference")
        ->capture_default_str();
    cmd->add_option("--csv", options->csv, "also write every number to FILE");
    cmd->callback([options, &exit_code] { exit_code = run_bench_truth(*options); });
}

}  // namespace lucent::app

// lucent bench ao: how long the per-vertex AO bake takes (thesis: 320 rays per vertex),
// as wall time and rays per second, for several meshes measured in one run; the last
// column is each row's bake time over the first row's.
#include <embree3/rtcore_config.h>

#include <chrono>
#include <ctime>
#include <cstdio>
#include <iostream>
#include <memory>
#include <thread>

#include "commands.h"
#include "core/ambient_occlusion.h"
#include "core/progress.h"
#include "cpu/ray_caster.h"

namespace lucent::app {
namespace {

struct BenchAoOptions {
    std::vector<std::string> meshes{"torus_knot:30k", "torus_knot:240k"};
    int rays = 320;
    unsigned threads = 0;
    bool progress = false;
};

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
        .count();
}

int run_bench_ao(const BenchAoOptions& options) {
    std::vector<Mesh> meshes;
    for (const std::string& spec : options.meshes) {
        try {
            meshes.push_back(load_mesh(spec));
        } catch (const MeshError& e) {
            std::cerr << "lucent bench ao: " << e.what() << "\n";
            return kExitUsage;
        }
    }
    const unsigned threads = options.threads != 0
                                 ? options.threads
                                 : std::max(1u, std::thread::hardware_concurrency());
    std::printf(
        "AO bake: %d rays per vertex (uniform, stratified hemisphere), %u threads, "
        "Embree %s\nbake s: wall time, BVH build included; CPU s: summed over threads, so "
        "Mrays/CPUs is the per-core rate (less affected by other load)\n",
        options.rays, threads, RTC_VERSION_STRING);
    std::printf("%-22s %9s %9s %11s %9s %9s %9s %11s %7s\n", "mesh", "faces", "vertices",
                "BVH build s", "bake s", "CPU s", "Mrays/s", "Mrays/CPUs", "ratio");
    double first_bake = 0.0;
    for (const Mesh& mesh : meshes) {
        const auto build_start = std::chrono::steady_clock::now();
        { const RayCaster caster(mesh); }
        const double build = seconds_since(build_start);

        AoBakeOptions bake;
        bake.rays = options.rays;
        bake.threads = threads;
        std::unique_ptr<ProgressBar> bar;
        if (options.progress) {
            bar =
                std::make_unique<ProgressBar>("AO bake " + mesh.name, mesh.vertex_count(),
                                              ProgressBarOptions{0.0, true});
            bake.progress = bar->callback();
        }
        const auto bake_start = std::chrono::steady_clock::now();
        const std::clock_t cpu_start = std::clock();  // process CPU time, all threads
        const std::vector<float> ao = bake_ambient_occlusion(mesh, bake);
        const double cpu = double(std::clock() - cpu_start) / CLOCKS_PER_SEC;
        const double seconds = seconds_since(bake_start);
        if (bar) bar->finish();
        if (first_bake == 0.0) first_bake = seconds;
        const double rays = double(mesh.vertex_count()) * options.rays;
        std::printf("%-22s %9zu %9zu %11.3f %9.3f %9.3f %9.2f %11.2f %7.2f\n",
                    mesh.name.c_str(), mesh.face_count(), mesh.vertex_count(), build, seconds,
                    cpu, rays / seconds / 1e6, rays / cpu / 1e6, seconds / first_bake);
        std::fflush(stdout);
    }
    return kExitOk;
}

}  // namespace

void register_bench_ao(CLI::App& bench, int& exit_code) {
    auto options = std::make_shared<BenchAoOptions>();
    auto* ao = bench.add_subcommand(
        "ao", "Time the per-vertex ambient-occlusion bake: seconds and rays per second");
    ao->add_option("--mesh", options->meshes,
                   "Meshes to bake, built-in (torus_knot:240k) or files; repeatable")
        ->capture_default_str();
    ao->add_option("--rays", options->rays, "Rays per vertex (ao_rays)")
        ->check(CLI::Range(1, 1 << 20))
        ->capture_default_str();
    ao->add_option("--threads", options->threads,
                   "Worker threads; 0 = all hardware threads")
        ->capture_default_str();
    ao->add_flag("--progress", options->progress, "Draw a progress bar on stderr");
    ao->callback([options, &exit_code] { exit_code = run_bench_ao(*options); });
}

}  // namespace lucent::app

// lucent bench ao: how long the per-vertex AO bake takes (thesis: 320 rays per vertex),
// as wall time and rays per CPU-second, for several meshes measured in one run, with
// where the time went: ray set-up against Embree's occlusion queries on the same rays
// (Embree's rate is the bake's ceiling). A second table times each Embree query type on
// the same rays of every Nth vertex, on one thread.
#include <embree3/rtcore_config.h>
#include <time.h>

#include <chrono>
#include <cstdio>
#include <ctime>
#include <iostream>
#include <memory>
#include <thread>

#include "app/bench_results.h"
#include "app/commands.h"
#include "common/cpu_time.h"
#include "renderer/core/ambient_occlusion.h"
#include "renderer/core/progress.h"
#include "renderer/cpu/ambient_occlusion_directions.h"
#include "renderer/cpu/occlusion_counter.h"

namespace lucent::app {
namespace {

struct BenchAoOptions {
    std::vector<std::string> meshes{"torus_knot:30k", "torus_knot:240k"};
    int rays = 320;
    unsigned threads = 0;
    unsigned sample = 8;
    bool progress = false;
    std::string csv;
};

double seconds_since(std::chrono::steady_clock::time_point start) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - start)
        .count();
}

using common::thread_cpu_seconds;

// Rays per CPU-second of each query type on the bake's own rays for every `sample`th
// vertex, on this thread, in both scene layouts; the escape counts must agree (same rays,
// same answers).
void time_query_types(const Mesh& mesh, int rays, unsigned sample,
                      BenchResults& results) {
    const AoDirections lattice(rays);
    const float offset = 1e-4f * std::max(mesh.bounding_sphere().radius, 1e-6f);
    struct Query {
        std::string name;
        OcclusionScene layout;
        OcclusionQuery query;
        double seconds = 0.0;
        std::size_t escaped = 0;
    };
    std::vector<Query> queries;
    for (const auto& [layout, layout_name] :
         {std::pair{OcclusionScene::triangles, "triangles"},
          std::pair{OcclusionScene::paired_quads, "quads"}})
        for (const auto& [query, query_name] :
             {std::pair{OcclusionQuery::single, "rtcOccluded1"},
              std::pair{OcclusionQuery::packet8, "rtcOccluded8"},
              std::pair{OcclusionQuery::stream, "rtcOccluded1M"}})
            queries.push_back(
                {std::string(query_name) + " " + layout_name, layout, query});
    const OcclusionCounter triangles(mesh, OcclusionScene::triangles);
    const OcclusionCounter quads(mesh, OcclusionScene::paired_quads);
    double setup = 0.0, traced = 0.0;
    std::vector<glm::vec3> directions;
    for (std::size_t v = 0; v < mesh.vertex_count(); v += sample) {
        const double t0 = thread_cpu_seconds();
        lattice.generate(v, mesh.normals[v], directions);
        const glm::vec3 origin = mesh.positions[v] + offset * mesh.normals[v];
        setup += thread_cpu_seconds() - t0;
        for (Query& q : queries) {
            const OcclusionCounter& counter =
                q.layout == OcclusionScene::triangles ? triangles : quads;
            const double start = thread_cpu_seconds();
            q.escaped += counter.count_escaping(origin, directions, 0.0f, q.query);
            q.seconds += thread_cpu_seconds() - start;
        }
        traced += rays;
    }
    const std::string section = "query " + mesh.name;
    std::printf("  %-24s %11.2f %9s  (ray directions + origins)\n", "set-up",
                traced / setup / 1e6, "");
    results.add(section, "set-up rate", traced / setup / 1e6, "Mrays/CPUs");
    for (const Query& q : queries) {
        const double rate = traced / q.seconds / 1e6;
        std::printf(
            "  %-24s %11.2f %9.2f  escaped %.5f%s\n", q.name.c_str(), rate,
            queries[0].seconds / q.seconds, double(q.escaped) / traced,
            q.escaped == queries[0].escaped ? "" : "  (differs from the first row)");
        results.add(section, q.name + " rate", rate, "Mrays/CPUs");
        results.add(section, q.name + " speed-up over the first row",
                    queries[0].seconds / q.seconds, "ratio");
        results.add(section, q.name + " escaped fraction", double(q.escaped) / traced,
                    "fraction");
    }
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
    BenchResults results;
    std::printf(
        "AO bake: %d rays per vertex (uniform, stratified hemisphere), %u threads, "
        "Embree %s\nbake s: wall time, BVH build included; CPU s: process CPU time, so "
        "Mrays/CPUs is the per-core rate (less affected by other load)\nEmbree: thread "
        "CPU "
        "time inside the occlusion queries only, on the same rays: the ceiling; set-up: "
        "directions and origins\n",
        options.rays, threads, RTC_VERSION_STRING);
    std::printf("%-18s %7s %8s %7s %8s %8s %8s %10s %8s %10s %8s %7s\n", "mesh", "faces",
                "vertices", "BVH s", "bake s", "CPU s", "Mrays/s", "Mrays/CPUs",
                "set-up s", "Embree s", "Embree", "bake/");
    std::printf("%-18s %7s %8s %7s %8s %8s %8s %10s %8s %10s %8s %7s\n", "", "", "", "",
                "", "", "", "", "CPU", "CPU", "Mrays/CPUs", "Embree");
    for (const Mesh& mesh : meshes) {
        const auto build_start = std::chrono::steady_clock::now();
        { const OcclusionCounter counter(mesh); }
        const double build = seconds_since(build_start);

        AoBakeOptions bake;
        bake.rays = options.rays;
        bake.threads = threads;
        AoBakeTimings timings;
        bake.timings = &timings;
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
        const double rays = double(mesh.vertex_count()) * options.rays;
        const double rate = rays / cpu / 1e6;
        const double ceiling = timings.rays / timings.trace_cpu_seconds / 1e6;
        std::printf(
            "%-18s %7zu %8zu %7.3f %8.3f %8.3f %8.2f %10.2f %8.3f %10.3f %8.2f %7.2f\n",
            mesh.name.c_str(), mesh.face_count(), mesh.vertex_count(), build, seconds,
            cpu, rays / seconds / 1e6, rate, timings.setup_cpu_seconds,
            timings.trace_cpu_seconds, ceiling, rate / ceiling);
        std::fflush(stdout);
        const std::string& m = mesh.name;
        results.add("bake " + m, "faces", double(mesh.face_count()), "count");
        results.add("bake " + m, "rays per vertex", options.rays, "count");
        results.add("bake " + m, "threads", threads, "count");
        results.add("bake " + m, "BVH build", build, "s");
        results.add("bake " + m, "bake wall", seconds, "s");
        results.add("bake " + m, "bake CPU", cpu, "s");
        results.add("bake " + m, "bake rate", rate, "Mrays/CPUs");
        results.add("bake " + m, "set-up CPU", timings.setup_cpu_seconds, "s");
        results.add("bake " + m, "Embree CPU", timings.trace_cpu_seconds, "s");
        results.add("bake " + m, "Embree rate (ceiling)", ceiling, "Mrays/CPUs");
        results.add("bake " + m, "bake / ceiling", rate / ceiling, "ratio");
    }
    std::printf(
        "\nEmbree query types and scene layouts (the mesh's triangles; paired into "
        "quads, "
        "the bake's) on the bake's rays of every %u%s vertex, one thread (thread CPU "
        "time)\n  %-24s %11s %9s\n",
        options.sample, options.sample == 1 ? "st" : "th", "query", "Mrays/CPUs",
        "vs first");
    for (const Mesh& mesh : meshes) {
        std::printf(" %s\n", mesh.name.c_str());
        time_query_types(mesh, options.rays, options.sample, results);
    }
    if (!options.csv.empty() && !results.write_csv(options.csv)) {
        std::cerr << "lucent bench ao: --csv: cannot write '" << options.csv << "'\n";
        return kExitFailure;
    }
    return kExitOk;
}

}  // namespace

void register_bench_ao(CLI::App& bench, int& exit_code) {
    auto options = std::make_shared<BenchAoOptions>();
    auto* ao = bench.add_subcommand(
        "ao",
        "Time the per-vertex ambient-occlusion bake: rays per CPU-second, against "
        "Embree's own rate on the same rays, and each Embree query type");
    ao->add_option("--mesh", options->meshes,
                   "Meshes to bake, built-in (torus_knot:240k) or files; repeatable")
        ->capture_default_str();
    ao->add_option("--rays", options->rays, "Rays per vertex (ao_rays)")
        ->check(CLI::Range(1, 1 << 20))
        ->capture_default_str();
    ao->add_option("--threads", options->threads,
                   "Worker threads; 0 = all hardware threads")
        ->check(CLI::Range(0, 1024))
        ->capture_default_str();
    ao->add_option("--sample", options->sample, "Query-type table: time every Nth vertex")
        ->check(CLI::Range(1, 1 << 20))
        ->capture_default_str();
    ao->add_flag("--progress", options->progress, "Draw a progress bar on stderr");
    ao->add_option(
        "--csv", options->csv,
        "Also write every number as CSV (section,name,value,unit) to this file");
    ao->callback([options, &exit_code] { exit_code = run_bench_ao(*options); });
}

}  // namespace lucent::app

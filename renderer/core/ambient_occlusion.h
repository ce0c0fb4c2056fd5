#pragma once
// Per-vertex ambient occlusion (thesis Sec. 3, Eq. 3.5): the fraction of `rays` rays over
// the hemisphere around each vertex normal that escape the mesh. Baked on the CPU with
// Embree (cpu/ambient_occlusion_bake.cpp), deterministic (fixed seed, stratified
// directions), multithreaded, and cached on disk keyed by mesh hash + rays + algorithm
// version (core/ambient_occlusion_cache.cpp).
//
// Directions are uniform over solid angle, not cosine-weighted: the thesis averages the
// visibility of directions with equal weight, so AO is the escaping solid-angle fraction.
#include <filesystem>
#include <functional>
#include <vector>

#include "renderer/core/mesh.h"

namespace lucent {

// Bumped whenever the bake's results change, so stale cache files are never used.
// 2: each vertex's rays traced as one Embree stream; the phi shift applied by rotating
// the tangent frame (the same directions up to float rounding).
// 3: triangles paired into quads for Embree (OcclusionCounter): the same surface, but
// Embree's quad test decides a few edge-grazing rays otherwise (3 of 120,000 vertices of
// torus_knot:240k moved by one ray of 320).
inline constexpr int kAoAlgorithmVersion = 3;

// Where a bake's time went, summed over its threads (thread CPU time); filled when
// AoBakeOptions::timings is set (costs two clock reads per vertex).
struct AoBakeTimings {
    double setup_cpu_seconds = 0.0;  // ray directions and origins
    double trace_cpu_seconds = 0.0;  // Embree occlusion queries (the ceiling's rate)
    double rays = 0.0;               // rays traced
};

struct AoBakeOptions {
    int rays = 320;  // rays per vertex, >= 1
    // Worker threads including the caller; 0 = one per hardware thread. Results do not
    // depend on it.
    unsigned threads = 0;
    // Called now and then with (vertices done, total) from the calling thread; may be
    // empty.
    std::function<void(std::size_t, std::size_t)> progress;
    // Accumulated into when non-null (benchmarks); results do not depend on it.
    AoBakeTimings* timings = nullptr;
};

// One value in [0, 1] per vertex (1 = fully open). Never reads or writes a cache.
// Throws std::invalid_argument for rays < 1.
std::vector<float> bake_ambient_occlusion(const Mesh& mesh, const AoBakeOptions& options);

// Cache directory: $LUCENT_CACHE_DIR, else $XDG_CACHE_HOME/lucent, else ~/.cache/lucent.
std::filesystem::path cache_directory();

// Where the bake of (mesh, rays) is cached: cache_directory()/ao/HASH-rRAYS-aVERSION.ao
std::filesystem::path ambient_occlusion_cache_path(const Mesh& mesh, int rays);

// Reads the cached bake for (mesh hash, rays, algorithm version) if present and intact;
// otherwise bakes and writes it (atomically: temporary file + rename). A truncated or
// corrupt cache file is detected (size + checksum) and rebuilt, never trusted. A cache
// that cannot be written costs a warning on stderr, not the result. Without a progress
// callback, a bake running over half a second draws a ProgressBar on a terminal.
std::vector<float> load_or_bake_ambient_occlusion(const Mesh& mesh,
                                                  const AoBakeOptions& options);

}  // namespace lucent

#pragma once
// Per-vertex ambient occlusion (thesis Sec. 3): the fraction of `rays` rays over the
// hemisphere around each vertex normal that escape the mesh. Baked on the CPU with
// Embree, deterministic (fixed seed, stratified directions), multithreaded, and cached
// on disk keyed by mesh hash + rays + algorithm version.
#include <filesystem>
#include <functional>
#include <vector>

#include "core/mesh.h"

namespace lucent {

struct AoBakeOptions {
    int rays = 320;  // rays per vertex, >= 1
    // Called now and then with (vertices done, total) from the calling thread; may be empty.
    std::function<void(std::size_t, std::size_t)> progress;
};

// One value in [0, 1] per vertex (1 = fully open). Never reads or writes a cache.
std::vector<float> bake_ambient_occlusion(const Mesh& mesh, const AoBakeOptions& options);

// Cache directory: $LUCENT_CACHE_DIR, else $XDG_CACHE_HOME/lucent, else ~/.cache/lucent.
std::filesystem::path cache_directory();

// Reads the cached bake for (mesh hash, rays, algorithm version) if present and intact;
// otherwise bakes and writes it (atomically: temporary file + rename). A truncated or
// corrupt cache file is detected (size + checksum) and rebuilt, never trusted.
std::vector<float> load_or_bake_ambient_occlusion(const Mesh& mesh,
                                                  const AoBakeOptions& options);

}  // namespace lucent

// The AO disk cache. One file per (mesh hash, rays, algorithm version):
//   "LUCENTAO" | u32 file format | u32 algorithm version | u32 rays | u32 normals hash
//   | u64 count | 16 chars mesh hash | u64 FNV-1a of the values | count x f32
// The mesh hash covers positions and triangles only; the normals (which orient the
// hemispheres) are checked through their own hash, so a mesh with the same geometry
// but other normals rebakes instead of reusing the file.
// A file is trusted only if every header field matches, its size is exact, the
// checksum matches and every value is in [0, 1]; otherwise the bake is redone.

#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <optional>
#include <string>

#include "common/content_hash.h"
#include "common/output_file.h"
#include "renderer/core/ambient_occlusion.h"
#include "renderer/core/progress.h"

namespace lucent {

namespace {

constexpr char kMagic[8] = {'L', 'U', 'C', 'E', 'N', 'T', 'A', 'O'};
constexpr std::uint32_t kFileFormat = 1;

#pragma pack(push, 1)
struct CacheHeader {
    char magic[8];
    std::uint32_t file_format;
    std::uint32_t algorithm_version;
    std::uint32_t rays;
    std::uint32_t normals_hash;
    std::uint64_t count;
    char mesh_hash[16];
    std::uint64_t checksum;
};
#pragma pack(pop)
static_assert(sizeof(CacheHeader) == 56);

template <typename T>
std::uint64_t checksum(const std::vector<T>& values) {  // FNV-1a over the bytes
    return common::ContentHash().bytes(values.data(), values.size() * sizeof(T)).result();
}

CacheHeader header_for(const Mesh& mesh, int rays, const std::vector<float>& values) {
    CacheHeader header{};
    std::memcpy(header.magic, kMagic, sizeof kMagic);
    header.file_format = kFileFormat;
    header.algorithm_version = kAoAlgorithmVersion;
    header.rays = static_cast<std::uint32_t>(rays);
    const std::uint64_t normals = checksum(mesh.normals);
    header.normals_hash = static_cast<std::uint32_t>(normals ^ (normals >> 32));
    header.count = mesh.vertex_count();
    std::memset(header.mesh_hash, '0', sizeof header.mesh_hash);
    std::memcpy(header.mesh_hash, mesh.content_hash.data(),
                std::min(mesh.content_hash.size(), sizeof header.mesh_hash));
    header.checksum = checksum(values);
    return header;
}

std::optional<std::vector<float>> read_cache(const std::filesystem::path& path,
                                             const Mesh& mesh, int rays) {
    std::ifstream file(path, std::ios::binary);
    if (!file) return std::nullopt;
    CacheHeader stored{};
    if (!file.read(reinterpret_cast<char*>(&stored), sizeof stored)) return std::nullopt;
    std::error_code error;
    const auto size = std::filesystem::file_size(path, error);
    if (error || stored.count != mesh.vertex_count() ||
        size != sizeof(CacheHeader) + stored.count * sizeof(float))
        return std::nullopt;
    std::vector<float> values(stored.count);
    if (!file.read(reinterpret_cast<char*>(values.data()),
                   static_cast<std::streamsize>(values.size() * sizeof(float))))
        return std::nullopt;
    const CacheHeader expected = header_for(mesh, rays, values);
    if (std::memcmp(&stored, &expected, sizeof stored) != 0) return std::nullopt;
    for (float v : values)
        if (!(v >= 0.0f && v <= 1.0f)) return std::nullopt;
    return values;
}

// Written atomically (common/output_file.h: a unique temporary sibling, renamed over the
// target): readers see the old file or the complete new one, never a partial one.
bool write_cache(const std::filesystem::path& path, const Mesh& mesh, int rays,
                 const std::vector<float>& values, std::string& reason) {
    std::error_code error;
    std::filesystem::create_directories(path.parent_path(), error);
    if (error) {
        reason = error.message();
        return false;
    }
    try {
        common::write_file_atomically(path, true, [&](std::ostream& file) {
            const CacheHeader header = header_for(mesh, rays, values);
            file.write(reinterpret_cast<const char*>(&header), sizeof header);
            file.write(reinterpret_cast<const char*>(values.data()),
                       static_cast<std::streamsize>(values.size() * sizeof(float)));
        });
    } catch (const common::OutputError& e) {
        reason = e.what();
        return false;
    }
    return true;
}

}  // namespace

std::filesystem::path cache_directory() {
    if (const char* dir = std::getenv("LUCENT_CACHE_DIR"); dir && *dir) return dir;
    if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg && *xdg)
        return std::filesystem::path(xdg) / "lucent";
    if (const char* home = std::getenv("HOME"); home && *home)
        return std::filesystem::path(home) / ".cache" / "lucent";
    return std::filesystem::temp_directory_path() / "lucent-cache";
}

std::filesystem::path ambient_occlusion_cache_path(const Mesh& mesh, int rays) {
    const std::string hash = mesh.content_hash.empty()
                                 ? compute_content_hash(mesh.positions, mesh.triangles)
                                 : mesh.content_hash;
    return cache_directory() / "ao" /
           (hash + "-r" + std::to_string(rays) + "-a" +
            std::to_string(kAoAlgorithmVersion) + ".ao");
}

std::vector<float> load_or_bake_ambient_occlusion(const Mesh& mesh,
                                                  const AoBakeOptions& options) {
    Mesh keyed;  // the cache key needs the hash; compute it if the caller left it empty
    const Mesh* source = &mesh;
    if (mesh.content_hash.empty()) {
        keyed = mesh;
        keyed.content_hash = compute_content_hash(mesh.positions, mesh.triangles);
        source = &keyed;
    }
    const std::filesystem::path path =
        ambient_occlusion_cache_path(*source, options.rays);
    if (std::optional<std::vector<float>> cached =
            read_cache(path, *source, options.rays))
        return *cached;
    // Long bakes show progress: without a caller's callback, a bar on stderr (terminal
    // only, after half a second).
    std::vector<float> values;
    if (options.progress) {
        values = bake_ambient_occlusion(*source, options);
    } else {
        ProgressBar bar("AO bake " + mesh.name, mesh.vertex_count());
        AoBakeOptions with_bar = options;
        with_bar.progress = bar.callback();
        values = bake_ambient_occlusion(*source, with_bar);
    }
    if (std::string reason; !write_cache(path, *source, options.rays, values, reason))
        std::fprintf(stderr, "lucent: warning: AO cache %s not written: %s\n",
                     path.string().c_str(), reason.c_str());
    return values;
}

}  // namespace lucent

// AO bake against analytic escape fractions: a convex sphere sees its whole hemisphere
// (AO exactly 1), a vertex inside a closed box none of it (exactly 0), and the centre
// of an open box's floor sees the opening's solid angle over 2 pi (uniform hemisphere).
// Plus determinism across thread counts and the cache's round trip and corruption.
#include "renderer/core/ambient_occlusion.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <numbers>
#include <thread>

#include "renderer/cpu/ambient_occlusion_directions.h"
#include "tests/support/test_paths.h"

namespace lucent {
namespace {

// Floor [-1,1]^2 at z = 0 split into four triangles around a centre vertex (index 0,
// normal +Z), four walls of height `height`, and a lid when `closed`. Normals outside
// the centre come from the mesh: only the centre's AO is examined.
Mesh box_with_floor_centre(float height, bool closed) {
    Mesh mesh;
    mesh.name = "test box";
    mesh.positions = {{0, 0, 0},       {-1, -1, 0},    {1, -1, 0},
                      {1, 1, 0},       {-1, 1, 0},     {-1, -1, height},
                      {1, -1, height}, {1, 1, height}, {-1, 1, height}};
    // Wound so the box's inside is the front (we look from the centre vertex).
    mesh.triangles = {{0, 2, 1}, {0, 3, 2}, {0, 4, 3}, {0, 1, 4}};
    for (unsigned i = 0; i < 4; ++i) {
        const unsigned a = 1 + i, b = 1 + (i + 1) % 4;
        mesh.triangles.push_back({a, b, b + 4});
        mesh.triangles.push_back({a, b + 4, a + 4});
    }
    if (closed) mesh.triangles.insert(mesh.triangles.end(), {{5, 6, 7}, {5, 7, 8}});
    mesh.normals = compute_smooth_normals(mesh.positions, mesh.triangles);
    mesh.normals[0] = {0, 0, 1};
    finalize_mesh(mesh);
    return mesh;
}

// Solid angle of a centred a x b rectangle at distance d, over the hemisphere's 2 pi.
double open_fraction(double a, double b, double d) {
    const double solid_angle =
        4.0 * std::asin(a * b / std::sqrt((a * a + 4 * d * d) * (b * b + 4 * d * d)));
    return solid_angle / (2.0 * std::numbers::pi);
}

// The directions are the rank-1 lattice whatever the per-vertex shift: unit, inside the
// hemisphere, one cos(theta) in each of the N strata ((k, k+1]/N), and azimuths (about
// the normal) that step by 2 pi / golden ratio from one ray to the next, as the closed
// form phi_i = 2 pi frac(i / golden ratio + shift) says.
TEST(AmbientOcclusion, DirectionsAreTheShiftedStratifiedLattice) {
    constexpr int kRays = 320;
    const AoDirections lattice(kRays);
    std::vector<glm::vec3> directions;
    const glm::vec3 normals[] = {glm::normalize(glm::vec3(0.3f, -0.5f, 0.8f)),
                                 {0.0f, 0.0f, -1.0f},  // the frame's sign flip
                                 glm::normalize(glm::vec3(1.0f, 1e-4f, -1e-4f))};
    for (std::size_t vertex : {0u, 1u, 12345u})
        for (const glm::vec3 n : normals) {
            lattice.generate(vertex, n, directions);
            ASSERT_EQ(directions.size(), std::size_t(kRays));
            // Any unit vector perpendicular to n measures the azimuth.
            const glm::vec3 helper =
                std::abs(n.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
            const glm::dvec3 e1 = glm::normalize(glm::cross(n, helper));
            const glm::dvec3 e2 = glm::cross(glm::dvec3(n), e1);
            std::vector<int> strata(kRays, 0);
            double first_phi = 0.0;
            for (int i = 0; i < kRays; ++i) {
                const glm::dvec3 d = directions[i];
                EXPECT_NEAR(glm::length(d), 1.0, 1e-6);
                const double cos_theta = glm::dot(d, glm::dvec3(n));
                ASSERT_GT(cos_theta, 0.0) << i;
                // Stratum of cos(theta); 1e-9 slack for a value on a boundary.
                ++strata[std::min(kRays - 1,
                                  int(std::ceil(cos_theta * kRays - 1e-9)) - 1)];
                const double phi = std::atan2(glm::dot(d, e2), glm::dot(d, e1));
                if (i == 0) first_phi = phi;
                double expected = 2.0 * std::numbers::pi * (i * 0.6180339887498949);
                double gap =
                    std::remainder(phi - first_phi - expected, 2.0 * std::numbers::pi);
                EXPECT_NEAR(gap, 0.0, 2e-5) << "vertex " << vertex << " ray " << i;
            }
            EXPECT_EQ(strata, std::vector<int>(kRays, 1)) << "vertex " << vertex;
        }
    // Different vertices get different shifts (not one pattern for all).
    std::vector<glm::vec3> other;
    lattice.generate(0, normals[0], directions);
    lattice.generate(1, normals[0], other);
    EXPECT_NE(directions, other);
    EXPECT_THROW(AoDirections(0), std::invalid_argument);
}

TEST(AmbientOcclusion, ConvexSphereIsFullyOpenAtEveryVertex) {
    const Mesh sphere = load_mesh("sphere:4000");
    const std::vector<float> ao = bake_ambient_occlusion(sphere, {});
    ASSERT_EQ(ao.size(), sphere.vertex_count());
    for (std::size_t i = 0; i < ao.size(); ++i) ASSERT_EQ(ao[i], 1.0f) << "vertex " << i;
}

TEST(AmbientOcclusion, MissingNormalsAreRebuiltFromTheFaces) {
    // Angle-weighted normals of a convex polyhedron lie in each vertex's normal cone,
    // so the sphere stays fully open with generated normals too.
    Mesh sphere = load_mesh("sphere:1000");
    sphere.normals.clear();
    const std::vector<float> ao = bake_ambient_occlusion(sphere, {});
    EXPECT_EQ(ao, std::vector<float>(sphere.vertex_count(), 1.0f));
}

TEST(AmbientOcclusion, VertexInsideAClosedBoxSeesNothing) {
    const std::vector<float> ao =
        bake_ambient_occlusion(box_with_floor_centre(1.0f, true), {});
    EXPECT_EQ(ao[0], 0.0f);
}

TEST(AmbientOcclusion, OpenBoxFloorCentreSeesTheOpeningsSolidAngle) {
    for (const float height : {0.5f, 1.0f, 2.0f}) {
        const Mesh box = box_with_floor_centre(height, false);
        const double expected = open_fraction(2.0, 2.0, height);  // 1/3 at height 1
        // Stratified sampling of a region with a sharp edge: error ~ N^-3/4.
        AoBakeOptions options;
        EXPECT_NEAR(bake_ambient_occlusion(box, options)[0], expected, 0.02) << height;
        options.rays = 4096;
        EXPECT_NEAR(bake_ambient_occlusion(box, options)[0], expected, 0.004) << height;
    }
    EXPECT_NEAR(open_fraction(2.0, 2.0, 1.0), 1.0 / 3.0, 1e-12);
}

TEST(AmbientOcclusion, HandIsOccludedBetweenItsFingersOnly) {
    const Mesh hand = load_mesh("hand:8000");
    AoBakeOptions options;
    options.rays = 64;
    const std::vector<float> ao = bake_ambient_occlusion(hand, options);
    float lowest = 1.0f;
    std::size_t open = 0;
    for (float value : ao) {
        ASSERT_GE(value, 0.0f);
        ASSERT_LE(value, 1.0f);
        lowest = std::min(lowest, value);
        if (value == 1.0f) ++open;
    }
    EXPECT_LT(lowest, 0.6f);          // crevices between fingers and palm
    EXPECT_GT(open, ao.size() / 10);  // convex parts
    // The highest vertex (the middle fingertip) has nothing above it.
    const auto top = std::max_element(hand.positions.begin(), hand.positions.end(),
                                      [](glm::vec3 a, glm::vec3 b) { return a.y < b.y; });
    EXPECT_EQ(ao[static_cast<std::size_t>(top - hand.positions.begin())], 1.0f);
}

TEST(AmbientOcclusion, ResultsAreIdenticalForEveryThreadCount) {
    const Mesh knot = load_mesh("torus_knot:4000");
    AoBakeOptions options;
    options.rays = 48;
    options.threads = 1;
    const std::vector<float> single = bake_ambient_occlusion(knot, options);
    for (const unsigned threads : {2u, 3u, 7u}) {
        options.threads = threads;
        EXPECT_EQ(bake_ambient_occlusion(knot, options), single) << threads << " threads";
    }
}

TEST(AmbientOcclusion, ProgressIsReportedFromTheCallingThreadAndEndsAtTotal) {
    const Mesh knot = load_mesh("torus_knot:4000");
    AoBakeOptions options;
    options.rays = 8;
    options.threads = 3;
    std::size_t last = 0, calls = 0;
    bool monotone = true, same_thread = true;
    const auto caller = std::this_thread::get_id();
    options.progress = [&](std::size_t done, std::size_t total) {
        EXPECT_EQ(total, knot.vertex_count());
        monotone = monotone && done >= last;
        same_thread = same_thread && std::this_thread::get_id() == caller;
        last = done;
        ++calls;
    };
    bake_ambient_occlusion(knot, options);
    EXPECT_GT(calls, 0u);
    EXPECT_TRUE(monotone);
    EXPECT_TRUE(same_thread);
    EXPECT_EQ(last, knot.vertex_count());
}

TEST(AmbientOcclusion, RejectsFewerThanOneRay) {
    AoBakeOptions options;
    options.rays = 0;
    EXPECT_THROW(bake_ambient_occlusion(load_mesh("sphere:400"), options),
                 std::invalid_argument);
}

// Points the cache at a fresh directory for one test.
class AoCacheTest : public ::testing::Test {
protected:
    void SetUp() override {
        dir_ = test::scratch_dir(
            std::string("ao_cache/") +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
        setenv("LUCENT_CACHE_DIR", dir_.c_str(), 1);
        options_.rays = 16;
        options_.progress = [this](std::size_t, std::size_t) { baked_ = true; };
    }
    // Runs load_or_bake and says whether it had to bake.
    std::vector<float> load(const Mesh& mesh, bool& baked) {
        baked_ = false;
        std::vector<float> values = load_or_bake_ambient_occlusion(mesh, options_);
        baked = baked_;
        return values;
    }

    std::filesystem::path dir_;
    AoBakeOptions options_;
    bool baked_ = false;
};

TEST_F(AoCacheTest, SecondLoadComesFromTheCacheFile) {
    const Mesh knot = load_mesh("torus_knot:4000");
    const std::vector<float> fresh = bake_ambient_occlusion(knot, {16});
    bool baked = false;
    EXPECT_EQ(load(knot, baked), fresh);
    EXPECT_TRUE(baked);
    const auto path = ambient_occlusion_cache_path(knot, 16);
    EXPECT_EQ(path.parent_path().parent_path(), dir_);
    ASSERT_TRUE(std::filesystem::exists(path));
    EXPECT_GT(std::filesystem::file_size(path), knot.vertex_count() * sizeof(float));
    EXPECT_EQ(load(knot, baked), fresh);
    EXPECT_FALSE(baked);
    // No temporary files are left behind.
    EXPECT_EQ(std::distance(std::filesystem::directory_iterator(path.parent_path()),
                            std::filesystem::directory_iterator()),
              1);
}

TEST_F(AoCacheTest, KeyIncludesRaysAlgorithmVersionAndMesh) {
    const Mesh knot = load_mesh("torus_knot:4000");
    const auto path = ambient_occlusion_cache_path(knot, 16).filename().string();
    EXPECT_NE(path, ambient_occlusion_cache_path(knot, 32).filename().string());
    EXPECT_NE(path, ambient_occlusion_cache_path(load_mesh("torus_knot:5000"), 16)
                        .filename()
                        .string());
    EXPECT_NE(path.find(knot.content_hash), std::string::npos);
    EXPECT_NE(path.find("-a" + std::to_string(kAoAlgorithmVersion)), std::string::npos);
}

TEST_F(AoCacheTest, CorruptOrTruncatedFilesAreRebuiltNotTrusted) {
    const Mesh knot = load_mesh("torus_knot:4000");
    const std::vector<float> fresh = bake_ambient_occlusion(knot, {16});
    const auto path = ambient_occlusion_cache_path(knot, 16);
    bool baked = false;
    load(knot, baked);
    const auto good_size = std::filesystem::file_size(path);

    auto damage_and_reload = [&](const char* what, auto damage) {
        damage();
        EXPECT_EQ(load(knot, baked), fresh) << what;
        EXPECT_TRUE(baked) << what << ": a damaged file must be rebuilt";
        EXPECT_EQ(std::filesystem::file_size(path), good_size) << what;
        EXPECT_EQ(load(knot, baked), fresh) << what;
        EXPECT_FALSE(baked) << what << ": the rebuilt file must be used";
    };
    damage_and_reload("flipped value byte", [&] {
        std::fstream file(path, std::ios::in | std::ios::out | std::ios::binary);
        file.seekp(static_cast<std::streamoff>(good_size - 5));
        file.put('\x7f');
    });
    damage_and_reload("truncated",
                      [&] { std::filesystem::resize_file(path, good_size / 2); });
    damage_and_reload("header only", [&] { std::filesystem::resize_file(path, 40); });
    damage_and_reload("empty", [&] { std::filesystem::resize_file(path, 0); });
    damage_and_reload("garbage", [&] {
        std::ofstream(path, std::ios::binary | std::ios::trunc)
            << std::string(good_size, 'x');
    });
    damage_and_reload("wrong rays in header", [&] {
        std::fstream file(path, std::ios::in | std::ios::out | std::ios::binary);
        file.seekp(16);  // after magic, file format and algorithm version
        file.put('\x20');
    });
}

TEST_F(AoCacheTest, SameGeometryWithOtherNormalsIsRebaked) {
    const Mesh box = box_with_floor_centre(1.0f, false);
    Mesh tilted = box;
    tilted.normals[0] = glm::normalize(glm::vec3(0.0f, 0.9f, 0.3f));  // towards a wall
    ASSERT_EQ(tilted.content_hash, box.content_hash);
    bool baked = false;
    const float open = load(box, baked)[0];
    const float leaning = load(tilted, baked)[0];
    EXPECT_TRUE(baked);
    EXPECT_LT(leaning, open - 0.05f);
    EXPECT_EQ(load(tilted, baked)[0], leaning);
    EXPECT_FALSE(baked);
}

TEST_F(AoCacheTest, UnwritableCacheStillReturnsTheBake) {
    const auto blocker = dir_ / "a-file";
    std::ofstream(blocker) << "not a directory";
    setenv("LUCENT_CACHE_DIR", (blocker / "cache").c_str(), 1);
    const Mesh sphere = load_mesh("sphere:400");
    bool baked = false;
    const std::vector<float> ao = load(sphere, baked);
    EXPECT_TRUE(baked);
    EXPECT_EQ(ao, std::vector<float>(sphere.vertex_count(), 1.0f));
}

}  // namespace
}  // namespace lucent

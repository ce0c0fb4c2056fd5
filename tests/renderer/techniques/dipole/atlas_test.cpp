// The surfel atlas, the mass pyramid and the inverse-CDF descent against independent
// sums and counts.
#include "renderer/techniques/dipole/atlas.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>

#include "renderer/core/mesh.h"
#include "tests/renderer/techniques/dipole/test_meshes.h"

namespace lucent::dipole {
namespace {

TEST(DipoleAtlas, MortonCodesRoundTrip) {
    EXPECT_EQ(morton2(0, 0), 0u);
    EXPECT_EQ(morton2(1, 0), 1u);
    EXPECT_EQ(morton2(0, 1), 2u);
    EXPECT_EQ(morton2(1, 1), 3u);
    EXPECT_EQ(morton2(2, 0), 4u);
    for (std::uint32_t x = 0; x < 64; x += 3)
        for (std::uint32_t y = 0; y < 64; y += 5)
            EXPECT_EQ(morton2_decode(morton2(x, y)), glm::uvec2(x, y));
}

TEST(DipoleAtlas, PreservesAreaAndPlacesTexelsOnTheSurface) {
    const Mesh cube = test::box({1.0f, 2.0f, 0.5f});
    glm::vec3 lo(1e30f), hi(-1e30f);
    for (auto p : cube.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
    const glm::vec3 side = hi - lo;
    const double scale = 4.0;  // mm per unit
    const double area =
        2.0 * (side.x * side.y + side.y * side.z + side.z * side.x) * scale * scale;
    const int a = 64;
    const SurfaceAtlas atlas = build_surface_atlas(cube, scale, a);
    ASSERT_EQ(atlas.position_area.size(), std::size_t(a * a));
    EXPECT_NEAR(atlas.total_area, area, 1e-9 * area);
    double sum = 0;
    std::map<int, int> per_face;  // texels per face of the box
    for (std::size_t i = 0; i < atlas.position_area.size(); ++i) {
        const glm::vec4 t = atlas.position_area[i];
        sum += t.w;
        EXPECT_FLOAT_EQ(t.w, float(area / (a * a)));  // every texel the same share
        // On the surface: one coordinate at a face of the box.
        const glm::dvec3 p = glm::dvec3(t) / scale;
        int face = -1;
        for (int c = 0; c < 3; ++c) {
            if (std::abs(p[c] - lo[c]) < 1e-5) face = 2 * c;
            if (std::abs(p[c] - hi[c]) < 1e-5) face = 2 * c + 1;
            EXPECT_GE(p[c], lo[c] - 1e-5);
            EXPECT_LE(p[c], hi[c] + 1e-5);
        }
        ASSERT_GE(face, 0) << "texel " << i << " is off the surface";
        ++per_face[face];
        // The normal is the face's.
        EXPECT_NEAR(std::abs(atlas.normal[i][face / 2]), 1.0, 1e-5);
    }
    EXPECT_NEAR(sum, area, 1e-4 * area);
    // Texels in proportion to area: each face gets its share to within one texel per
    // triangle (2 triangles per face).
    for (const auto& [face, count] : per_face) {
        const int c = face / 2;
        const double face_area = side[(c + 1) % 3] * side[(c + 2) % 3] * scale * scale;
        EXPECT_NEAR(count, face_area / area * a * a, 2.0) << "face " << face;
    }
}

TEST(DipoleAtlas, NeighbouringTexelsAreNeighboursOnTheSurface) {
    // Morton order in 3D and 2D: the 2x2 blocks of the atlas are small patches, so the
    // mean distance between texels of one block is far below the mean over all pairs.
    const Mesh sphere = load_mesh("sphere:5k");
    const SurfaceAtlas atlas = build_surface_atlas(sphere, 1.0, 128);
    double block = 0;
    int blocks = 0;
    for (int y = 0; y < 128; y += 2)
        for (int x = 0; x < 128; x += 2) {
            const glm::vec3 p = atlas.position_area[y * 128 + x];
            const glm::vec3 q = atlas.position_area[(y + 1) * 128 + x + 1];
            block += glm::length(p - q);
            ++blocks;
        }
    // Random points on a unit sphere are 4/3 apart on average; 128^2 texels on area 4 pi
    // are ~0.03 apart.
    EXPECT_LT(block / blocks, 0.1);
}

TEST(DipoleAtlas, RejectsBadResolutions) {
    const Mesh cube = test::box({1.0f, 1.0f, 1.0f});
    EXPECT_THROW(build_surface_atlas(cube, 1.0, 100), std::invalid_argument);
    EXPECT_THROW(build_surface_atlas(cube, 1.0, 0), std::invalid_argument);
    EXPECT_THROW(build_surface_atlas(cube, 1.0, 8192), std::invalid_argument);
}

std::vector<double> test_field(int n) {
    // Masses with zeros, including whole zero quadrants and a single isolated texel.
    std::vector<double> field(std::size_t(n) * n, 0.0);
    for (int y = 0; y < n; ++y)
        for (int x = 0; x < n; ++x) {
            if (x < n / 2 && y < n / 2) continue;  // an empty quadrant
            if ((x + 2 * y) % 3 == 0) continue;    // scattered zeros
            field[y * n + x] = 1.0 + 0.37 * ((x * 7 + y * 13) % 11);
        }
    field[1] = 5.0;  // one texel alone in the empty quadrant
    return field;
}

TEST(DipoleSampling, PyramidLevelsAreBoxSums) {
    const int n = 16;
    const std::vector<double> field = test_field(n);
    const MassPyramid p = build_mass_pyramid(field, n);
    ASSERT_EQ(p.levels.size(), 5u);
    double total = 0;
    for (double m : field) total += m;
    EXPECT_NEAR(p.total(), total, 1e-12 * total);
    // Level 2 (4x4): each texel is the sum of its 4x4 block of the field.
    for (int y = 0; y < 4; ++y)
        for (int x = 0; x < 4; ++x) {
            double block = 0;
            for (int j = 0; j < 4; ++j)
                for (int i = 0; i < 4; ++i) block += field[(4 * y + j) * n + 4 * x + i];
            EXPECT_NEAR(p.levels[2][y * 4 + x], block, 1e-12 * total);
        }
    EXPECT_THROW(build_mass_pyramid(field, 8), std::invalid_argument);
}

TEST(DipoleSampling, StratifiedDescentDrawsEachTexelInProportionToItsMass) {
    const int n = 16;
    const std::vector<double> field = test_field(n);
    const MassPyramid p = build_mass_pyramid(field, n);
    const int samples = 10007;
    std::vector<int> count(field.size(), 0);
    for (double y : stratified_positions(samples, 3)) {
        const auto texel = descend(p, y);
        ASSERT_TRUE(texel.has_value());
        ++count[texel->y * n + texel->x];
    }
    // The descent is the inverse CDF along the Morton curve, so stratified positions
    // give each texel its expected count to within one.
    for (std::size_t i = 0; i < field.size(); ++i) {
        if (field[i] == 0.0) {
            EXPECT_EQ(count[i], 0) << "zero-mass texel " << i << " was picked";
            continue;
        }
        EXPECT_NEAR(count[i], samples * field[i] / p.total(), 1.0) << "texel " << i;
    }
}

TEST(DipoleSampling, NeverPicksAZeroMassTexelAtTheEdges) {
    const int n = 16;
    const std::vector<double> field = test_field(n);
    const MassPyramid p = build_mass_pyramid(field, n);
    // y at 0, just below 1, and exactly at every cumulative boundary in Morton order.
    std::vector<double> ys = {0.0, std::nextafter(1.0, 0.0), 1.0, -0.5, 2.0};
    double cumulative = 0;
    for (std::uint32_t m = 0; m < std::uint32_t(n * n); ++m) {
        const glm::uvec2 xy = morton2_decode(m);
        cumulative += field[xy.y * n + xy.x];
        ys.push_back(cumulative / p.total());
        ys.push_back(std::nextafter(cumulative / p.total(), 0.0));
    }
    for (double y : ys) {
        const auto texel = descend(p, y);
        ASSERT_TRUE(texel.has_value());
        EXPECT_GT(field[texel->y * n + texel->x], 0.0) << "y = " << y;
    }
}

TEST(DipoleSampling, NoMassNoSample) {
    const MassPyramid p = build_mass_pyramid(std::vector<double>(64, 0.0), 8);
    EXPECT_FALSE(descend(p, 0.5).has_value());
}

TEST(DipoleSampling, PositionsAreStratifiedAndDeterministic) {
    const auto y = stratified_positions(400, 7);
    ASSERT_EQ(y.size(), 400u);
    for (int k = 0; k < 400; ++k) {
        EXPECT_GE(y[k], k / 400.0);
        EXPECT_LT(y[k], (k + 1) / 400.0);
    }
    EXPECT_EQ(y, stratified_positions(400, 7));
    EXPECT_NE(y, stratified_positions(400, 8));
    EXPECT_DOUBLE_EQ(stratification_offset(0), 0.5);
}

}  // namespace
}  // namespace lucent::dipole

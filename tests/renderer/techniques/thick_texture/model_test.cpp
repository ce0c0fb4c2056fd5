// The thick-texture model on the CPU against exact values: hand-counted records, the
// closed forms of the note (stripes dx/w, square-hole nets, model and exact), the exact
// traversal, the pyramid's averages, mirror symmetry, the wide-hole fix, hard cases.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "renderer/techniques/thick_texture/thick_texture.h"

namespace lucent::thick_texture {
namespace {

// A tile from rows written top first ('#' opaque, '.' hole).
TexelGrid grid_of(std::vector<std::string> rows_top_first) {
    TexelGrid g;
    g.height = int(rows_top_first.size());
    g.width = int(rows_top_first[0].size());
    for (int j = 0; j < g.height; ++j)
        for (int i = 0; i < g.width; ++i)
            g.opaque.push_back(rows_top_first[g.height - 1 - j][i] == '#');
    g.colour.assign(g.opaque.size(), glm::vec3(1.0f));
    return g;
}

TexelGrid net(int hole, int wall) {
    std::vector<std::string> rows(hole + wall, std::string(hole + wall, '#'));
    for (int j = 0; j < hole; ++j)
        for (int i = 0; i < hole; ++i) rows[j][i] = '.';
    return grid_of(rows);
}

// The average record of a tile (the pyramid's top when the tile is a power of two).
TexelRecord mean_record(const TexelGrid& g, int bins = 1) {
    const auto records = level0_records(g, bins);
    TexelRecord mean = records[0];
    mean = TexelRecord{};
    for (auto& b : mean.bins) b.assign(bins > 1 ? bins : 0, 0.0);
    for (const auto& r : records) {
        mean.walls += r.walls / double(records.size());
        mean.triangles += r.triangles / double(records.size());
        mean.opaque += r.opaque / double(records.size());
        for (int d = 0; d < 4; ++d)
            for (std::size_t k = 0; k < r.bins[d].size(); ++k)
                mean.bins[d][k] += r.bins[d][k] / double(records.size());
    }
    return mean;
}

double model_net(int n, glm::dvec2 r) {
    const double a = std::min(std::abs(r.x), 1.0), b = std::min(std::abs(r.y), 1.0);
    return (n - a) * (n - b) / double((n + 1) * (n + 1));
}
double exact_net(int n, glm::dvec2 r) {
    return (n - std::min(std::abs(r.x), double(n))) *
           (n - std::min(std::abs(r.y), double(n))) / double((n + 1) * (n + 1));
}

TEST(ThickTextureRecords, SingleHoleHasFourWallsAndNoTriangles) {
    const auto records = level0_records(grid_of({"###", "#.#", "###"}), 1);
    const TexelRecord& hole = records[1 * 3 + 1];
    EXPECT_EQ(hole.walls, glm::dvec4(1, 1, 1, 1));
    EXPECT_EQ(hole.triangles, glm::dvec4(0, 0, 0, 0));
    EXPECT_EQ(hole.opaque, 0.0);
    EXPECT_EQ(records[0].opaque, 1.0);
    EXPECT_EQ(records[0].walls, glm::dvec4(0.0));
}

TEST(ThickTextureRecords, TwoByOneHoleMatchesTheHandCount) {
    // Left texel of a 2x1 hole: walls top, left, bottom, not right; TR and BR see the
    // diagonal's wall through the open right neighbour.
    const auto records = level0_records(grid_of({"####", "#..#", "####"}), 1);
    const TexelRecord& left = records[1 * 4 + 1];
    EXPECT_EQ(left.walls, glm::dvec4(1, 1, 1, 0));
    EXPECT_EQ(left.triangles, glm::dvec4(1, 0, 0, 1));
    // Summed over the hole, (+,+): O = a + 2b - ab = 2 - (2 - a)(1 - b) (the exact area).
    const glm::dvec2 r(0.6, 0.3);
    const double sum = model_fractions(left, r).occluded +
                       model_fractions(records[1 * 4 + 2], r).occluded;
    EXPECT_NEAR(sum, 2.0 - (2.0 - 0.6) * (1.0 - 0.3), 1e-12);
}

TEST(ThickTextureModel, NormalRaySeesTheHoleFraction) {
    for (const TexelGrid& g :
         {net(5, 1), net(1, 1), grid_of({"#..#.", ".#...", "..###"})}) {
        const TexelRecord mean = mean_record(g);
        EXPECT_NEAR(model_fractions(mean, {0.0, 0.0}).transparent, g.hole_fraction(),
                    1e-12);
        EXPECT_NEAR(exact_fractions(g, {0.0, 0.0}, 4).transparent, g.hole_fraction(),
                    1e-12);
    }
}

TEST(ThickTextureModel, StripesFollowTheTwoDimensionalFormula) {
    // Holes n wide, walls 1: the model's O = dx / w per hole gives (n - a) / (n + 1), the
    // truth (n - min(dx, n)) / (n + 1).
    for (int n : {1, 2, 4})
        for (double dx : {0.0, 0.25, 0.7, 1.0, 1.8, 3.5}) {
            std::string row(n + 1, '#');
            std::fill(row.begin(), row.begin() + n, '.');
            const TexelGrid g = grid_of({row});
            const double model = (n - std::min(dx, 1.0)) / (n + 1.0);
            const double exact = (n - std::min(dx, double(n))) / (n + 1.0);
            EXPECT_NEAR(model_fractions(mean_record(g), {dx, 0.0}).transparent, model,
                        1e-12)
                << n << " " << dx;
            EXPECT_NEAR(exact_fractions(g, {dx, 0.0}, 64).transparent, exact, 2e-3)
                << n << " " << dx;
        }
}

TEST(ThickTextureModel, SquareHoleNetsFollowTheClosedForms) {
    for (int n : {1, 2, 3, 5})
        for (glm::dvec2 r :
             {glm::dvec2(0.3, 0.0), glm::dvec2(0.5, -0.8), glm::dvec2(-1.7, 0.4),
              glm::dvec2(2.5, 1.0), glm::dvec2(-6.0, -0.2)}) {
            const TexelGrid g = net(n, 1);
            EXPECT_NEAR(model_fractions(mean_record(g), r).transparent, model_net(n, r),
                        1e-12)
                << n << " " << r.x << "," << r.y;
            EXPECT_NEAR(exact_fractions(g, r, 48).transparent, exact_net(n, r), 4e-3)
                << n << " " << r.x << "," << r.y;
        }
    // The mosquito net at h = 1, 60 degrees, azimuth 0: model 0.556, truth 0.454.
    const glm::dvec2 r(std::tan(60.0 * M_PI / 180.0), 0.0);
    EXPECT_NEAR(model_net(5, r), 0.5556, 1e-4);
    EXPECT_NEAR(exact_net(5, r), 0.4539, 1e-4);
}

TEST(ThickTextureModel, OneTexelHolesAreExactAtEveryAngle) {
    const TexelGrid g = net(1, 1);
    for (glm::dvec2 r :
         {glm::dvec2(0.4, 0.2), glm::dvec2(3.0, -0.5), glm::dvec2(-20.0, 20.0)})
        EXPECT_NEAR(model_fractions(mean_record(g), r).transparent,
                    exact_fractions(g, r, 48).transparent, 3e-3);
}

TEST(ThickTextureModel, MatchesTheExactAreaOnRandomTexturesBelowOneTexel) {
    // The 0..2 triangle rule: the summed model equals the exact area for |r| <= 1 on any
    // texture (a 0/1 rule is off by up to 0.08 here).
    for (int seed = 1; seed <= 4; ++seed) {
        const TexelGrid full =
            make_texel_grid("random:0.5," + std::to_string(seed), glm::vec3(1));
        TexelGrid g;  // an 8 x 8 corner, tiled
        g.width = g.height = 8;
        for (int j = 0; j < 8; ++j)
            for (int i = 0; i < 8; ++i) g.opaque.push_back(full.at(i, j));
        g.colour.assign(64, glm::vec3(1.0f));
        for (glm::dvec2 r : {glm::dvec2(0.7, 0.45), glm::dvec2(-0.9, 0.3),
                             glm::dvec2(0.2, -1.0), glm::dvec2(-0.55, -0.65)}) {
            const Fractions model = model_fractions(mean_record(g), r);
            const Fractions exact = exact_fractions(g, r, 96);
            EXPECT_NEAR(model.transparent, exact.transparent, 3e-3) << seed;
            EXPECT_NEAR(model.opaque, exact.opaque, 1e-12);
        }
    }
}

TEST(ThickTextureModel, MirroredTextureWithMirroredRayGivesTheSameFractions) {
    const TexelGrid g = grid_of({"#..##", "#...#", "##.##", "#####"});
    TexelGrid mirrored = g;
    for (int j = 0; j < g.height; ++j)
        for (int i = 0; i < g.width; ++i)
            mirrored.opaque[j * g.width + i] = g.opaque[j * g.width + (g.width - 1 - i)];
    for (glm::dvec2 r : {glm::dvec2(0.6, 0.2), glm::dvec2(0.3, -0.9)}) {
        const glm::dvec2 flipped(-r.x, r.y);
        EXPECT_NEAR(model_fractions(mean_record(g), r).transparent,
                    model_fractions(mean_record(mirrored), flipped).transparent, 1e-12);
        EXPECT_NEAR(exact_fractions(g, r, 32).transparent,
                    exact_fractions(mirrored, flipped, 32).transparent, 2e-3);
    }
}

TEST(ThickTextureModel, WideHoleFixIsExactOnNetsAndAlgorithmOneBelowATexel) {
    const TexelGrid g = net(5, 1);
    const TexelRecord thesis = mean_record(g, 1), fixed = mean_record(g, 8);
    // The note's check: r = (2.5, 1): exact 0.2778, the thesis 0.444.
    EXPECT_NEAR(model_fractions(fixed, {2.5, 1.0}).transparent, 10.0 / 36.0, 1e-12);
    EXPECT_NEAR(model_fractions(thesis, {2.5, 1.0}).transparent, 16.0 / 36.0, 1e-12);
    for (glm::dvec2 r : {glm::dvec2(0.4, -0.7), glm::dvec2(-1.0, 0.2)})
        EXPECT_NEAR(model_fractions(fixed, r).transparent,
                    model_fractions(thesis, r).transparent, 1e-12);
    for (glm::dvec2 r :
         {glm::dvec2(3.3, 0.0), glm::dvec2(-4.2, 1.9), glm::dvec2(7.0, 2.0)})
        EXPECT_NEAR(model_fractions(fixed, r).transparent, exact_net(5, r), 1e-12);
}

TEST(ThickTexturePyramid, EachLevelIsTheMeanOfItsChildren) {
    const TexelGrid g = make_texel_grid("random:0.4,7", glm::vec3(0.5f, 0.2f, 0.9f));
    const RecordPyramid pyramid = build_pyramid(g, 4);
    ASSERT_EQ(pyramid.sizes.back(), glm::ivec2(1, 1));
    for (std::size_t l = 1; l < pyramid.levels.size(); ++l) {
        const glm::ivec2 above = pyramid.sizes[l - 1], size = pyramid.sizes[l];
        for (int y = 0; y < size.y; y += 3)
            for (int x = 0; x < size.x; x += 3) {
                glm::dvec4 walls(0.0);
                double opaque = 0.0, bin = 0.0;
                for (int dy = 0; dy < 2; ++dy)
                    for (int dx = 0; dx < 2; ++dx) {
                        const auto& c =
                            pyramid.levels[l - 1][(2 * y + dy) * above.x + 2 * x + dx];
                        walls += c.walls / 4.0;
                        opaque += c.opaque / 4.0;
                        bin += c.bins[0][1] / 4.0;
                    }
                const auto& t = pyramid.levels[l][y * size.x + x];
                EXPECT_NEAR(glm::length(t.walls - walls), 0.0, 1e-12);
                EXPECT_NEAR(t.opaque, opaque, 1e-12);
                EXPECT_NEAR(t.bins[0][1], bin, 1e-12);
            }
    }
    // The top is the tile's mean: rho_op = the opaque fraction.
    EXPECT_NEAR(pyramid.levels.back()[0].opaque, 1.0 - g.hole_fraction(), 1e-12);
}

TEST(ThickTexturePyramid, ThreeTimesPowerOfTwoTilesReduceExactly) {
    const TexelGrid g = make_texel_grid("net:5,1", glm::vec3(1.0f));
    EXPECT_EQ(g.width, 384);  // 6 * 64
    const RecordPyramid pyramid = build_pyramid(g, 1);
    EXPECT_EQ(pyramid.sizes.back(), glm::ivec2(1, 1));
    // Level 6 (6 x 6 texels of 64 x 64) and the top are the period's mean exactly.
    const TexelRecord mean = mean_record(net(5, 1));
    EXPECT_NEAR(pyramid.levels.back()[0].opaque, mean.opaque, 1e-12);
    EXPECT_NEAR(glm::length(pyramid.levels.back()[0].walls - mean.walls), 0.0, 1e-12);
}

TEST(ThickTextureHardCases, GrazingHugeAndZeroThicknessStayFiniteAndInRange) {
    const TexelGrid g = net(5, 1);
    const TexelRecord mean = mean_record(g, 8);
    for (glm::dvec3 d :
         {glm::dvec3(1, 0, 0), glm::dvec3(0.7, -0.7, 1e-30), glm::dvec3(0, 0, 1),
          glm::dvec3(0, 0, 0), glm::dvec3(1e-30, 0, 0)})
        for (double h : {0.0, 1e-9, 1.0, 64.0}) {
            const glm::dvec2 r = scaled_ray(d, h);
            ASSERT_TRUE(std::isfinite(r.x) && std::isfinite(r.y));
            const Fractions f = model_fractions(mean, r);
            for (double v : {f.opaque, f.occluded, f.transparent}) {
                EXPECT_TRUE(std::isfinite(v));
                EXPECT_GE(v, 0.0);
                EXPECT_LE(v, 1.0);
            }
            EXPECT_NEAR(f.opaque + f.occluded + f.transparent, 1.0, 1e-12);
        }
    // Grazing through a 1-texel net: fully occluded, in the model and in the traversal.
    const glm::dvec2 grazing = scaled_ray({1.0, 0.0, 0.0}, 1.0, 1e4);
    EXPECT_NEAR(model_fractions(mean_record(net(1, 1)), grazing).transparent, 0.0, 1e-12);
    EXPECT_EQ(exact_fractions(net(1, 1), grazing, 8).transparent, 0.0);
    // h = 0: the hole fraction whatever the angle.
    EXPECT_NEAR(model_fractions(mean, scaled_ray({0.9, 0.1, 0.01}, 0.0)).transparent,
                25.0 / 36.0, 1e-12);
    // No hole, no opaque texel.
    EXPECT_EQ(model_fractions(mean_record(grid_of({"##"})), {3.0, 2.0}).transparent, 0.0);
    EXPECT_EQ(model_fractions(mean_record(grid_of({".."})), {3.0, 2.0}).transparent, 1.0);
}

TEST(ThickTextureSpecs, BadSpecsAreOneLineNamingTheTexture) {
    for (const char* spec : {"net:5", "net:a,1", "net:0,0", "random:2,1", "weave:0,1",
                             "checker:3", "no_such_file.png", "curtain:x"}) {
        try {
            make_texel_grid(spec, glm::vec3(1.0f));
            ADD_FAILURE() << spec << " was accepted";
        } catch (const KnobError& e) {
            const std::string what = e.what();
            EXPECT_EQ(what.rfind(std::string("texture: '") + spec + "'", 0), 0u) << what;
            EXPECT_EQ(what.find('\n'), std::string::npos);
        }
    }
    EXPECT_NEAR(make_texel_grid("random:0.3,5", glm::vec3(1)).hole_fraction(), 0.3, 0.01);
    EXPECT_TRUE(make_texel_grid("weave:2,1", glm::vec3(1)).coloured);
    const TexelGrid curtain = make_texel_grid("curtain:3", glm::vec3(1));
    EXPECT_GT(curtain.hole_fraction(), 0.05);
    EXPECT_LT(curtain.hole_fraction(), 0.5);
}

}  // namespace
}  // namespace lucent::thick_texture

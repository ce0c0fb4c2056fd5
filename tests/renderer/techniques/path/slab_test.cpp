// The path technique's transport on the infinite slab against closed forms and published
// values, each within 3 standard errors of the estimate (issue 28, section 2).
#include "renderer/techniques/path/slab.h"

#include <gtest/gtest.h>

#include <cmath>

namespace lucent::path {
namespace {

void expect_within_3_se(const Tally& tally, double expected, const char* what) {
    EXPECT_TRUE(std::isfinite(tally.mean)) << what;
    EXPECT_LE(std::abs(tally.mean - expected), 3.0 * tally.standard_error + 1e-12)
        << what << ": " << tally.mean << " +- " << tally.standard_error << ", expected "
        << expected;
}

// Wang, Jacques and Zheng 1995 (MCML), Table 2's standard case: index-matched, mu_a =
// 10/cm, mu_s = 90/cm, g = 0.75, d = 0.02 cm: optical depth 2, albedo 0.9.
TEST(Slab, MatchesMcmlStandardCase) {
    SlabProblem p;
    p.albedo = 0.9;
    p.g = 0.75;
    p.optical_depth = 2.0;
    p.eta = 1.0;
    p.paths = 200'000;
    const SlabResult r = run_slab(p);
    expect_within_3_se(r.diffuse_reflectance, 0.09739, "diffuse reflectance");
    expect_within_3_se(r.total_transmittance, 0.66096, "total transmittance");
    EXPECT_EQ(r.specular_reflectance.mean, 0.0);
    EXPECT_LT(r.total_transmittance.standard_error, 2e-3);
}

// Semi-infinite, index-matched, isotropic, albedo 0.8, normal incidence: total diffuse
// reflectance 0.28525 by adding-doubling (iadpython's tests).
TEST(Slab, MatchesAddingDoublingSemiInfinite) {
    SlabProblem p;
    p.albedo = 0.8;
    p.optical_depth = INFINITY;
    p.paths = 200'000;
    const SlabResult r = run_slab(p);
    expect_within_3_se(r.diffuse_reflectance, 0.28525, "reflectance");
    EXPECT_EQ(r.total_transmittance.mean, 0.0);
}

// Albedo 1 in a half-space: nothing is absorbed and every walk returns, so the
// reflectance is 1; the walks the event cap stops are counted, not hidden.
TEST(Slab, ConservesEnergyAtAlbedoOne) {
    SlabProblem p;
    p.albedo = 1.0;
    p.optical_depth = INFINITY;
    p.paths = 4000;
    p.limits.max_events = 1'000'000;  // P(unfinished) ~ 1 / sqrt(pi cap) = 5.6e-4
    const SlabResult r = run_slab(p);
    EXPECT_LE(r.counters.unfinished, 10u);
    const double lost = double(r.counters.unfinished) / double(p.paths);
    EXPECT_NEAR(r.diffuse_reflectance.mean + lost, 1.0, 1e-12);
    expect_within_3_se(r.diffuse_reflectance, 1.0 - lost, "reflectance");
}

// A clear absorbing slab between two Fresnel interfaces at incidence mu: the closed form
// of its multiple reflections, R = r + (1-r)^2 r T^2 / (1 - r^2 T^2) and
// T_total = (1-r)^2 T / (1 - r^2 T^2), with r the Fresnel reflectance at the incidence
// (the same inside at the refracted angle) and T = exp(-tau / mu_t) one crossing.
double fresnel(double cos_i, double eta) {
    const double sin_t = std::sqrt(1 - cos_i * cos_i) / eta;
    const double cos_t = std::sqrt(1 - sin_t * sin_t);
    const double rs = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    const double rp = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    return 0.5 * (rs * rs + rp * rp);
}

TEST(Slab, ClearSlabMatchesMultipleReflections) {
    for (const double eta : {1.5, 2.0}) {
        for (const double mu : {1.0, 0.5}) {
            SlabProblem p;
            p.albedo = 0.0;
            p.optical_depth = 0.3;
            p.eta = eta;
            p.incidence_cosine = mu;
            p.paths = 100'000;
            const double r = fresnel(mu, eta);
            const double mu_t = std::sqrt(1 - (1 - mu * mu) / (eta * eta));
            const double t = std::exp(-p.optical_depth / mu_t);
            const double denominator = 1 - r * r * t * t;
            const SlabResult result = run_slab(p);
            SCOPED_TRACE("eta " + std::to_string(eta) + " mu " + std::to_string(mu));
            expect_within_3_se(result.total_reflectance,
                               r + (1 - r) * (1 - r) * r * t * t / denominator,
                               "reflectance");
            expect_within_3_se(result.total_transmittance,
                               (1 - r) * (1 - r) * t / denominator, "transmittance");
            expect_within_3_se(result.specular_reflectance, r, "first surface");
        }
    }
}

// Each shortcut equals the full walk within the standard errors: index-matched without
// Fresnel events, no collisions without scattering.
TEST(Slab, ShortcutsMatchTheFullWalk) {
    for (const double albedo : {0.0, 0.7}) {
        SlabProblem p;
        p.albedo = albedo;
        p.optical_depth = 1.0;
        p.paths = 100'000;
        const SlabResult pruned = run_slab(p);
        p.shortcuts = WalkShortcuts::none();
        p.seed = 2;
        const SlabResult full = run_slab(p);
        const auto close = [](const Tally& a, const Tally& b) {
            return std::abs(a.mean - b.mean) <=
                   3.0 * std::hypot(a.standard_error, b.standard_error) + 1e-12;
        };
        EXPECT_TRUE(close(pruned.diffuse_reflectance, full.diffuse_reflectance))
            << albedo;
        EXPECT_TRUE(close(pruned.total_transmittance, full.total_transmittance))
            << albedo;
        EXPECT_EQ(pruned.counters.interface_events, 0u);
        EXPECT_GT(full.counters.interface_events, 0u);
    }
}

TEST(Slab, IsDeterministicForASeed) {
    SlabProblem p;
    p.albedo = 0.95;
    p.g = 0.5;
    p.optical_depth = 4.0;
    p.eta = 1.33;
    p.paths = 5000;
    const SlabResult a = run_slab(p), b = run_slab(p);
    EXPECT_EQ(a.diffuse_reflectance.mean, b.diffuse_reflectance.mean);
    EXPECT_EQ(a.total_transmittance.mean, b.total_transmittance.mean);
}

TEST(Slab, HardCasesStayFinite) {
    for (const double depth : {0.0, 1e-9, 1e4}) {
        for (const double mu : {1.0, 1e-6}) {
            SlabProblem p;
            p.albedo = 0.99;
            p.optical_depth = depth;
            p.eta = 2.0;
            p.incidence_cosine = mu;
            p.paths = 2000;
            const SlabResult r = run_slab(p);
            const double sum = r.total_reflectance.mean + r.total_transmittance.mean;
            EXPECT_TRUE(std::isfinite(sum));
            EXPECT_LE(sum, 1.0 + 1e-12);
            if (depth == 0.0) {
                EXPECT_NEAR(sum, 1.0, 1e-12);  // nothing to absorb
            }
        }
    }
}

TEST(Slab, RefusesOutOfRangeInputsNamingTheFlag) {
    SlabProblem p;
    p.albedo = 1.5;
    try {
        run_slab(p);
        FAIL();
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("--albedo"), std::string::npos);
    }
    p = {};
    p.g = 1.0;
    EXPECT_THROW(run_slab(p), std::invalid_argument);
    p = {};
    p.incidence_cosine = 0.0;
    EXPECT_THROW(run_slab(p), std::invalid_argument);
}

}  // namespace
}  // namespace lucent::path

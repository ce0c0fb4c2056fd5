// The path tracer's Henyey-Greenstein phase function and its sampling against closed
// forms: the density integrates to one over the sphere, the sampled cosines follow the
// density's own CDF (chi-square, 40 bins), their mean is g, the azimuth is uniform, and
// the extremes (g near +-1, g near 0, u at 0 and 1) give finite unit directions.
#include <gtest/gtest.h>

#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <glm/glm.hpp>
#include <random>
#include <vector>

#include "renderer/techniques/path/transport.h"

namespace lucent::path {
namespace {

constexpr double kPi = 3.14159265358979323846;

// P(cos theta <= x) for Henyey-Greenstein, integrated by hand from its density:
// (1 - g^2) / (2 g) * ((1 + g^2 - 2 g x)^(-1/2) - 1 / (1 + g)); (x + 1) / 2 at g = 0.
double cdf_of_cosine(double g, double x) {
    if (g == 0.0) return (x + 1.0) / 2.0;
    return (1.0 - g * g) / (2.0 * g) *
           (1.0 / std::sqrt(1.0 + g * g - 2.0 * g * x) - 1.0 / (1.0 + g));
}

const std::vector<double> kAsymmetries = {-0.95, -0.5, 0.0, 5e-5, 0.3, 0.75, 0.95};

TEST(HenyeyGreenstein, TheDensityIntegratesToOneOverTheSphere) {
    for (const double g : kAsymmetries) {
        // 2 pi times the integral over cos theta, by the midpoint rule on a grid fine
        // enough for the forward peak at g = 0.95 (width ~ 1 - g).
        const int n = 2'000'000;
        double sum = 0;
        for (int i = 0; i < n; ++i)
            sum += henyey_greenstein(g, -1.0 + (i + 0.5) * 2.0 / n);
        EXPECT_NEAR(2.0 * kPi * sum * 2.0 / n, 1.0, 1e-6) << "g = " << g;
    }
}

TEST(HenyeyGreenstein, SampledCosinesFollowTheDensityAndAverageG) {
    const glm::dvec3 forwards[] = {glm::normalize(glm::dvec3(1, 2, -3)), {0, 0, -1}};
    for (const glm::dvec3 forward : forwards)
        for (const double g : kAsymmetries) {
            std::mt19937_64 rng(1234);
            std::uniform_real_distribution<double> u(0.0, 1.0);
            const int samples = 200'000, bins = 40;
            std::vector<int> counts(bins, 0);
            double mean = 0;
            for (int i = 0; i < samples; ++i) {
                const double u1 = u(rng), u2 = u(rng);
                const glm::dvec3 d = sample_henyey_greenstein(g, forward, u1, u2);
                ASSERT_NEAR(glm::length(d), 1.0, 1e-12) << "g = " << g;
                const double mu = glm::dot(d, forward);
                mean += mu / samples;
                counts[std::min(bins - 1, int((mu + 1.0) / 2.0 * bins))]++;
            }
            double chi2 = 0;
            int used = 0;
            for (int b = 0; b < bins; ++b) {
                const double p = cdf_of_cosine(g, -1.0 + 2.0 * (b + 1) / bins) -
                                 cdf_of_cosine(g, -1.0 + 2.0 * b / bins);
                const double expected = p * samples;
                // Bins the density leaves almost empty (backward at g = 0.95) are
                // checked by the mean; a chi-square term needs an expectation.
                if (expected < 5) continue;
                ++used;
                chi2 += (counts[b] - expected) * (counts[b] - expected) / expected;
            }
            const double limit =
                boost::math::quantile(boost::math::chi_squared(used - 1), 0.9999);
            EXPECT_LT(chi2, limit) << "g = " << g;
            // The mean cosine of Henyey-Greenstein is g (standard error < 0.0013).
            EXPECT_NEAR(mean, g, 0.006) << "g = " << g;
        }
}

TEST(HenyeyGreenstein, TheAzimuthAroundTheForwardDirectionIsUniform) {
    const glm::dvec3 forward = glm::normalize(glm::dvec3(-0.3, 0.5, 0.8));
    const Frame frame(forward);
    std::mt19937_64 rng(99);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const int samples = 100'000, bins = 24;
    std::vector<int> counts(bins, 0);
    for (int i = 0; i < samples; ++i) {
        const double u1 = u(rng), u2 = u(rng);
        const glm::dvec3 d = sample_henyey_greenstein(0.6, forward, u1, u2);
        const double phi = std::atan2(glm::dot(d, frame.t), glm::dot(d, frame.s));
        counts[std::min(bins - 1, int((phi + kPi) / (2 * kPi) * bins))]++;
    }
    double chi2 = 0;
    const double expected = double(samples) / bins;
    for (const int c : counts) chi2 += (c - expected) * (c - expected) / expected;
    EXPECT_LT(chi2, boost::math::quantile(boost::math::chi_squared(bins - 1), 0.9999));
}

TEST(HenyeyGreenstein, ExtremeArgumentsGiveFiniteUnitDirections) {
    const glm::dvec3 forward(0, 1, 0);
    for (const double g : {-0.95, -1e-5, 0.0, 1e-5, 1e-4, 0.95})
        for (const double u1 : {0.0, 1e-300, 0.5, 1.0 - 1e-16, 1.0})
            for (const double u2 : {0.0, 1.0}) {
                const glm::dvec3 d = sample_henyey_greenstein(g, forward, u1, u2);
                EXPECT_TRUE(std::isfinite(d.x) && std::isfinite(d.y) &&
                            std::isfinite(d.z))
                    << "g = " << g << ", u1 = " << u1;
                EXPECT_NEAR(glm::length(d), 1.0, 1e-12);
                EXPECT_TRUE(std::isfinite(henyey_greenstein(g, glm::dot(d, forward))));
            }
    // u1 = 0 is straight back and u1 = 1 straight ahead, for either sign of g.
    EXPECT_NEAR(glm::dot(sample_henyey_greenstein(0.9, forward, 0.0, 0.3), forward), -1.0,
                1e-9);
    EXPECT_NEAR(glm::dot(sample_henyey_greenstein(-0.9, forward, 1.0, 0.3), forward), 1.0,
                1e-9);
}

}  // namespace
}  // namespace lucent::path

// The CPU reference's scattering integral against the note's analytic scenes, computed
// here by an independent quadrature: a puck lit along its axis (top- and bottom-face
// centres), a sphere lit from its pole (B depends only on the angle from the pole), the
// small- and large-scale limits and the hard cases of section 6.
#include "renderer/techniques/dipole/integrator.h"

#include <gtest/gtest.h>

#include <cmath>

#include "renderer/core/mesh.h"
#include "renderer/cpu/ray_caster.h"
#include "tests/renderer/techniques/dipole/test_meshes.h"

namespace lucent::dipole {
namespace {

// JMLH01's printed form, independent of Dipole::rd (see scattering_test.cpp).
glm::dvec3 jensen_rd(double r, const Material& m) {
    glm::dvec3 out;
    for (int c = 0; c < 3; ++c) {
        const double sa = m.sigma_a[c], ss = m.sigma_s_prime[c], eta = m.eta;
        const double st = sa + ss, ap = ss / st;
        const double fdr = -1.44 / (eta * eta) + 0.71 / eta + 0.668 + 0.0636 * eta;
        const double a = (1 + fdr) / (1 - fdr);
        const double tr = std::sqrt(3 * sa * st), zr = 1 / st, zv = zr * (1 + 4 * a / 3);
        const double dr = std::hypot(r, zr), dv = std::hypot(r, zv);
        out[c] = ap / (4 * M_PI) *
                 (zr * (tr + 1 / dr) * std::exp(-tr * dr) / (dr * dr) +
                  zv * (tr + 1 / dv) * std::exp(-tr * dv) / (dv * dv));
    }
    return out;
}

// Composite Simpson of f(t) over [0, 1] with n (even) intervals.
template <class F>
glm::dvec3 simpson(F f, int n) {
    glm::dvec3 sum(0.0);
    for (int i = 0; i <= n; ++i) {
        const double w = (i == 0 || i == n) ? 1 : (i % 2 ? 4 : 2);
        sum += w * f(double(i) / n);
    }
    return sum / (3.0 * n);
}

// pi Ft(1) integral_0^R 2 pi r Rd(sqrt(r^2 + depth^2)) dr: the puck's face centres.
glm::dvec3 puck_centre(const Material& m, double radius, double depth) {
    const double ft = fresnel_transmittance(m.eta, 1.0);
    return M_PI * ft *
           simpson(
               [&](double t) {
                   const double r = radius * t * t;  // dense near the axis
                   return 2 * M_PI * r * jensen_rd(std::hypot(r, depth), m) *
                          (2 * radius * t);
               },
               20000);
}

// B(theta0) on a sphere of radius R lit from +z: in spherical coordinates (gamma, psi)
// around xo, cos(theta) = cos(theta0) cos(gamma) + sin(theta0) sin(gamma) cos(psi).
glm::dvec3 sphere_radiosity(const Material& m, double radius, double theta0) {
    const int n = 1600;
    return simpson(
        [&](double t) {
            const double gamma = M_PI * t * t, dgamma = 2 * M_PI * t;
            const glm::dvec3 rd = jensen_rd(2 * radius * std::sin(gamma / 2), m);
            const glm::dvec3 ring = simpson(
                [&](double u) {
                    const double psi = M_PI * u;
                    const double mu = std::cos(theta0) * std::cos(gamma) +
                                      std::sin(theta0) * std::sin(gamma) * std::cos(psi);
                    const double e =
                        mu > 0 ? M_PI * fresnel_transmittance(m.eta, mu) * mu : 0;
                    return glm::dvec3(2 * M_PI * e);  // psi over [0, 2 pi] by symmetry
                },
                n);
            return radius * radius * std::sin(gamma) * dgamma * ring * rd;
        },
        n);
}

void expect_relative(glm::dvec3 got, glm::dvec3 want, double tolerance,
                     const std::string& what) {
    for (int c = 0; c < 3; ++c)
        EXPECT_NEAR(got[c], want[c], tolerance * std::abs(want[c]))
            << what << " channel " << c << ": got " << got[c] << ", want " << want[c];
}

TEST(DipoleReferenceIntegral, PuckLitAlongItsAxis) {
    const double radius = 5.0, thickness = 2.0;
    const Mesh puck = test::puck(float(radius), float(thickness), 512, 24);
    const RayCaster caster(puck);
    for (const char* name : {"skin1", "skimmilk", "marble"}) {
        const Material& m = *find_material_preset(name);
        const ScatteringIntegrator integrator(puck, 1.0, {0, 0, 1}, m, {}, &caster);
        // Phi = pi Ft(1) * top area (the rim and the bottom are unlit).
        const double polygon = 0.5 * 512 * radius * radius * std::sin(2 * M_PI / 512);
        EXPECT_NEAR(integrator.flux(), M_PI * fresnel_transmittance(1.3, 1.0) * polygon,
                    1e-6 * integrator.flux());
        expect_relative(integrator.radiosity({0, 0, thickness}),
                        puck_centre(m, radius, 0.0), 1e-3, std::string(name) + " top");
        expect_relative(integrator.radiosity({0, 0, 0}),
                        puck_centre(m, radius, thickness), 1e-3,
                        std::string(name) + " bottom");
    }
}

TEST(DipoleReferenceIntegral, SphereLitFromItsPoleDependsOnlyOnTheAngle) {
    const double radius = 5.0;
    const Mesh sphere = load_mesh("sphere:200k");  // unit sphere
    const RayCaster caster(sphere);
    for (const char* name : {"skin1", "skimmilk", "marble"}) {
        const Material& m = *find_material_preset(name);
        const ScatteringIntegrator integrator(sphere, radius, {0, 0, 1}, m, {}, &caster);
        // Flux = E_perp pi R^2 times the mean transmittance (0.938868 at eta 1.3).
        EXPECT_NEAR(integrator.flux(), M_PI * M_PI * radius * radius * 0.938868,
                    2e-4 * integrator.flux());
        for (double degrees : {0.0, 45.0, 90.0, 135.0, 180.0}) {
            const double theta = degrees * M_PI / 180;
            const glm::dvec3 want = sphere_radiosity(m, radius, theta);
            for (double phi : {0.0, 2.0, 4.0}) {  // symmetry about the axis
                const glm::dvec3 xo =
                    radius * glm::dvec3(std::sin(theta) * std::cos(phi),
                                        std::sin(theta) * std::sin(phi), std::cos(theta));
                expect_relative(integrator.radiosity(xo), want, 1e-3,
                                std::string(name) + " theta " + std::to_string(degrees));
            }
        }
    }
}

TEST(DipoleReferenceIntegral, TinyModelIsUniformRdAtZeroTimesFlux) {
    // diag << zr: B -> Rd(0) Phi everywhere, Phi proportional to size^2.
    const Mesh sphere = load_mesh("sphere:5k");
    const Material& m = *find_material_preset("skin1");
    const double scale = 0.001;  // 2 um across
    const ScatteringIntegrator tiny(sphere, scale, {0, 0, 1}, m, {}, nullptr);
    const glm::dvec3 rd0 = jensen_rd(0.0, m);
    for (const glm::dvec3 xo : {glm::dvec3(0, 0, scale), glm::dvec3(0, 0, -scale)})
        expect_relative(tiny.radiosity(xo), rd0 * tiny.flux(), 1e-3, "tiny");
    const ScatteringIntegrator twice(sphere, 2 * scale, {0, 0, 1}, m, {}, nullptr);
    EXPECT_NEAR(twice.flux() / tiny.flux(), 4.0, 1e-9);
}

TEST(DipoleReferenceIntegral, HugePlateIsTheBrdfLimit) {
    // A plate much wider than 1/sigma_tr facing the light: B = pi Ft(1) Rd_tot, the
    // note's skin1 column (and skim milk's B / E_perp = .80108 .79915 .67069).
    const Mesh plate = test::plate(400.0f, 64);
    IntegratorQuality quality;
    quality.max_cells = 400000;
    for (const char* name : {"skin1", "skimmilk"}) {
        const Material& m = *find_material_preset(name);
        const ScatteringIntegrator integrator(plate, 1.0, {0, 0, 1}, m, quality, nullptr);
        const glm::dvec3 want =
            M_PI * fresnel_transmittance(1.3, 1.0) * DipoleRgb(m).total_reflectance();
        expect_relative(integrator.radiosity({0.3, -0.2, 0}), want, 2e-3, name);
        if (std::string(name) == "skimmilk")
            expect_relative(integrator.radiosity({0, 0, 0}) / M_PI,
                            {.80108, .79915, .67069}, 2e-3, "note's skim milk");
    }
}

TEST(DipoleReferenceIntegral, NoIrradianceGivesZero) {
    const Mesh plate = test::plate(10.0f, 4);
    const Material& m = *find_material_preset("marble");
    // Light from behind the plate, and grazing along it: no flux, B = 0, no NaN.
    for (const glm::dvec3 light : {glm::dvec3(0, 0, -1), glm::dvec3(1, 0, 0)}) {
        const ScatteringIntegrator integrator(plate, 1.0, light, m, {}, nullptr);
        EXPECT_EQ(integrator.flux(), 0.0);
        EXPECT_EQ(integrator.radiosity({0, 0, 0}), glm::dvec3(0.0));
    }
    // Nothing scatters: B = 0.
    const ScatteringIntegrator black(plate, 1.0, {0, 0, 1}, Material{}, {}, nullptr);
    EXPECT_EQ(black.radiosity({0, 0, 0}), glm::dvec3(0.0));
}

TEST(DipoleReferenceIntegral, ShadowedCellsGetNoIrradiance) {
    // Two stacked plates lit from above: the lower one is in the upper one's shadow.
    test::MeshBuilder b;
    for (float z : {0.0f, 1.0f})
        b.quad({-5, -5, z}, {5, -5, z}, {5, 5, z}, {-5, 5, z}, {0, 0, 1});
    const Mesh stack = b.done("stack");
    const RayCaster caster(stack);
    const Material& m = *find_material_preset("skin1");
    const ScatteringIntegrator shadowed(stack, 1.0, {0, 0, 1}, m, {}, &caster);
    const ScatteringIntegrator unshadowed(stack, 1.0, {0, 0, 1}, m, {}, nullptr);
    EXPECT_NEAR(shadowed.flux(), M_PI * fresnel_transmittance(1.3, 1.0) * 100.0,
                1e-9 * shadowed.flux());
    EXPECT_NEAR(unshadowed.flux(), 2 * shadowed.flux(), 1e-9 * shadowed.flux());
}

}  // namespace
}  // namespace lucent::dipole

// Hard cases stay finite and take their documented values, on the GL path and the CPU
// reference alike: open meshes (no second layer), pixels at the far plane, zero-length
// normals, thickness_exponent 0 and huge, shininess 0, zero-area triangles, and a light
// straight behind the object.
#include <gtest/gtest.h>

#include "renderer/gl/frame_executor.h"
#include "renderer/render.h"
#include "tests/renderer/techniques/empirical/empirical_support.h"
#include "tests/support/gl_test_fixture.h"

namespace lucent {
namespace {

using test::all_finite;
using test::empirical_scene;
using test::thickness_only;

// A square in the plane z = 0 facing +z: an open mesh, one layer only.
std::shared_ptr<const Mesh> open_square(glm::vec3 normal = {0, 0, 1}) {
    Mesh mesh;
    mesh.name = "test:open_square";
    mesh.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    mesh.normals.assign(4, normal);
    mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
    mesh.content_hash =
        "open_square/" + std::to_string(normal.x) + std::to_string(normal.z);
    return std::make_shared<const Mesh>(std::move(mesh));
}

class EmpiricalNumerics : public test::HeadlessGlTest {
protected:
    // Renders with GL and with the CPU reference; both must be finite.
    std::pair<Image, Image> both(const Scene& scene) {
        Image gl_image = render_image(executor_, scene);
        Image cpu_image = find_technique("empirical").render_reference(scene);
        EXPECT_TRUE(all_finite(gl_image));
        EXPECT_TRUE(all_finite(cpu_image));
        return {std::move(gl_image), std::move(cpu_image)};
    }
    gl::FrameExecutor executor_;
};

// Documented: no second layer counts as the full diameter (t = 1), so the backlight term
// is wb * 0^r = 0 for r > 0 and wb * (Kd + Kb) for r = 0 (0^0 = 1).
TEST_F(EmpiricalNumerics, OpenMeshWithoutSecondLayerHasThicknessOne) {
    for (const char* r : {"1", "0"}) {
        for (const char* kernel : {"1", "5"}) {
            const Scene scene = empirical_scene(
                open_square(),
                thickness_only({{"thickness_exponent", r}, {"blur_kernel", kernel}}), 32,
                32);
            const auto [gl_image, cpu_image] = both(scene);
            const float expected = std::string(r) == "0" ? 1.0f : 0.0f;
            EXPECT_EQ(gl_image.at(16, 16).a, 1.0f);
            EXPECT_FLOAT_EQ(gl_image.at(16, 16).r, expected) << "r=" << r;
            EXPECT_FLOAT_EQ(cpu_image.at(16, 16).r, expected) << "r=" << r;
        }
    }
}

// Geometry cut by the far plane: the clipped back has no second layer (t = 1 there), the
// rest keeps its thickness; nothing becomes NaN at window depth 1.
TEST_F(EmpiricalNumerics, PixelsAtTheFarPlaneStayFinite) {
    Scene scene =
        empirical_scene(test::builtin_mesh("sphere:4k"), thickness_only(), 33, 33);
    scene.camera.far_plane = 2.5f;  // the sphere spans eye depths [1, 3]
    const auto [gl_image, cpu_image] = both(scene);
    // Central ray: front at 1, back at 3 > far: no second layer, t = 1, colour 0.
    EXPECT_NEAR(gl_image.at(16, 16).r, 0.0f, 1e-6);
    EXPECT_NEAR(cpu_image.at(16, 16).r, 0.0f, 1e-6);
    // And with the front at the far plane too (whole object clipped): only background.
    scene.camera.far_plane = 0.9f;
    scene.camera.near_plane = 0.5f;
    const auto [gl_clipped, cpu_clipped] = both(scene);
    for (int i = 0; i < 33 * 33; ++i) {
        EXPECT_EQ(gl_clipped.rgba[i * 4 + 3], 0.0f);
        EXPECT_EQ(cpu_clipped.rgba[i * 4 + 3], 0.0f);
    }
}

// Documented: a zero-length normal faces the viewer, N = (0,0,1) in eye space. With only
// the diffuse term (wd = Kd = Id = 1) and the light along +z the colour is N.L = 1.
TEST_F(EmpiricalNumerics, ZeroLengthNormalsFaceTheViewer) {
    const Scene scene = empirical_scene(open_square({0, 0, 0}),
                                        {{"albedo", "1"},
                                         {"ambient", "0"},
                                         {"backlight", "0"},
                                         {"specular_contribution", "0"},
                                         {"diffuse_contribution", "1"},
                                         {"light_direction", "0,0,1"}},
                                        32, 32);
    const auto [gl_image, cpu_image] = both(scene);
    EXPECT_FLOAT_EQ(gl_image.at(16, 16).r, 1.0f);
    EXPECT_FLOAT_EQ(cpu_image.at(16, 16).r, 1.0f);
}

// r = 0: (1 - t)^0 = 1 everywhere, so the backlight term is wb * (Kd + Kb) = 1 on every
// covered pixel. A huge r leaves only the thinnest rims, in [0, 1] and finite.
TEST_F(EmpiricalNumerics, ThicknessExponentZeroAndHuge) {
    const auto mesh = test::builtin_mesh("torus_knot:4k");
    const auto [gl_zero, cpu_zero] = both(
        empirical_scene(mesh, thickness_only({{"thickness_exponent", "0"}}), 48, 48));
    const auto [gl_huge, cpu_huge] = both(
        empirical_scene(mesh, thickness_only({{"thickness_exponent", "10000"}}), 48, 48));
    int covered = 0;
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 48; ++x) {
            if (gl_zero.at(x, y).a == 0.0f) continue;
            ++covered;
            EXPECT_EQ(gl_zero.at(x, y).r, 1.0f);
            EXPECT_GE(gl_huge.at(x, y).r, 0.0f);
            EXPECT_LE(gl_huge.at(x, y).r, 1.0f);
        }
    EXPECT_GT(covered, 100);
    for (int y = 0; y < 48; ++y)
        for (int x = 0; x < 48; ++x)
            if (cpu_zero.at(x, y).a > 0.0f) {
                EXPECT_EQ(cpu_zero.at(x, y).r, 1.0f);
            }
}

// n = 0: (N.H)^0 = 1 wherever N.L > 0, so the specular term is ws * ks * Is = 1 there.
TEST_F(EmpiricalNumerics, ShininessZeroGivesAConstantLobe) {
    const Scene scene = empirical_scene(test::builtin_mesh("sphere:4k"),
                                        {{"ambient", "0"},
                                         {"backlight", "0"},
                                         {"diffuse_contribution", "0"},
                                         {"specular_contribution", "1"},
                                         {"specular", "1"},
                                         {"shininess", "0"},
                                         {"light_direction", "0,0,1"}},
                                        33, 33);
    const auto [gl_image, cpu_image] = both(scene);
    EXPECT_FLOAT_EQ(gl_image.at(16, 16).r, 1.0f);
    EXPECT_FLOAT_EQ(cpu_image.at(16, 16).r, 1.0f);
}

// Zero-area triangles (repeated and collinear vertices) add no fragments and no hits:
// the image equals the one without them, on both paths.
TEST_F(EmpiricalNumerics, ZeroAreaTrianglesChangeNothing) {
    const auto clean = test::builtin_mesh("sphere:2k");
    Mesh dirty = *clean;
    dirty.name = "test:sphere_with_degenerates";
    dirty.content_hash += "+degenerate";
    const auto base = static_cast<unsigned>(dirty.positions.size());
    dirty.positions.push_back({0.0f, 0.0f, 1.0f});
    dirty.positions.push_back({0.5f, 0.0f, 1.0f});
    dirty.positions.push_back({1.0f, 0.0f, 1.0f});  // collinear with the two above
    dirty.normals.insert(dirty.normals.end(), 3, glm::vec3(0, 0, 1));
    dirty.triangles.push_back({base, base, base});
    dirty.triangles.push_back({base, base + 1, base + 2});
    dirty.triangles.push_back({0, 0, 1});
    const auto settings = std::vector<KnobAssignment>{{"ambient", "0"}};
    const Scene a = empirical_scene(clean, settings, 40, 40);
    Scene b = empirical_scene(std::make_shared<const Mesh>(dirty), settings, 40, 40);
    b.camera = a.camera;  // the extra points lie inside the bounding sphere anyway
    b.bounds = a.bounds;
    const auto [gl_a, cpu_a] = both(a);
    const auto [gl_b, cpu_b] = both(b);
    EXPECT_LT(test::max_abs_difference(gl_a, gl_b), 1e-6);
    EXPECT_LT(test::max_abs_difference(cpu_a, cpu_b), 1e-6);
}

// A key light exactly opposite the viewer makes L + V = 0 (no half vector): the specular
// term is then 0, not NaN.
TEST_F(EmpiricalNumerics, LightBehindTheObjectHasNoHalfVector) {
    const auto [gl_image, cpu_image] =
        both(empirical_scene(test::builtin_mesh("torus:2k"),
                             {{"ambient", "0"}, {"light_direction", "0,0,-1"}}, 40, 40));
    EXPECT_NEAR(test::max_abs_difference(gl_image, cpu_image), 0.0, 0.05);
}

}  // namespace
}  // namespace lucent

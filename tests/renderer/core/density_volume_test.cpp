// Density volumes: generators against their definitions, determinism and content hash,
// the contrast knob, the trilinear convention, the NRRD subset and its errors.
#include "renderer/core/density_volume.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>

namespace lucent {
namespace {

std::string temp_path(const std::string& name) {
    return (std::filesystem::temp_directory_path() /
            ("lucent_density_" + std::to_string(::getpid()) + "_" + name))
        .string();
}

std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const DensityError& e) {
        return e.what();
    }
    return "";
}

TEST(DensityVolume, ConstantIsConstant) {
    const auto v = make_density_volume("constant:value=0.25", 8, 1.0);
    EXPECT_EQ(v->size, glm::ivec3(8));
    EXPECT_TRUE(v->constant());
    EXPECT_FLOAT_EQ(v->mean, 0.25f);
    EXPECT_DOUBLE_EQ(v->sample({0.3, 0.9, 0.1}), 0.25);
}

TEST(DensityVolume, CubeIsTheCentredBoxOfFig58) {
    const auto v = make_density_volume("cube:size=0.5,inside=1,outside=0.1", 16, 1.0);
    // Voxel centres (i + 1/2) / 16: i = 4..11 lie within |t - 1/2| < 1/4.
    for (int i = 0; i < 16; ++i) {
        const bool inside = i >= 4 && i <= 11;
        EXPECT_FLOAT_EQ(v->voxel(i, 8, 8), inside ? 1.0f : 0.1f) << i;
    }
    EXPECT_FLOAT_EQ(v->voxel(8, 0, 8), 0.1f);
    EXPECT_FALSE(v->constant());
}

TEST(DensityVolume, GeneratorsAreDeterministicAndSeeded) {
    for (const char* spec : {"marble", "spheres", "layers:count=3,axis=x"}) {
        const auto a = make_density_volume(spec, 16, 1.0);
        const auto b = make_density_volume(spec, 16, 1.0);
        EXPECT_EQ(a->content_hash, b->content_hash) << spec;
        EXPECT_EQ(a->voxels, b->voxels) << spec;
        EXPECT_GE(a->min, 0.0f);
        EXPECT_LE(a->max, 1.0f);
        EXPECT_GT(a->max - a->min, 0.3f) << spec;  // actually heterogeneous
    }
    EXPECT_NE(make_density_volume("marble:seed=1", 16, 1.0)->content_hash,
              make_density_volume("marble:seed=2", 16, 1.0)->content_hash);
    // Layers along x: rho = 0.5 + 0.5 cos(2 pi N t_x), constant in y and z.
    const auto layers = make_density_volume("layers:count=3,axis=x", 16, 1.0);
    for (int i = 0; i < 16; ++i) {
        const double t = (i + 0.5) / 16.0;
        EXPECT_NEAR(layers->voxel(i, 3, 7), 0.5 + 0.5 * std::cos(2 * M_PI * 3 * t), 1e-6);
        EXPECT_EQ(layers->voxel(i, 3, 7), layers->voxel(i, 12, 1));
    }
}

TEST(DensityVolume, ContrastScalesAboutTheMeanAndZeroIsHomogeneous) {
    const auto full = make_density_volume("layers:count=2", 8, 1.0);
    const auto half = make_density_volume("layers:count=2", 8, 0.5);
    const auto none = make_density_volume("layers:count=2", 8, 0.0);
    EXPECT_TRUE(none->constant());
    EXPECT_NEAR(none->mean, full->mean, 1e-6);
    for (std::size_t i = 0; i < full->voxels.size(); ++i)
        EXPECT_NEAR(half->voxels[i], full->mean + 0.5 * (full->voxels[i] - full->mean),
                    1e-6);
    EXPECT_NE(full->content_hash, half->content_hash);
}

TEST(DensityVolume, TrilinearUsesVoxelCentresAndClampsToTheEdge) {
    std::vector<float> voxels(8, 0.0f);
    voxels[1] = 1.0f;  // voxel (1, 0, 0)
    const DensityVolume v = finish_density_volume({2, 2, 2}, voxels, "test");
    EXPECT_DOUBLE_EQ(v.sample({0.75, 0.25, 0.25}), 1.0);  // its centre
    EXPECT_DOUBLE_EQ(v.sample({0.5, 0.25, 0.25}), 0.5);   // halfway to voxel 0
    EXPECT_DOUBLE_EQ(v.sample({1.0, 0.25, 0.25}), 1.0);   // clamp to edge
    EXPECT_DOUBLE_EQ(v.sample({0.75, 0.5, 0.5}), 0.25);
}

TEST(DensityVolume, NrrdRoundTripsFloatAndReadsBytes) {
    const auto marble = make_density_volume("marble", 8, 1.0);
    const std::string path = temp_path("marble.nrrd");
    write_density_nrrd(*marble, path);
    const auto back = make_density_volume(path, 64, 1.0);  // files keep their size
    EXPECT_EQ(back->size, glm::ivec3(8));
    EXPECT_EQ(back->voxels, marble->voxels);
    EXPECT_EQ(back->content_hash, marble->content_hash);
    std::filesystem::remove(path);

    const std::string bytes = temp_path("bytes.nrrd");
    {
        std::ofstream out(bytes, std::ios::binary);
        out << "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 2 1 1\nencoding: raw\n\n";
        out.put(char(0)).put(char(255));
    }
    const auto b = make_density_volume(bytes, 64, 1.0);
    EXPECT_EQ(b->size, glm::ivec3(2, 1, 1));
    EXPECT_FLOAT_EQ(b->voxels[0], 0.0f);
    EXPECT_FLOAT_EQ(b->voxels[1], 1.0f);
    std::filesystem::remove(bytes);
}

// The volume cache keys a file on its bytes: the file rewritten with other voxels of
// the same size and given its old modification time back (as a coarse-timestamp file
// system, or a copy that keeps times, leaves it) is the new volume, and the old bytes
// again are the old volume.
TEST(DensityVolume, TheCacheSeesAFileRewrittenWithTheSameSizeAndModificationTime) {
    const std::string path = temp_path("rewritten.nrrd");
    const auto cube = make_density_volume("cube", 8, 1.0);
    const auto spheres = make_density_volume("spheres", 8, 1.0);
    ASSERT_NE(cube->content_hash, spheres->content_hash);
    KnobValues values;
    values.set("density", path);
    values.set("density_resolution", std::string("64"));
    values.set("density_contrast", 1.0);

    write_density_nrrd(*cube, path);
    const auto size = std::filesystem::file_size(path);
    const auto written = std::filesystem::last_write_time(path);
    EXPECT_EQ(density_from_knobs(values)->content_hash, cube->content_hash);
    EXPECT_EQ(density_from_knobs(values)->content_hash, cube->content_hash);  // cached

    write_density_nrrd(*spheres, path);
    std::filesystem::last_write_time(path, written);
    ASSERT_EQ(std::filesystem::file_size(path), size);
    ASSERT_EQ(std::filesystem::last_write_time(path), written);
    EXPECT_EQ(density_from_knobs(values)->content_hash, spheres->content_hash);

    write_density_nrrd(*cube, path);
    std::filesystem::last_write_time(path, written);
    EXPECT_EQ(density_from_knobs(values)->content_hash, cube->content_hash);
    std::filesystem::remove(path);
    EXPECT_NE(error_of([&] { density_from_knobs(values); }).find("cannot open"),
              std::string::npos);
}

TEST(DensityVolume, BadFilesNameTheFieldOrVoxel) {
    const std::string path = temp_path("bad.nrrd");
    const auto write = [&](const std::string& header, const std::vector<float>& data) {
        std::ofstream out(path, std::ios::binary);
        out << header << "\n";
        out.write(reinterpret_cast<const char*>(data.data()),
                  std::streamsize(data.size() * 4));
    };
    write(
        "NRRD0004\ntype: float\ndimension: 2\nsizes: 2 2\nencoding: raw\nendian: "
        "little\n",
        {});
    EXPECT_NE(
        error_of([&] { make_density_volume(path, 8, 1); }).find("field 'dimension'"),
        std::string::npos);
    write("NRRD0004\ntype: double\ndimension: 3\nsizes: 1 1 1\nencoding: raw\n", {});
    EXPECT_NE(error_of([&] { make_density_volume(path, 8, 1); }).find("field 'type'"),
              std::string::npos);
    write(
        "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 1 1\nencoding: gzip\nendian: "
        "little\n",
        {0, 0});
    EXPECT_NE(error_of([&] { make_density_volume(path, 8, 1); }).find("field 'encoding'"),
              std::string::npos);
    write(
        "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 1 1\nencoding: raw\nendian: "
        "little\n",
        {0.5f, std::nanf("")});
    EXPECT_NE(error_of([&] { make_density_volume(path, 8, 1); }).find("voxel (1, 0, 0)"),
              std::string::npos);
    write(
        "NRRD0004\ntype: float\ndimension: 3\nsizes: 4 1 1\nencoding: raw\nendian: "
        "little\n",
        {0.5f});
    EXPECT_NE(error_of([&] { make_density_volume(path, 8, 1); }).find("data:"),
              std::string::npos);
    std::filesystem::remove(path);
    EXPECT_NE(error_of([&] { make_density_volume(path, 8, 1); }).find("cannot open"),
              std::string::npos);
}

TEST(DensityVolume, BadSpecsNameTheParameter) {
    EXPECT_NE(
        error_of([] { parse_density_spec("marbel"); }).find("valid: constant, cube"),
        std::string::npos);
    EXPECT_NE(error_of([] { parse_density_spec("marble:freq=2"); }).find("'freq=2'"),
              std::string::npos);
    EXPECT_NE(error_of([] { parse_density_spec("cube:size=2"); }).find("size '2'"),
              std::string::npos);
    EXPECT_NE(error_of([] { parse_density_spec("spheres:count=2.5"); }).find("whole"),
              std::string::npos);
    EXPECT_EQ(error_of([] { parse_density_spec("layers:axis=y,count=3"); }), "");
    const std::string e = error_of([] { parse_density_spec("nope"); });
    EXPECT_EQ(e.rfind("density: ", 0), 0u) << e;
}

}  // namespace
}  // namespace lucent

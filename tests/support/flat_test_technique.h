#pragma once
// A technique that exists only in the tests (issue 27 item 2): registered by a test with
// TechniqueRegistration, it must reach every layer that asks the registry without any
// other edit. "test_flat" paints every pixel one colour, quantised on the CPU to
// `levels` steps per channel and uploaded as the plan's output; its CPU reference is the
// exact colour. So `levels` is a quality knob with a closed-form error,
// |c - round(c (L - 1)) / (L - 1)| per channel, for `lucent bench accuracy`. Its colour
// knob names a panel of its own, which the explorer must draw.
#include <cmath>
#include <string>
#include <vector>

#include "renderer/core/technique.h"

namespace lucent::test {

class FlatTestTechnique : public Technique {
public:
    static constexpr const char* kName = "test_flat";

    FlatTestTechnique() {
        Knob colour{"flat_colour", "the one colour of every pixel (linear rgb)",
                    KnobKind::rgb, 0.0,
                    1.0,           glm::dvec3(0.3, 0.5, 0.7)};
        colour.panel = "Flat test";
        colour.suggestions = {"0.25", "0.75"};
        knobs_ = {colour,
                  {"levels", "steps per channel the colour is quantised to",
                   KnobKind::integer, 2.0, 4096.0, 256}};
    }

    // The colour `levels` gives, as the GL path uploads it.
    static float quantised(double channel, int levels) {
        return static_cast<float>(std::round(channel * (levels - 1)) / (levels - 1));
    }

    std::string_view name() const override { return kName; }
    std::string_view description() const override {
        return "a flat colour (a technique defined by a test)";
    }
    const std::vector<Knob>& knobs() const override { return knobs_; }

    void plan(const Scene& scene, PlanBuilder& plan) const override {
        const glm::dvec3 colour = scene.values.vec3("flat_colour");
        const int levels = scene.values.integer("levels");
        const int width = scene.width, height = scene.height;
        plan.create("flat", ResourceFormat::rgba32f);
        Pass paint{"paint", "the quantised colour, made on the CPU", PassKind::upload};
        paint.writes = {"flat"};
        paint.data.content_hash = format_knob_value(colour) + "/" +
                                  std::to_string(levels) + "/" + std::to_string(width) +
                                  "x" + std::to_string(height);
        paint.data.produce = [=](const ProduceOptions&) {
            TextureData data;
            data.size = {width, height, 1};
            std::vector<float> texels(static_cast<std::size_t>(width) * height * 4, 1.0f);
            for (std::size_t i = 0; i < texels.size(); i += 4)
                for (int c = 0; c < 3; ++c) texels[i + c] = quantised(colour[c], levels);
            data.levels.push_back(std::move(texels));
            return data;
        };
        plan.add(std::move(paint));
        plan.set_output("flat");
    }

    Image render_reference(const Scene& scene) const override {
        const glm::dvec3 colour = scene.values.vec3("flat_colour");
        Image image(scene.width, scene.height);
        for (int y = 0; y < scene.height; ++y)
            for (int x = 0; x < scene.width; ++x)
                image.set(x, y, glm::vec4(glm::vec3(colour), 1.0f));
        return image;
    }

    std::vector<QualitySweep> quality_sweeps() const override {
        return {{"levels", {2, 5, 17, 257}, 4096}};
    }

private:
    std::vector<Knob> knobs_;
};

}  // namespace lucent::test

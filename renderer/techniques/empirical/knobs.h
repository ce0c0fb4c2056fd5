#pragma once
// Parameters of the empirical translucency shader (thesis Eq. 3.6, Table 4.3), as a plain
// aggregate with defaults, and the knob descriptions (ranges) read everywhere else.
#include <glm/glm.hpp>
#include <string>
#include <vector>

#include "renderer/core/knobs.h"
#include "renderer/core/scene.h"

namespace lucent::empirical {

struct Params {
    glm::dvec3 albedo{0.8, 0.55, 0.35};  // Kd, linear rgb in [0, 1]
    double ambient = 0.3;                // ka, [0, 10]
    double specular = 0.5;               // ks, [0, 10]
    double shininess = 64.0;             // n, [0, 10000]
    double diffuse_contribution = 0.6;   // wd, [0, 10]
    double specular_contribution = 1.0;  // ws, [0, 10]
    double backlight = 1.2;              // wb, [0, 10]; Table 4.3 row 1
    double thickness_exponent = 25.0;    // r, [0, 10000]; Table 4.3 row 1
    double diffuse_weight = 0.2;         // Kb, [0, 10]; Table 4.3 row 1
    int ao_rays = 320;                   // AO bake rays per vertex, [1, 4096]
    int blur_kernel = 5;                 // 1 (none), 3 or 5: back-layer smoothing kernel
    std::string depth_precision =
        "32f";  // "16", "24" or "32f": depth-layer texture format
    // "auto": on a closed mesh facing out the layers are the nearest front and back faces
    // (culling, no peel); otherwise, and always with "peel", the thesis's depth peeling.
    std::string layer_method = "auto";
    bool operator==(const Params&) const = default;
};

// The technique's knobs (material + technique), defaults taken from Params{}.
const std::vector<Knob>& knobs();
// Reads the typed parameters of a scene whose values were resolved from knobs().
Params params(const Scene& scene);

}  // namespace lucent::empirical

#pragma once
// What the Embree users of cpu/ share: a device that throws in one line when it cannot
// be made, the check after a scene commit, and the SSE flags Embree asks traversing
// threads to set. Internal to renderer/cpu.
#include <embree3/rtcore.h>

#include <string>
#include <vector>

#include "renderer/core/mesh.h"

namespace lucent::embree {

// A new device (Embree's defaults, or `config`, e.g. "quad_accel=bvh8.quad4v");
// std::runtime_error naming the error otherwise.
RTCDevice new_device(const char* config = nullptr);
// std::runtime_error "Embree: <what> failed (error N)" when the device holds an error.
void check(RTCDevice device, const std::string& what);
// std::invalid_argument naming the mesh when a triangle indexes past its positions.
void check_indices(const Mesh& mesh);

// A committed static scene (robust: rays through shared edges or vertices never slip
// between primitives; high build quality) of the mesh's triangles, or of `quads` (Embree
// quads over the mesh's positions) when given. std::runtime_error when Embree fails.
RTCScene build_scene(RTCDevice device, const Mesh& mesh,
                     const std::vector<glm::uvec4>* quads = nullptr);

// A ray for Embree with every mask bit set (tnear is inclusive in Embree).
RTCRay make_ray(glm::vec3 origin, glm::vec3 direction, float t_near, float t_far);
bool finite(glm::vec3 v);

// Sets the SSE control register's flush-to-zero and denormals-are-zero bits for its
// lifetime, as Embree's verbose start-up asks of every thread that traces: its stream
// traversal produces denormals, and without these bits `lucent bench ao` measured
// rtcOccluded1M 2.5x slower on the AO bake's rays (with the same answers, tested).
class FlushDenormals {
public:
    FlushDenormals();
    ~FlushDenormals();
    FlushDenormals(const FlushDenormals&) = delete;
    FlushDenormals& operator=(const FlushDenormals&) = delete;

private:
    unsigned saved_ = 0;
};

}  // namespace lucent::embree

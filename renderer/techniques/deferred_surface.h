#pragma once
// Deferred lighting of the nearest surface, shared by techniques whose final pass is
// costly per fragment (the dipole's sums over hundreds of samples, the HTSM's rays):
// a `surface` pass rasterises the mesh once into rgba32f textures (object position, w = 1
// where covered; object normal, w = AO; the eye normal), and the lighting pass becomes
// full screen, reading them (surface_inputs.glsl). On llvmpipe a small triangle's
// fragments cost a whole 4x4 block of lanes, so lighting each covered pixel once is
// several times cheaper; the stored values are the interpolated floats, so the image is
// the forward one bit for bit (each technique tests it).
#include <vector>

#include "renderer/core/frame_plan.h"

namespace lucent {

enum class SurfaceShading {
    deferred,  // what the techniques plan
    forward,   // the lighting pass rasterises the mesh (tests compare the two)
};

// Adds the `surface` pass (mesh.vert + surface.frag, with the `camera` uniforms) before
// `lighting`, a draw_mesh pass whose fragment shader includes surface_inputs.glsl and
// declares u_background, and turns `lighting` into the full-screen pass that reads the
// surface: DEFERRED, the surface textures bound, the vertex AO stream and the camera
// uniforms dropped, `colour` its only write. `eye_normal`: the shader uses the eye-space
// normal (WITH_EYE_NORMAL); `ambient_occlusion`: it uses the AO (WITH_AMBIENT).
void shade_deferred(PlanBuilder& plan, Pass& lighting, const std::vector<Uniform>& camera,
                    bool eye_normal, bool ambient_occlusion);

}  // namespace lucent

#version 450 core
// Depth-aware smoothing of the second layer (App. C.2.2, Eq. C.1) into its own texture,
// for the peeled path (smoothing.glsl has the kernel).
#include "techniques/empirical/shaders/smoothing.glsl"
uniform sampler2D back_depth;
uniform float u_falloff;
layout(location = 0) out float out_depth;

void main() { out_depth = smoothed_depth(back_depth, ivec2(gl_FragCoord.xy), u_falloff); }

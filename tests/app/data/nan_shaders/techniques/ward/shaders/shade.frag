#version 450 core
// Test shader (LUCENT_SHADER_DIR): every object pixel is NaN, as a shader bug would make it.
// It declares the uniforms the ward technique sets (unused), as a shader must: a name the
// shader lacks fails the pass.
uniform vec3 u_albedo;
uniform vec3 u_albedo_chroma;
uniform float u_albedo_luminance;
uniform float u_ambient;
uniform vec3 u_light_ambient;
uniform float u_diffuse;
uniform vec3 u_light_diffuse;
uniform vec3 u_light_direction;
uniform float u_specular_reflectance;
uniform float u_roughness;
uniform vec3 u_light_specular;
layout(location = 0) out vec4 out_colour;
void main() { out_colour = vec4(uintBitsToFloat(0x7fc00000u)); }

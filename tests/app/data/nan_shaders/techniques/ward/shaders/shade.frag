#version 450 core
// Test shader (LUCENT_SHADER_DIR): every object pixel is NaN, as a shader bug would make it.
layout(location = 0) out vec4 out_colour;
void main() { out_colour = vec4(uintBitsToFloat(0x7fc00000u)); }

#version 450 core
// One colour everywhere: blending tests combine two of these.
uniform vec4 colour;
out vec4 result;
void main() { result = colour; }

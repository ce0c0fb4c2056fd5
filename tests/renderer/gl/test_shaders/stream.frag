#version 450 core
// The interpolated stream value times u_scale; u_offset exists only in the WITH_OFFSET
// variant (elsewhere it is declared but compiled out).
in float v_value;
uniform float u_scale;
#ifdef WITH_OFFSET
uniform float u_offset;
#endif
out vec4 result;
void main() {
    result = vec4(v_value * u_scale, 0.0, 0.0, 1.0);
#ifdef WITH_OFFSET
    result.r += u_offset;
#endif
}

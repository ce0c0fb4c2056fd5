#version 450 core
// Positions are clip coordinates; a vertex stream at attribute 2 passes through.
layout(location = 0) in vec3 a_position;
layout(location = 2) in float a_value;
out float v_value;
void main() {
    v_value = a_value;
    gl_Position = vec4(a_position, 1.0);
}

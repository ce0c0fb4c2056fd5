#version 450 core
// Writes attachment k as (k + 1, x, y, 1) at window position (x, y): each attachment and
// the viewport's extent can be told apart on read-back.
layout(location = 0) out vec4 out0;
layout(location = 1) out vec4 out1;
layout(location = 2) out vec4 out2;
layout(location = 3) out vec4 out3;
void main() {
    out0 = vec4(1.0, gl_FragCoord.xy, 1.0);
    out1 = vec4(2.0, gl_FragCoord.xy, 1.0);
    out2 = vec4(3.0, gl_FragCoord.xy, 1.0);
    out3 = vec4(4.0, gl_FragCoord.xy, 1.0);
}

#version 450 core
// Second layer by depth peeling (App. B): a fragment at or in front of the first layer
// (plus epsilon) is discarded, so the depth test keeps the nearest surface behind it.
uniform sampler2D front_depth;
uniform float u_epsilon;

void main() {
    float front = texelFetch(front_depth, ivec2(gl_FragCoord.xy), 0).r;
    if (gl_FragCoord.z <= front + u_epsilon) discard;
}

#version 450 core
// Pixel (i, j) samples `source` at origin + step * (i, j, 0) and level `lod`, so a test
// reads sampler behaviour (filter, wrap, border, mip filter) straight off the image.
#ifdef VOLUME
uniform sampler3D source;
#else
uniform sampler2D source;
#endif
uniform vec3 origin;
uniform vec3 step;
uniform float lod;
out vec4 result;
void main() {
    vec3 p = origin + step * vec3(floor(gl_FragCoord.xy), 0.0);
#ifdef VOLUME
    result = textureLod(source, p, lod);
#else
    result = textureLod(source, p.xy, lod);
#endif
}

#version 450 core
// Shows a linear float image on screen: clamp to [0, 1] and sRGB-encode (IEC 61966-2-1),
// as write_image() does for PNG, so what the explorer shows is what `lucent render` writes.
in vec2 v_uv;
uniform sampler2D image;
layout(location = 0) out vec4 out_colour;

float encode(float v) {
    v = clamp(v, 0.0, 1.0);
    return v <= 0.0031308 ? 12.92 * v : 1.055 * pow(v, 1.0 / 2.4) - 0.055;
}

void main() {
    vec3 c = texture(image, v_uv).rgb;
    out_colour = vec4(encode(c.r), encode(c.g), encode(c.b), 1.0);
}

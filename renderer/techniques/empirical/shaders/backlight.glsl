// The backlight term of Eq. 3.6 (Eqs. 3.3, 3.4, 3.10), shared by shade.frag and
// add_backlight.frag so both compute it with the same operations.
uniform float u_near;
uniform float u_far;
uniform float u_diameter;
uniform float u_backlight;
uniform float u_thickness_exponent;
uniform float u_diffuse_weight;

// Eq. 3.3: window depth -> positive eye-space distance.
float eye_depth(float window_depth) {
    float ndc = 2.0 * window_depth - 1.0;
    return 2.0 * u_near * u_far / (u_far + u_near - ndc * (u_far - u_near));
}

// Thickness over the bounding-sphere diameter (Eq. 3.4), in [0, 1], from the window depths
// of the two layers. No second layer (open mesh, clipped back) counts as the full
// diameter: t = 1.
float thickness(float front, float back) {
    if (back >= 1.0 || !(u_diameter > 0.0)) return 1.0;
    float t = (eye_depth(back) - eye_depth(front)) / u_diameter;
    return clamp(t, 0.0, 1.0);
}

// Eq. 3.10: wb * (1 - t)^r * (Kd + Kb).
vec3 backlight_term(float front, float back, vec3 albedo) {
    return u_backlight * power(1.0 - thickness(front, back), u_thickness_exponent) *
           (albedo + vec3(u_diffuse_weight));
}

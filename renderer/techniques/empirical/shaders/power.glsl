// x^e with x^0 = 1 (also for x = 0) and negative bases treated as 0: GLSL's pow is
// undefined there.
float power(float x, float e) {
    if (e == 0.0) return 1.0;
    return x <= 0.0 ? 0.0 : pow(x, e);
}

#version 450 core
// One level of an exact box mip chain (PassKind::build_mips): each texel is the mean of
// its footprint in the level above, which is bound as the texture's only visible level.
// The footprint is 2x2, widened to 3 at the last column/row when the level above has an
// odd size, so no texel is dropped (a 3 x 2^k texture reduces exactly to 1).
uniform sampler2D source;
out vec4 result;

void main() {
    ivec2 source_size = textureSize(source, 0);
    ivec2 size = max(source_size / 2, ivec2(1));
    ivec2 texel = ivec2(gl_FragCoord.xy);
    ivec2 lo = 2 * texel;
    ivec2 hi = min(lo + 1, source_size - 1);
    if (texel.x == size.x - 1) hi.x = source_size.x - 1;
    if (texel.y == size.y - 1) hi.y = source_size.y - 1;
    vec4 sum = vec4(0.0);
    for (int y = lo.y; y <= hi.y; ++y)
        for (int x = lo.x; x <= hi.x; ++x) sum += texelFetch(source, ivec2(x, y), 0);
    result = sum / float((hi.x - lo.x + 1) * (hi.y - lo.y + 1));
}

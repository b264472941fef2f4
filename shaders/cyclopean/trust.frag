// Which semi-global disparities the local evidence supports (src/stereo/trust.rs holds the rule
// and its twin): a disparity is matched where the census matcher found the same within AGREE_PX,
// or found none and the census window is flat (no texture to disagree with); any other is
// inferred from the surface around it, and written 0 here. Integer grey levels and one f32
// subtraction: the GPU decides as the twin does, bit for bit.

layout(location = 0) out float o_disparity;

int grey(ivec2 q) {
    q = clamp(q, ivec2(0), u_size - 1);
    uvec3 c = uvec3(round(texelFetch(u_color, q, 0).rgb * 255.0));
    return int(c.r + c.g + c.b);
}

void main() {
    ivec2 p = ivec2(gl_FragCoord.xy);
    float semi_global = texelFetch(u_semi_global, p, 0).r;
    float census = texelFetch(u_census, p, 0).r;
    bool matched = false;
    if (semi_global > 0.0) {
        if (census > 0.0) {
            matched = abs(semi_global - census) <= AGREE_PX;
        } else {
            int lo = 765;
            int hi = 0;
            for (int dy = -HALF_H; dy <= HALF_H; ++dy) {
                for (int dx = -HALF_W; dx <= HALF_W; ++dx) {
                    int g = grey(p + ivec2(dx, dy));
                    lo = min(lo, g);
                    hi = max(hi, g);
                }
            }
            matched = hi - lo <= FLAT_GREY;
        }
    }
    o_disparity = matched ? semi_global : 0.0;
}

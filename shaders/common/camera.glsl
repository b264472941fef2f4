// Camera helpers shared by the cyclopean passes: points through 4x4 matrices, view rays, and
// NDC <-> window (pixel) positions. Pixel centres sit at integer + 0.5 in window coordinates.

vec3 transform_point(mat4 m, vec3 p) {
    vec4 q = m * vec4(p, 1.0);
    return q.xyz / q.w;
}

// View-space direction through ndc, scaled to GL z = -1, from the projection's ray basis (the
// inverse of its clip x, y and w rows, in a mat4's upper-left 3x3: src/camera/rays.rs). The
// depth conventions change only clip z and the row order only the sign of clip y, so every
// convention traces the same ray; unprojecting an NDC point through the inverse projection
// rounds differently under each (issue 47).
vec3 view_ray(mat4 ray_basis, vec2 ndc) {
    return mat3(ray_basis) * vec3(ndc, 1.0);
}

// NDC of the centre of pixel p (p counted from 0) in an image of `size` pixels, as
// (2 p + 1 - size) / size: the numerator is exact, so the mirrored pixel (the other row order)
// gets exactly the negated value.
vec2 ndc_of_pixel(vec2 p, vec2 size) {
    return (2.0 * p + 1.0 - size) / size;
}

// Window position (pixels, centres at + 0.5) of a clip-space point in an image of `size`.
vec2 window_of_clip(vec4 clip, vec2 size) {
    return (clip.xy / clip.w * 0.5 + 0.5) * size;
}

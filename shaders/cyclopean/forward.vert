// Forward warp of one eye into the middle camera. The eye's depth map is the refocus grid mesh
// (half-pixel ring, discontinuities broken on the CPU), drawn by vertex pulling: vertex 3t + k
// is corner k of kept triangle t (code = cell << 1 | tri from u_tris). A stereo warp is mostly a
// horizontal shift, so middle pixel centres land exactly on mesh edges row after row; each
// triangle is therefore pushed out by u_expand_px in the middle image (moved vertices stay on its
// plane) and the fragment shader keeps exactly the closed triangle: coverage does not depend on
// the fill rule or the row order. Eye clip (x, y, w) and the middle view distance are linear in
// 3-D, so they interpolate exactly.

// Parameters and images: shaders/cyclopean/forward_params.glsl (one block, both backends).

flat out ivec3 v_cell;         // cell i, j (image grid coordinates) and triangle
out vec3 v_eye_clip;           // eye clip (x, y, w)
out float v_middle_distance;

vec3 corner_world(ivec2 c) {
    vec2 img = vec2(vertex_pos(c.x, u_eye_size.x), vertex_pos(c.y, u_eye_size.y));
    ivec2 px = clamp(c - 1, ivec2(0), u_eye_size - 1);
#if !ROWS_TOP_DOWN
    img.y = float(u_eye_size.y) - 1.0 - img.y;
    px.y = u_eye_size.y - 1 - px.y;
#endif
    float dist = texelFetch(u_distance, px, 0).r;
    vec3 ray = view_ray(u_ray_basis_e, ndc_of_pixel(img, vec2(u_eye_size)));
    return transform_point(u_inv_view_e, ray * dist);
}

vec2 window_xy(vec3 world) {
    return window_of_clip(u_view_proj_m * vec4(world, 1.0), u_size_m);
}

void main() {
    ivec2 c;
    int tri, k;
    ivec2 corners[3];
    pulled_triangle(u_tris, u_eye_size.x + 1, c, tri, corners, k);
    vec3 p[3];
    for (int n = 0; n < 3; ++n) {
        p[n] = corner_world(corners[n]);
    }
    v_cell = ivec3(c, tri);
    vec3 point = p[k];

    vec4 clip0 = u_view_proj_m * vec4(p[0], 1.0);
    vec4 clip1 = u_view_proj_m * vec4(p[1], 1.0);
    vec4 clip2 = u_view_proj_m * vec4(p[2], 1.0);
    if (clip0.w > 0.0 && clip1.w > 0.0 && clip2.w > 0.0) {
        vec2 w0 = window_xy(p[k]);
        vec2 wn = window_xy(p[(k + 1) % 3]);
        vec2 wp = window_xy(p[(k + 2) % 3]);
        vec2 w_new;
        if (pushed_out_corner(w0, wn, wp, u_expand_px, w_new)) {
            // The middle ray through the moved point, met with the triangle's plane.
            vec2 ndc = w_new / u_size_m * 2.0 - 1.0;
            vec3 dir = view_ray(u_ray_basis_vp_m, ndc);  // world direction: the basis of view-proj
            vec3 nrm = cross(p[1] - p[0], p[2] - p[0]);
            float den = dot(nrm, dir);
            if (abs(den) > 1e-30) {
                float tt = dot(nrm, p[0] - u_middle_centre) / den;
                if (tt > 0.0) {
                    point = u_middle_centre + dir * tt;
                }
            }
        }
    }
    vec4 eye_clip = u_view_proj_e * vec4(point, 1.0);
    v_eye_clip = eye_clip.xyw;
    v_middle_distance = -(u_view_m * vec4(point, 1.0)).z;
    vec3 pushed = u_middle_centre + (point - u_middle_centre) * (1.0 + u_depth_bias);
    gl_Position = u_view_proj_m * vec4(pushed, 1.0);
}

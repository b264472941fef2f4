// Ray tracer of a scene description (src/scene/shapes.rs; f64 twin: src/scene/reference.rs
// `trace_gl_reference`). One ray per pixel centre from the camera's ray basis (the inverse of
// the view-projection's clip x, y, w rows), the same under every convention.
// Outputs colour, view distance (GL: -z_eye; 0 on a miss) and window depth under the
// conventions (the far value on a miss).

// Parameters: shaders/scene/scene_params.glsl (one block, both backends).

layout(location = 0) out vec4 o_color;
layout(location = 1) out float o_view_z;
layout(location = 2) out float o_device;

const float NONE = 3.0e38;
const float EDGE_SLACK = 1e-5;

bool ok(float t) {
    return t > 1e-9 && t < NONE;
}

float intersect(int i, vec3 o, vec3 d) {
    int kind = u_kind[i].x;
    if (kind == 0) {
        vec3 n = u_b[i].xyz;
        float den = dot(n, d);
        if (abs(den) <= 1e-12) {
            return NONE;
        }
        float t = dot(n, u_a[i].xyz - o) / den;
        vec3 p = o + d * t;
        // Closed bounds widened by EDGE_SLACK (src/scene/shapes.rs): planes sharing an edge
        // leave no crack where rounding puts a hit just outside both.
        vec3 ap = abs(p);
        float slack = EDGE_SLACK * (1.0 + max(ap.x, max(ap.y, ap.z)));
        bool inside = all(greaterThanEqual(p, u_c[i].xyz - slack)) && all(lessThanEqual(p, u_d[i].xyz + slack));
        return ok(t) && inside ? t : NONE;
    }
    if (kind == 1) {
        vec3 c = u_a[i].xyz - o;
        float r = u_a[i].w;
        float b = dot(d, c);
        float dd = dot(d, d);
        float disc = b * b - dd * (dot(c, c) - r * r);
        if (disc < 0.0) {
            return NONE;
        }
        float s = sqrt(disc);
        float t0 = (b - s) / dd;
        float t1 = (b + s) / dd;
        return ok(t0) ? t0 : (ok(t1) ? t1 : NONE);
    }
    vec3 lo = u_a[i].xyz;
    vec3 hi = u_b[i].xyz;
    float t0 = -NONE;
    float t1 = NONE;
    for (int k = 0; k < 3; ++k) {
        if (d[k] == 0.0) {
            if (o[k] <= lo[k] || o[k] >= hi[k]) {
                return NONE;
            }
            continue;
        }
        float a = (lo[k] - o[k]) / d[k];
        float b = (hi[k] - o[k]) / d[k];
        t0 = max(t0, min(a, b));
        t1 = min(t1, max(a, b));
    }
    if (t0 > t1) {
        return NONE;
    }
    return ok(t0) ? t0 : (ok(t1) ? t1 : NONE);
}

float stripes(float a, float f) {
    return 0.5 + 0.5 * sin(a * f);
}

// Same patterns as src/scene/mod.rs pattern_color.
vec3 pattern_color(int pattern, vec3 p) {
    float x = p.x, y = p.y, z = p.z;
    if (pattern == 0) {
        return vec3(200.0 * stripes(x, 3.0) + 30.0, 120.0 * stripes(y, 5.0) + 60.0, 180.0 * stripes(x + y, 1.7) + 40.0);
    }
    if (pattern == 1) {
        float checker = mod(floor(x * 2.0) + floor(z * 2.0), 2.0);
        return vec3(90.0 + 100.0 * checker * stripes(x, 11.0), 80.0 + 60.0 * stripes(z, 4.0), 70.0 + 40.0 * checker);
    }
    if (pattern == 2) {
        return vec3(230.0 * stripes(y, 9.0) + 20.0, 60.0 + 80.0 * stripes(x, 13.0), 40.0 + 30.0 * stripes(z, 7.0));
    }
    return vec3(40.0 + 200.0 * stripes(x - y, 20.0), 200.0 * stripes(y, 2.0) + 40.0, 90.0);
}

void main() {
    vec3 eye = u_eye;
    vec3 dir;
    if (u_ods == 1) {
        float lon = 2.0 * PI * gl_FragCoord.x / u_size.x - PI;
        float lat = 0.5 * PI - PI * gl_FragCoord.y / u_size.y;
        ods_ray(lon, lat, u_ods_centre, u_ods_radius, u_ods_fade_start, eye, dir);
    } else {
        // (2 p + 1 - n) / n with gl_FragCoord = p + 0.5: exact numerator, so mirrored rows get
        // exactly negated NDC and both row orders the same ray (src/camera/rays.rs pixel_ndc).
        vec2 ndc = (2.0 * gl_FragCoord.xy - u_size) / u_size;
        dir = (u_ray_basis * vec4(ndc, 1.0, 0.0)).xyz;
    }
    float best = NONE;
    int hit = -1;
    for (int i = 0; i < u_count; ++i) {
        float t = intersect(i, eye, dir);
        if (t < best) {
            best = t;
            hit = i;
        }
    }
    if (hit < 0) {
        o_color = vec4(0.0);
        o_view_z = 0.0;
        o_device = window_depth_of_ndc_z(NDC_Z_FAR);
        return;
    }
    vec3 p = eye + dir * best;
    o_color = vec4(clamp(floor(pattern_color(u_kind[hit].y, p) + 0.5), 0.0, 255.0) / 255.0, 1.0);
    if (u_ods == 1) {
        o_view_z = best;  // distance along the unit ray
        o_device = 0.0;
        return;
    }
    o_view_z = -(u_view * vec4(p, 1.0)).z;
    vec4 clip = u_view_proj * vec4(p, 1.0);
    o_device = window_depth_of_ndc_z(clip.z / clip.w);
}

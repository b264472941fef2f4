// ODS equirect stitch of six over-wide cube faces, one eye per draw (seed 001 and the two
// alternatives in src/stitch/mod.rs). The f64 twin is src/stitch/reference.rs: keep in step.
// Defines: METHOD (0 blend, 1 border weight, 2 reproject), REPROJECT_STEPS.
// Outputs: colour, and the distance along the ODS ray from its origin on the viewing circle to
// the surface the colour came from (0 = sky); a target without that attachment drops it.

// Parameters and atlases: shaders/stitch/stitch_params.glsl (one block, both backends).

layout(location = 0) out vec4 o_color;
layout(location = 1) out float o_distance;

const float FAR_DISTANCE = 500.0;
const float TOLERANCE_PX = 1.5;
const float AGREE_REL = 0.03;

vec3 face_axis(int k) {
    return vec3(u_rot[k][2][0], u_rot[k][2][1], u_rot[k][2][2]);
}

// Face pixel of a world direction; false unless in front of the face.
bool project_dir(int k, vec3 v, out vec2 uv) {
    vec3 q = v * mat3(u_rot[k]);  // R^T v
    if (!(q.z > 1e-2 * length(q))) {
        uv = vec2(0.0);
        return false;
    }
    uv = u_f * q.xy / q.z + u_c;
    return true;
}

bool project_point(int k, vec3 x, out vec2 uv) {
    return project_dir(k, x - u_eye[k].xyz, uv);
}

bool inside(vec2 uv) {
    float hi = float(u_n) - 0.5;
    return all(greaterThanEqual(uv, vec2(-0.5))) && all(lessThanEqual(uv, vec2(hi)));
}

// Atlas texel of face k's texel t (t.y counted from the face's top row).
ivec2 atlas(int k, ivec2 t) {
#if ROWS_TOP_DOWN
    return ivec2(t.x + k * u_n, t.y);
#else
    return ivec2(t.x + k * u_n, u_n - 1 - t.y);
#endif
}

vec3 texel(int k, ivec2 t) {
    t = clamp(t, ivec2(0), ivec2(u_n - 1));
    return texelFetch(u_color, atlas(k, t), 0).rgb * 255.0;
}

vec3 face_color(int k, vec2 uv) {
    uv = clamp(uv, vec2(0.0), vec2(float(u_n - 1)));
    vec2 i0 = floor(uv);
    vec2 fr = uv - i0;
    ivec2 t = ivec2(i0);
    return bilinear(texel(k, t), texel(k, t + ivec2(1, 0)), texel(k, t + ivec2(0, 1)), texel(k, t + ivec2(1, 1)), fr);
}

// View Z at the nearest texel, or -1 for background.
float face_depth(int k, vec2 uv) {
    ivec2 t = clamp(ivec2(floor(uv + 0.5)), ivec2(0), ivec2(u_n - 1));
    float z = texelFetch(u_depth, atlas(k, t), 0).r;
    return (!isnan(z) && !isinf(z) && z > 0.0) ? z : -1.0;
}

vec3 face_ray(int k, vec2 uv) {
    return mat3(u_rot[k]) * vec3((uv - u_c) / u_f, 1.0);
}

vec3 unproject(int k, vec2 uv, float z) {
    vec3 ray = face_ray(k, uv);
    return z > 0.0 ? u_eye[k].xyz + ray * z : u_eye[k].xyz + normalize(ray) * FAR_DISTANCE;
}

vec3 plain(int k, vec3 d) {
    vec2 uv;
    return project_dir(k, d, uv) ? face_color(k, uv) : vec3(0.0);
}

struct Pair {
    int primary, a, b;
    float w;
    bool in_band;
};

Pair pair_weight(vec3 d) {
    float comp[6];
    for (int k = 0; k < 6; ++k) {
        comp[k] = dot(d, face_axis(k));
    }
    int p = 0;
    for (int k = 1; k < 6; ++k) {
        if (comp[k] > comp[p]) p = k;
    }
    int s = -1;
    for (int k = 0; k < 6; ++k) {
        if (k != p && k != (p ^ 1) && (s < 0 || comp[k] > comp[s])) s = k;
    }
    Pair r;
    r.primary = p;
    r.a = min(p, s);
    r.b = max(p, s);
    float gamma = atan(comp[r.b], comp[r.a]) - 0.25 * PI;
    r.in_band = abs(gamma) < u_overlap;
    r.w = r.in_band ? clamp(0.5 + gamma / (2.0 * u_overlap), 0.0, 1.0) : (p == r.b ? 1.0 : 0.0);
    return r;
}

vec3 blend(Pair pw, vec3 d) {
    return mix(plain(pw.a, d), plain(pw.b, d), pw.w);
}

// Distance along the ODS ray (o, d) to the surface face k sees along d; -1 for none.
float face_range(int k, vec3 o, vec3 d) {
    vec2 uv;
    if (!project_dir(k, d, uv)) {
        return -1.0;
    }
    float z = face_depth(k, uv);
    return z > 0.0 ? dot(unproject(k, uv, z) - o, d) : -1.0;
}

// The pair's distance where the colour is a mix of both faces along d (blend, border weight,
// reproject's last resort): both weighted when their surfaces agree, else the heavier face's
// (w < 0.5: A), so that no distance lies between two surfaces.
float mix_range(Pair pw, vec3 o, vec3 d) {
    float ta = face_range(pw.a, o, d);
    float tb = face_range(pw.b, o, d);
    if (ta > 0.0 && tb > 0.0 && abs(ta - tb) <= AGREE_REL * min(ta, tb)) {
        return ta * (1.0 - pw.w) + tb * pw.w;
    }
    return pw.w < 0.5 ? ta : tb;
}

// Seed 001 "stitch with border weight"; a = the seed's +Z face (cPos), b = its -X face (cPosMX).
vec3 border_weight(int a, int b, float w, vec3 d) {
    vec3 cpos = u_eye[a].xyz;
    vec3 cposmx = u_eye[b].xyz;
    vec3 wpos = cpos + d * FAR_DISTANCE;
    vec2 pwz, pwx;
    if (!project_point(a, wpos, pwz) || !project_point(b, wpos, pwx)) {
        return mix(plain(a, d), plain(b, d), w);
    }
    float za = face_depth(a, pwz);
    float zb = face_depth(b, pwx);
    vec3 base_col = face_color(a, pwz);
    vec3 col2_plain = face_color(b, pwx);
    if (za < 0.0 && zb < 0.0) {
        return (base_col + col2_plain) * 0.5;
    }
    vec3 dd = cpos - cposmx;
    vec3 iwpos = unproject(b, pwx, zb);
    vec3 iwpos2 = normalize((iwpos - cposmx) + dd) * FAR_DISTANCE + cpos;
    vec3 wpos2 = iwpos * w + iwpos2 * (1.0 - w);
    vec2 uv;
    vec3 col2 = project_point(b, wpos2, uv) ? face_color(b, uv) : col2_plain;
    vec3 iwzpos = unproject(a, pwz, za);
    vec3 iwzpos2 = normalize((iwzpos - cpos) - dd) * FAR_DISTANCE + cposmx;
    vec3 wzpos2 = iwzpos * (1.0 - w) + iwzpos2 * w;
    vec3 col1 = project_point(a, wzpos2, uv) ? face_color(a, uv) : base_col;
    vec3 col = col2 * w + col1 * (1.0 - w);
    if (w < 0.5) {
        float w2 = w / 0.5;
        col = base_col * (1.0 - w2) + col * w2;
    }
    return col;
}

// kind: 0 invalid, 1 background, 2 surface.
struct Candidate {
    int kind;
    float t;
    vec3 color;
};

Candidate walk(int k, vec3 o, vec3 d) {
    Candidate invalid = Candidate(0, 0.0, vec3(0.0));
    vec2 uv;
    if (!project_dir(k, d, uv)) {
        return invalid;
    }
    float z0 = face_depth(k, uv);
    float t = z0 > 0.0 ? dot(unproject(k, uv, z0) - o, d) : FAR_DISTANCE;
    for (int step = 0; step <= REPROJECT_STEPS; ++step) {
        if (!(t > 1e-6)) {
            return invalid;
        }
        if (!project_point(k, o + d * t, uv) || !inside(uv)) {
            return invalid;
        }
        float z = face_depth(k, uv);
        if (z < 0.0) {
            return Candidate(1, 0.0, face_color(k, uv));
        }
        vec3 y = unproject(k, uv, z);
        vec3 yo = y - o;
        float t_new = dot(yo, d);
        if (step == REPROJECT_STEPS) {
            vec3 perp = yo - d * t_new;
            if (length(perp) > TOLERANCE_PX * length(y - u_eye[k].xyz) / u_f) {
                return invalid;
            }
            return Candidate(2, t_new, face_color(k, uv));
        }
        t = t_new;
    }
    return invalid;
}

// Colour and (in t) distance; t = 0 where only background is seen.
vec3 reproject(Pair pw, vec3 o, vec3 d, out float t) {
    Candidate ca = walk(pw.a, o, d);
    Candidate cb = walk(pw.b, o, d);
    float wa = 1.0 - pw.w;
    float wb = pw.w;
    if (ca.kind == 2 && cb.kind == 2) {
        if (abs(ca.t - cb.t) <= AGREE_REL * min(ca.t, cb.t)) {
            t = ca.t * wa + cb.t * wb;
            return ca.color * wa + cb.color * wb;
        }
        t = min(ca.t, cb.t);
        return ca.t <= cb.t ? ca.color : cb.color;
    }
    if (ca.kind == 2) {
        t = ca.t;
        return ca.color;
    }
    if (cb.kind == 2) {
        t = cb.t;
        return cb.color;
    }
    t = 0.0;
    float total = (ca.kind == 1 ? wa : 0.0) + (cb.kind == 1 ? wb : 0.0);
    vec3 sum = (ca.kind == 1 ? ca.color * wa : vec3(0.0)) + (cb.kind == 1 ? cb.color * wb : vec3(0.0));
    if (total > 0.0) return sum / total;
    if (ca.kind == 1 && cb.kind == 1) return 0.5 * (ca.color + cb.color);
    if (ca.kind == 1) return ca.color;
    if (cb.kind == 1) return cb.color;
    t = mix_range(pw, o, d);
    return blend(pw, d);
}

void main() {
    // Equirect pixel (column, row from the top) of this fragment in its eye's half.
    vec2 px = vec2(floor(gl_FragCoord.x), floor(gl_FragCoord.y) - float(u_row0));
#if !ROWS_TOP_DOWN
    px.y = float(u_size.y - 1) - px.y;
#endif
    float lon = 2.0 * PI * (px.x + 0.5) / float(u_size.x) - PI;
    float lat = 0.5 * PI - PI * (px.y + 0.5) / float(u_size.y);
    vec3 o, d;
    ods_ray(lon, lat, u_centre.xyz, u_side * u_half_ipd, u_fade_start, o, d);
    Pair pw = pair_weight(d);
#if METHOD == 0
    vec3 c = blend(pw, d);
    float t = mix_range(pw, o, d);
#elif METHOD == 1
    vec3 c = pw.in_band ? border_weight(pw.a, pw.b, pw.w, d) : plain(pw.primary, d);
    // The seed's warps move colour, not surfaces: the faces' surfaces along d, as blend.
    float t = mix_range(pw, o, d);
#else
    float t;
    vec3 c = reproject(pw, o, d, t);
#endif
    o_color = vec4(clamp(c, 0.0, 255.0) / 255.0, 1.0);
    o_distance = max(t, 0.0);
}

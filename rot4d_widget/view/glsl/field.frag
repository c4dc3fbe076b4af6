// The page's own picture of a field's cut (issue 36): a ray through one box (field.vert), each
// sample point X of the slice turned into the data's 4-D index coordinates g = a_g0 + a_gx X.x +
// a_gy X.y + a_gz X.z (the page's predicted rotation and c0, page/raycast.js) and the value read
// there from the 4-D data (field_data.glsl: quadrilinear).  The renderings follow the kernel's
// pictures (volume.frag for the ray-cast ones, rot4d_widget/keep/volume.py's rules; the surface
// layer for isosurfaces), so the page's picture of a state is the kernel's to a few levels:
//   u_mode 0 "volume": samples every u_step kernel grid spacings at the middle of each piece of
//          the ray in the kernel's grid box, a sample counting where its kernel grid cell's eight
//          nodes lie in the data's box (as the kernel's grid is NaN outside it) and its data are
//          finite; emission-absorption front to back, extinction u_density / (longest side).
//          Blocks of the data below the colour limits are skipped (field_data.glsl's block
//          ranges: their samples add nothing), the samples left where they were.
//   u_mode 1 "mip": the largest value along the ray, opaque (blocks below the largest so far
//          skipped).
//   u_mode 2 "sections": the nearest of the planes x, y, z = lo + u_sections * span where a
//          sample counts, opaque.
//   u_mode 3 "surface": the isosurfaces of every level (u_sign: +1 encloses f >= level, -1
//          f <= level; a value not finite is never enclosed), closed on the data box's faces
//          (u_caps), marched every u_march scene units from where the ray enters the data's box,
//          each crossing refined by bisection and a last linear step, shaded by the 4-D gradient projected into the
//          slice (lighting.glsl, as the surface layer); one level opaque at its first crossing
//          (its depth written), several blended front to back at u_opacity each.  Blocks no level
//          crosses are skipped whole.
// Values are in [0, 1] over the copy's range; u_clim, u_levels are the kernel's, in those units.
// u_output 1 (tests): the first surface hit's distance from the eye, t / u_depth_scale in 24
// bits (r, g, b high to low), a = 1 where hit.
// @include field_data.glsl
uniform sampler2D u_lut;
// The rendering is compiled in (FIELD_MODE, set by page/fieldpicture.js: one program a rendering,
// each without the others' code, which software WebGL runs faster); u_mode without it.
#ifdef FIELD_MODE
const float u_mode = float(FIELD_MODE);
#else
uniform float u_mode;
#endif
uniform vec2 u_clim;
uniform vec3 u_sections;
uniform float u_density;
uniform float u_step;
uniform float u_march;
uniform float u_sign;
uniform float u_caps;
uniform float u_opacity;
uniform float u_nlevels;
uniform float u_levels[8];
uniform vec3 u_level_rgb[8];
uniform vec3 u_box_rgb[64];
uniform float u_box_colours;
uniform mat4 u_view;
uniform mat3 u_normal_view;
uniform mat4 projectionMatrix;
uniform float u_output;
uniform float u_depth_scale;
varying vec3 v_pos;
varying vec3 v_eye;
varying vec4 v_g0;
varying vec4 v_gx;
varying vec4 v_gy;
varying vec4 v_gz;
varying vec3 v_lo;
varying vec3 v_span;
varying vec2 v_cell;
// @include lighting.glsl

const int MAX_STEPS = 1024;
const int MAX_LEVELS = 8;
const int REFINE = 4;

vec4 gAt(vec3 x) {
    return v_g0 + v_gx * x.x + v_gy * x.y + v_gz * x.z;
}

vec3 lut(float x) {
    float i = min(floor(clamp(x, 0.0, 1.0) * 256.0), 255.0);
    return texture2D(u_lut, vec2((i + 0.5) / 256.0, 0.5)).rgb;
}

float ramp(float v) {
    return clamp((v - u_clim.x) / (u_clim.y - u_clim.x), 0.0, 1.0);
}

// true where the kernel's grid cell holding x has its eight nodes in the data's box (the kernel's
// grid is NaN outside it, and a sample counts only where its cell's nodes are finite)
bool cellInside(vec3 x) {
    float h = v_cell.x;
    vec3 n = floor(v_span / h + 0.5);  // cells along each axis
    vec3 c = clamp(floor((x - v_lo) / h), vec3(0.0), max(n - 1.0, vec3(0.0)));
    vec4 g = gAt(v_lo + h * c);
    vec4 lo = g + h * (min(v_gx, 0.0) + min(v_gy, 0.0) + min(v_gz, 0.0));
    vec4 hi = g + h * (max(v_gx, 0.0) + max(v_gy, 0.0) + max(v_gz, 0.0));
    vec4 tol = vec4(1e-4);
    return all(greaterThanEqual(lo, -tol)) && all(lessThanEqual(hi, u_shape - 1.0 + tol));
}

// (value, 1 if it counts) at x for the ray-cast renderings
vec2 sampleAt(vec3 x) {
    if (!cellInside(x)) return vec2(0.0, 0.0);
    return field(gAt(x));
}

// s > 0 inside level i's surface; a value not finite is outside
float side(vec2 s, float level) {
    return s.y > 0.5 ? u_sign * (s.x - level) : -1.0;
}

// the 4-D gradient projected into the slice, d(value)/dX = sum_j d(value)/dg_j dg_j/dX: read as the
// value's change along each of the slice's axes X (forward differences of about half a node spacing
// from the hit's value v): three reads, where the 4-D gradient's central differences take eight
vec3 gradientAt(vec4 g, float v) {
    vec3 h = 0.5 / max(vec3(length(v_gx), length(v_gy), length(v_gz)), vec3(1e-6));
    return vec3(field(g + h.x * v_gx).x - v,
                field(g + h.y * v_gy).x - v,
                field(g + h.z * v_gz).x - v) / h;
}

vec3 shadeAt(vec3 x, vec3 normal, vec3 rgb) {
    vec3 p = (u_view * vec4(x, 1.0)).xyz;
    vec3 n = normalize(u_normal_view * normal);
    if (dot(n, p) > 0.0) n = -n;  // the side facing the viewer, as the surface layer lights it
    return shade(rgb, n, p);
}

float depthOf(vec3 x) {
    vec4 clip = projectionMatrix * (u_view * vec4(x, 1.0));
    return clamp(0.5 * clip.z / clip.w + 0.5, 0.0, 1.0);
}

vec3 levelRgb(int i, vec3 boxRgb) {
    return u_box_colours > 0.5 ? boxRgb : u_level_rgb[i];
}

void main() {
    vec3 dir = normalize(v_pos - v_eye);
    vec3 d = mix(dir, vec3(1e-12), vec3(equal(dir, vec3(0.0))));
    vec3 top = v_lo + v_span;
    vec3 t1 = (v_lo - v_eye) / d;
    vec3 t2 = (top - v_eye) / d;
    vec3 tn = min(t1, t2);
    vec3 tf = max(t1, t2);
    float t_in = max(max(max(tn.x, tn.y), tn.z), 0.0);
    float t_out = min(min(tf.x, tf.y), tf.z);
    if (!(t_out > t_in)) discard;
    gl_FragDepth = gl_FragCoord.z;
    if (u_mode > 2.5) {
        // the data's box along the ray: 0 <= gE + t gD <= n - 1 on every axis
        vec4 gE = gAt(v_eye);
        vec4 gD = v_gx * dir.x + v_gy * dir.y + v_gz * dir.z;
        float b_in = t_in, b_out = t_out;
        int face = -1;
        for (int j = 0; j < 4; j++) {
            float e = gE[j], r = gD[j], top4 = u_shape[j] - 1.0;
            if (abs(r) < 1e-9) {
                if (e < -1e-4 || e > top4 + 1e-4) discard;
                continue;
            }
            float a = (0.0 - e) / r, b = (top4 - e) / r;
            float lo = min(a, b), hi = max(a, b);
            if (lo > b_in) {
                b_in = lo;
                face = j;
            }
            b_out = min(b_out, hi);
        }
        if (!(b_out > b_in)) discard;
        int nl = int(u_nlevels + 0.5);
        vec3 boxRgb = u_box_rgb[int(v_cell.y + 0.5)];
        vec4 acc = vec4(0.0);  // premultiplied colour, alpha (front to back)
        float hitT = -1.0;
        // caps where the ray enters: the levels whose inside holds there
        vec3 x0 = v_eye + b_in * dir;
        vec2 s0 = field(gAt(x0));
        vec4 prev = vec4(-1.0);
        vec4 prev2 = vec4(-1.0);  // levels 4..7
        for (int i = 0; i < MAX_LEVELS; i++) {
            if (i >= nl) break;
            float s = side(s0, u_levels[i]);
            if (i < 4) prev[i] = s; else prev2[i - 4] = s;
            if (u_caps > 0.5 && s >= 0.0 && face >= 0) {
                vec3 nrm = vec3(v_gx[face], v_gy[face], v_gz[face]);
                vec3 c = shadeAt(x0, nrm, levelRgb(i, boxRgb));
                acc += (1.0 - acc.a) * u_opacity * vec4(c, 1.0);
                if (hitT < 0.0) hitT = b_in;
            }
        }
        float tPrev = b_in;
        float blockEnd = -1.0;  // the block of the last step's start lasts to here along the ray
        bool crossed = true;  // some level crosses that block
        for (int k = 1; k < MAX_STEPS; k++) {
            if (acc.a > 0.996 || tPrev >= b_out) break;
            if (tPrev >= blockEnd) {  // (steps are shorter than blocks: asked once a block)
                vec4 blk = blockOf(gE + tPrev * gD);
                vec2 range = blockRange(blk);
                crossed = false;
                for (int i = 0; i < MAX_LEVELS; i++) {
                    if (i >= nl) break;
                    crossed = crossed || (u_levels[i] >= range.x && u_levels[i] <= range.y);
                }
                blockEnd = blockExit(gE, gD, blk);
            }
            // a block no level crosses: on to where the ray leaves it (no side changes there)
            if (!crossed) {
                tPrev = min(max(blockEnd, tPrev) + 1e-4 * u_march, b_out);
                continue;
            }
            float t = min(tPrev + u_march, b_out);
            vec2 sv = field(gAt(v_eye + t * dir));
            for (int i = 0; i < MAX_LEVELS; i++) {
                if (i >= nl) break;
                float level = u_levels[i];
                float s = side(sv, level);
                float p = i < 4 ? prev[i] : prev2[i - 4];
                if ((s >= 0.0) != (p >= 0.0)) {
                    // refine: the crossing between tPrev (side p) and t (side s), bisected
                    // REFINE times, then where the side's line crosses zero in what is left
                    float a = tPrev, b = t, sa = p, sb = s;
                    for (int r = 0; r < REFINE; r++) {
                        float m = 0.5 * (a + b);
                        float sm = side(field(gAt(v_eye + m * dir)), level);
                        if ((sm >= 0.0) == (p >= 0.0)) {
                            a = m;
                            sa = sm;
                        } else {
                            b = m;
                            sb = sm;
                        }
                    }
                    float th = mix(a, b, clamp(sa / (sa - sb), 0.0, 1.0));  // (sa, sb on either side of 0)
                    vec3 xh = v_eye + th * dir;
                    vec4 gh = gAt(xh);
                    vec3 c = shadeAt(xh, gradientAt(gh, field(gh).x), levelRgb(i, boxRgb));
                    acc += (1.0 - acc.a) * u_opacity * vec4(c, 1.0);
                    if (hitT < 0.0) hitT = th;
                }
                if (i < 4) prev[i] = s; else prev2[i - 4] = s;
            }
            tPrev = t;
        }
        // caps where the ray leaves: the levels still inside there
        if (u_caps > 0.5 && acc.a <= 0.996) {
            vec3 x1 = v_eye + b_out * dir;
            for (int i = 0; i < MAX_LEVELS; i++) {
                if (i >= nl) break;
                float p = i < 4 ? prev[i] : prev2[i - 4];
                if (p >= 0.0) {
                    vec4 g1 = gAt(x1);
                    // the face the ray leaves by: the axis whose bound it reaches last
                    int out_face = 0;
                    float best = 1e30;
                    for (int j = 0; j < 4; j++) {
                        float r = gD[j];
                        if (abs(r) < 1e-9) continue;
                        float lim = r > 0.0 ? u_shape[j] - 1.0 - g1[j] : g1[j];
                        if (abs(lim) < best) {
                            best = abs(lim);
                            out_face = j;
                        }
                    }
                    vec3 nrm = vec3(v_gx[out_face], v_gy[out_face], v_gz[out_face]);
                    vec3 c = shadeAt(x1, nrm, levelRgb(i, boxRgb));
                    acc += (1.0 - acc.a) * u_opacity * vec4(c, 1.0);
                    if (hitT < 0.0) hitT = b_out;
                }
            }
        }
        if (hitT < 0.0 || acc.a <= 0.0) discard;
        if (u_output > 0.5) {
            float q = floor(clamp(hitT / u_depth_scale, 0.0, 1.0) * 16777215.0);
            float r = floor(q / 65536.0);
            float g = floor((q - r * 65536.0) / 256.0);
            gl_FragColor = vec4(r / 255.0, g / 255.0, (q - r * 65536.0 - g * 256.0) / 255.0, 1.0);
            gl_FragDepth = depthOf(v_eye + hitT * dir);
            return;
        }
        if (u_opacity > 0.999) gl_FragDepth = depthOf(v_eye + hitT * dir);
        gl_FragColor = vec4(acc.rgb / acc.a, acc.a);
        return;
    }
    if (u_mode > 1.5) {
        vec3 plane = v_lo + u_sections * v_span;
        vec3 tp = (plane - v_eye) / d;
        float best = 1e30;
        float x = 0.0;
        for (int a = 0; a < 3; a++) {
            float t = a == 0 ? tp.x : (a == 1 ? tp.y : tp.z);
            if (t >= t_in && t <= t_out && t < best) {
                vec2 s = sampleAt(v_eye + t * dir);
                if (s.y > 0.5) {
                    best = t;
                    x = ramp(s.x);
                }
            }
        }
        if (best > 1e29) discard;
        gl_FragColor = vec4(lut(x), 1.0);
        return;
    }
    float dt = u_step * v_cell.x;
    float extinction = u_density / max(max(v_span.x, v_span.y), v_span.z);
    bool mip = u_mode > 0.5;
    float best = -1.0;
    vec3 colour = vec3(0.0);
    float trans = 1.0;
    vec4 gE = gAt(v_eye);
    vec4 gD = v_gx * dir.x + v_gy * dir.y + v_gz * dir.z;
    // where every kernel grid cell a sample can lie in is inside the data's box (its corners are
    // within a cell's reach of the sample on each axis): there cellInside need not be asked
    vec4 reach = v_cell.x * (abs(v_gx) + abs(v_gy) + abs(v_gz));
    float s_in = t_in, s_out = t_out;
    for (int j = 0; j < 4; j++) {
        float e = gE[j], r = gD[j], lo = reach[j], hi = u_shape[j] - 1.0 - reach[j];
        if (abs(r) < 1e-9) {
            if (e < lo || e > hi) s_out = -1.0;
            continue;
        }
        float a = (lo - e) / r, b = (hi - e) / r;
        s_in = max(s_in, min(a, b));
        s_out = min(s_out, max(a, b));
    }
    float fi = 0.0;  // the sample's index: samples stay where the kernel's are, skipped or not
    // The block ranges are asked only where samples lie closer than half a block along the ray
    // (index units, the longest axis's): at longer steps nearly every sample is in a block of its
    // own, and the lookup and exit cost what the sample it may save would (the held picture of a
    // 64^4 field samples every 4 cells: docs/performance.md, "Turning a field").
    bool skips = dt * max(max(abs(gD.x), abs(gD.y)), max(abs(gD.z), abs(gD.w))) < 0.5 * u_block;
    float blockEnd = skips ? -1.0 : 1e30;  // the block of the last sample lasts to here along the ray
    float peak = 1.0;  // the greatest value of that block, on the colour ramp
    for (int i = 0; i < MAX_STEPS; i++) {
        float start = t_in + fi * dt;
        if (start >= t_out) break;
        float piece = min(dt, t_out - start);
        float tm = start + 0.5 * piece;
        // a block that adds nothing (below the colour limits; for mip, below the brightest so far):
        // on to the first sample past where the ray leaves it
        if (tm >= blockEnd) {
            vec4 blk = blockOf(gE + tm * gD);
            peak = ramp(blockRange(blk).y);
            blockEnd = blockExit(gE, gD, blk);
        }
        if (mip ? peak <= best : peak < 0.5 / 255.0) {  // (below half a level of the kernel's 8 bits: 0 there)
            fi = max(fi + 1.0, ceil((blockEnd - t_in) / dt - 0.5));
            continue;
        }
        fi += 1.0;
        bool counts = (tm >= s_in && tm <= s_out) || cellInside(v_eye + tm * dir);
        vec2 s = counts ? field(gE + tm * gD) : vec2(0.0);
        if (s.y > 0.5) {
            float x = ramp(s.x);
            if (mip) {
                best = max(best, x);
            } else if (x >= 0.5 / 255.0) {  // (as a skipped block's: 0 in the kernel's 8 bits)
                float alpha = 1.0 - exp(-extinction * x * piece);
                colour += trans * alpha * lut(x);
                trans *= 1.0 - alpha;
                if (trans < 1e-4) break;
            }
        }
    }
    if (mip) {
        if (best < 0.0) discard;
        gl_FragColor = vec4(lut(best), 1.0);
        return;
    }
    float a = 1.0 - trans;
    if (a <= 0.0) discard;
    gl_FragColor = vec4(colour / a, a);
}

// Ray casting of a field's cut through its grid, the static renders' rules
// (rot4d_widget/keep/volume.py): samples every u_step spacings at the middle of each piece of
// the ray inside the box; a sample counts only where its cell's nodes are all finite (the atlas's
// alpha, 1 at a finite node, 0 elsewhere, is 1 only there); values arrive quantised over clim to
// [0, 1] (8 bits), so the ramp of "volume" is the value itself.
//   u_mode 0 "volume": emission-absorption, front to back, extinction u_density / (longest side)
//          per scene unit at the top of the ramp; straight (not premultiplied) colour out.
//   u_mode 1 "mip": the largest value along the ray, opaque.
//   u_mode 2 "sections": the nearest of the planes x, y, z = lo + u_sections * span where the
//          sample counts, opaque.
// Colours: the 256-entry table u_lut, entry min(floor(256 x), 255) (matplotlib's lookup).
uniform sampler2D u_atlas;
uniform sampler2D u_lut;
uniform vec2 u_atlas_size;
uniform float u_mode;
uniform vec3 u_sections;
uniform float u_density;
uniform float u_step;
varying vec3 v_pos;
varying vec3 v_eye;
varying vec3 v_lo;
varying vec3 v_span;
varying vec3 v_shape;
varying vec3 v_tile;

const int MAX_STEPS = 1024;

// (luminance, alpha) of z-layer k of the grid at in-layer index coordinates xy (bilinear)
vec2 layer(float k, vec2 xy) {
    float row = floor((k + 0.5) / v_tile.z);
    float col = k - row * v_tile.z;
    vec2 texel = v_tile.xy + vec2(col * v_shape.x, row * v_shape.y) + xy + 0.5;
    vec4 t = texture2D(u_atlas, texel / u_atlas_size);
    return vec2(t.r, t.a);
}

// (value in [0, 1], 1 if it counts else 0) at grid index coordinates g
vec2 grid(vec3 g) {
    g = clamp(g, vec3(0.0), v_shape - 1.0);
    float k0 = min(floor(g.z), v_shape.z - 2.0);
    vec2 a = layer(k0, g.xy);
    vec2 b = layer(k0 + 1.0, g.xy);
    float ok = (min(a.y, b.y) > 0.996) ? 1.0 : 0.0;
    return vec2(mix(a.x, b.x, g.z - k0), ok);
}

vec3 lut(float x) {
    float i = min(floor(x * 256.0), 255.0);
    return texture2D(u_lut, vec2((i + 0.5) / 256.0, 0.5)).rgb;
}

void main() {
    vec3 dir = normalize(v_pos - v_eye);
    vec3 d = mix(dir, vec3(1e-12), vec3(equal(dir, vec3(0.0))));
    vec3 hi = v_lo + v_span;
    vec3 t1 = (v_lo - v_eye) / d;
    vec3 t2 = (hi - v_eye) / d;
    vec3 tn = min(t1, t2);
    vec3 tf = max(t1, t2);
    float t_in = max(max(max(tn.x, tn.y), tn.z), 0.0);
    float t_out = min(min(tf.x, tf.y), tf.z);
    if (!(t_out > t_in)) discard;
    vec3 per = (v_shape - 1.0) / v_span;  // grid index per scene unit
    vec3 g0 = (v_eye - v_lo) * per;
    vec3 gd = dir * per;
    if (u_mode > 1.5) {
        vec3 plane = v_lo + u_sections * v_span;
        vec3 tp = (plane - v_eye) / d;
        float best = 1e30;
        float x = 0.0;
        for (int a = 0; a < 3; a++) {
            float t = a == 0 ? tp.x : (a == 1 ? tp.y : tp.z);
            if (t >= t_in && t <= t_out && t < best) {
                vec2 s = grid(g0 + t * gd);
                if (s.y > 0.5) {
                    best = t;
                    x = s.x;
                }
            }
        }
        if (best > 1e29) discard;
        gl_FragColor = vec4(lut(x), 1.0);
        return;
    }
    float dt = u_step * v_span.x / (v_shape.x - 1.0);
    float extinction = u_density / max(max(v_span.x, v_span.y), v_span.z);
    bool mip = u_mode > 0.5;
    float best = -1.0;
    vec3 colour = vec3(0.0);
    float trans = 1.0;
    for (int i = 0; i < MAX_STEPS; i++) {
        float start = t_in + float(i) * dt;
        if (start >= t_out) break;
        float piece = min(dt, t_out - start);
        vec2 s = grid(g0 + (start + 0.5 * piece) * gd);
        if (s.y > 0.5) {
            if (mip) {
                best = max(best, s.x);
            } else {
                float alpha = 1.0 - exp(-extinction * s.x * piece);
                colour += trans * alpha * lut(s.x);
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

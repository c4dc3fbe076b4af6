attribute vec3 bar_a;
attribute vec3 bar_b;
uniform float u_bar_radius;
varying vec3 v_point;
varying vec3 v_a;
varying vec3 v_w;
varying float v_len;
void widen(vec3 c, vec2 e, vec2 f, inout vec4 box, inout float near) {
    float z = max(-c.z, 1.0e-4);
    vec2 q = c.xy / z;
    float pe = dot(q, e);
    float pf = dot(q, f);
    box = vec4(min(box.x, pe), max(box.y, pe), min(box.z, pf), max(box.w, pf));
    near = min(near, z);
}
void main() {
    vec3 a = (modelViewMatrix * vec4(bar_a, 1.0)).xyz;
    vec3 b = (modelViewMatrix * vec4(bar_b, 1.0)).xyz;
    vec3 axis = b - a;
    float len = length(axis);
    if (len < 1.0e-12) {
        v_point = vec3(0.0);
        v_a = vec3(0.0);
        v_w = vec3(0.0, 0.0, 1.0);
        v_len = 0.0;
        gl_Position = vec4(0.0, 0.0, 2.0, 1.0);
        return;
    }
    vec3 w = axis / len;
    // The box around the bar has sides u and v (both perpendicular to the axis).
    // Any such pair bounds the cylinder; taking u across the line of sight (and
    // v nearly along it) makes the box's projection hug the cylinder's, so the
    // quad is about 2r wide instead of up to 2.8r for a fixed helper axis.
    vec3 mid = 0.5 * (a + b);
    vec3 across = cross(w, mid);
    vec3 helper = abs(w.x) < 0.9 ? vec3(1.0, 0.0, 0.0) : vec3(0.0, 1.0, 0.0);
    if (dot(across, across) < 1.0e-8 * dot(mid, mid)) across = cross(w, helper);  // bar seen end-on
    float r = u_bar_radius;
    vec3 u = r * normalize(across);
    vec3 v = r * normalize(cross(w, u));
    // the bar's box (end discs included), projected on the plane z = -1 and
    // bounded by a rectangle aligned with the projected axis
    vec2 d = b.xy / max(-b.z, 1.0e-4) - a.xy / max(-a.z, 1.0e-4);
    vec2 e = dot(d, d) > 1.0e-12 ? normalize(d) : vec2(1.0, 0.0);
    vec2 f = vec2(-e.y, e.x);
    vec4 box = vec4(1.0e9, -1.0e9, 1.0e9, -1.0e9);
    float near = 1.0e9;
    widen(a + u + v, e, f, box, near);
    widen(a + u - v, e, f, box, near);
    widen(a - u + v, e, f, box, near);
    widen(a - u - v, e, f, box, near);
    widen(b + u + v, e, f, box, near);
    widen(b + u - v, e, f, box, near);
    widen(b - u + v, e, f, box, near);
    widen(b - u - v, e, f, box, near);
    vec2 pad = 0.01 * vec2(box.y - box.x, box.w - box.z);
    float pe = position.x < 0.0 ? box.x - pad.x : box.y + pad.x;
    float pf = position.y < 0.0 ? box.z - pad.y : box.w + pad.y;
    vec3 p = near * vec3(pe * e + pf * f, -1.0);
    v_point = p;
    v_a = a;
    v_w = w;
    v_len = len;
    gl_Position = projectionMatrix * vec4(p, 1.0);
}

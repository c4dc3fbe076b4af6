uniform vec3 u_bar_color;
uniform float u_bar_radius;
varying vec3 v_point;
varying vec3 v_a;
varying vec3 v_w;
varying float v_len;
// @include lighting.glsl
// @include impostor_depth.glsl

void main() {
    // ray from the eye (the origin) through this pixel against the closed cylinder
    vec3 ray = normalize(v_point);
    vec3 w = normalize(v_w);
    float r2 = u_bar_radius * u_bar_radius;
    float rw = dot(ray, w);
    float aw = dot(v_a, w);
    vec3 rp = ray - rw * w;
    vec3 ap = v_a - aw * w;
    float qa = dot(rp, rp);
    float qb = dot(rp, ap);
    float disc = qb * qb - qa * (dot(ap, ap) - r2);
    if (disc < 0.0 || qa < 1.0e-12) discard;
    float t = (qb - sqrt(disc)) / qa;
    vec3 hit = t * ray;
    float s = dot(hit - v_a, w);
    vec3 n;
    if (s < 0.0 || s > v_len) {
        // the front of the side lies past an end: the ray can only enter through that end's disc
        float cap = s < 0.0 ? 0.0 : v_len;
        vec3 c = v_a + cap * w;
        if (abs(rw) < 1.0e-6) discard;
        hit = (dot(c, w) / rw) * ray;
        vec3 off = hit - c;
        if (dot(off, off) > r2) discard;
        n = s < 0.0 ? -w : w;
    } else {
        n = (hit - v_a - s * w) / u_bar_radius;
    }
    write_depth(hit);
    gl_FragColor = vec4(shade(u_bar_color, n, hit, ray), 1.0);
}

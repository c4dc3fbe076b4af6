attribute vec3 tri_a;
attribute vec3 tri_b;
attribute vec3 tri_c;
attribute float tri_rgb;
varying vec3 v_color;
// @include lighting.glsl

void main() {
    vec3 p = position.x * tri_a + position.y * tri_b + position.z * tri_c;
    float r = floor(tri_rgb / 65536.0);
    float g = floor((tri_rgb - r * 65536.0) / 256.0);
    float b = tri_rgb - r * 65536.0 - g * 256.0;
    vec4 mv = modelViewMatrix * vec4(p, 1.0);
    vec3 n = normalize(normalMatrix * cross(tri_b - tri_a, tri_c - tri_a));
    // a flat face: dot(n, point) has one sign over it, so each corner picks the same side
    if (dot(n, mv.xyz) > 0.0) n = -n;  // light the side facing the viewer
    v_color = shade(vec3(r, g, b) / 255.0, n, mv.xyz);
    gl_Position = projectionMatrix * mv;
}

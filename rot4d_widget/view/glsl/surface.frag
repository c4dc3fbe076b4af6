uniform float u_opacity;
varying vec3 v_pos;
varying vec3 v_normal;
varying vec3 v_rgb;
// @include lighting.glsl

void main() {
    vec3 n = normalize(v_normal);
    if (dot(n, v_pos) > 0.0) n = -n;  // light the side facing the viewer (inside of an open cut too)
    gl_FragColor = vec4(shade(v_rgb, n, v_pos), u_opacity);
}

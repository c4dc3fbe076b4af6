uniform vec3 u_ball_color;
uniform float u_ball_radius;
varying vec3 v_centre;
varying vec3 v_point;
// @include lighting.glsl
// @include impostor_depth.glsl

void main() {
    vec3 ray = normalize(v_point);
    float b = dot(ray, v_centre);
    float q = dot(v_centre, v_centre) - u_ball_radius * u_ball_radius;
    float disc = b * b - q;
    if (disc < 0.0) discard;
    vec3 hit = (b - sqrt(disc)) * ray;
    vec3 n = (hit - v_centre) / u_ball_radius;
    write_depth(hit);
    gl_FragColor = vec4(shade(u_ball_color, n, hit, ray), 1.0);
}

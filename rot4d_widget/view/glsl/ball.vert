attribute vec4 ball;
uniform float u_ball_radius;
varying vec3 v_centre;
varying vec3 v_point;
void main() {
    if (ball.w < 0.5) {
        v_centre = vec3(0.0);
        v_point = vec3(0.0);
        gl_Position = vec4(0.0, 0.0, 2.0, 1.0);
        return;
    }
    vec3 c = (modelViewMatrix * vec4(ball.xyz, 1.0)).xyz;
    float r = u_ball_radius;
    float d = max(length(c), 1.0e-6);
    vec3 w = c / d;
    vec3 helper = abs(w.y) < 0.9 ? vec3(0.0, 1.0, 0.0) : vec3(1.0, 0.0, 0.0);
    vec3 u = normalize(cross(helper, w));
    vec3 v = cross(w, u);
    float s = 1.05 * r * d / sqrt(max(d * d - r * r, 1.0e-4 * r * r));
    vec3 p = c + s * (position.x * u + position.y * v);
    v_centre = c;
    v_point = p;
    gl_Position = projectionMatrix * vec4(p, 1.0);
}

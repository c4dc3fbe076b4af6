// A smooth surface (an isosurface of a 4-D field's slice), indexed and quantised:
// position: uint16 normalised to [0, 1] inside the box u_lo + [0, u_span]; normal: int8
// normalised to [-1, 1]; a_rgb: uint8 colour.  The companion sets all of them, and the
// box, as it applies one update.
uniform vec3 u_lo;
uniform vec3 u_span;
attribute vec3 a_rgb;
varying vec3 v_pos;
varying vec3 v_normal;
varying vec3 v_rgb;

void main() {
    vec4 mv = modelViewMatrix * vec4(u_lo + position * u_span, 1.0);
    v_pos = mv.xyz;
    v_normal = normalMatrix * normal;
    v_rgb = a_rgb;
    gl_Position = projectionMatrix * mv;
}

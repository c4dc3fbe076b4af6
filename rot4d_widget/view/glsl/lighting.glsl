uniform vec3 u_ambient;
uniform vec3 u_sky;
uniform vec3 u_ground;
uniform vec3 u_light_color;
uniform vec3 u_light_position;
uniform float u_specular;
// Ambient + a hemisphere fixed in the world (sky above the world's +y) + a point light riding
// with the camera, and a Blinn-Phong highlight of exponent 40.  Software WebGL runs it for every
// pixel an impostor covers, hidden or not, so it costs no more operations than it must
// (docs/design.md, "Drawing on software WebGL"; figures in docs/performance.md, "The draw").

// x^40 by six products (pow is exp2(40 log2 x): two polynomial approximations in software WebGL)
float highlight(float x) {
    float x2 = x * x;
    float x4 = x2 * x2;
    float x8 = x4 * x4;
    float x16 = x8 * x8;
    return x16 * x16 * x8;
}

// n the unit normal, p the point and v the unit direction from the eye to it (view coordinates)
vec3 shade(vec3 base, vec3 n, vec3 p, vec3 v) {
    vec3 up = viewMatrix[1].xyz;  // the world's +y seen from the camera: a rotation's column, unit
    vec3 hemi = mix(u_ground, u_sky, 0.5 + 0.5 * dot(n, up));
    vec3 l = normalize(u_light_position - p);
    float diffuse = max(dot(n, l), 0.0);
    vec3 h = normalize(l - v);
    float spec = diffuse > 0.0 ? highlight(max(dot(n, h), 0.0)) : 0.0;
    return base * (u_ambient + hemi + u_light_color * diffuse) + u_specular * spec * u_light_color;
}

vec3 shade(vec3 base, vec3 n, vec3 p) {
    return shade(base, n, p, normalize(p));
}

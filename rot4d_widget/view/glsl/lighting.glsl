uniform vec3 u_ambient;
uniform vec3 u_sky;
uniform vec3 u_ground;
uniform vec3 u_light_color;
uniform vec3 u_light_position;
uniform float u_specular;
uniform float u_shininess;

vec3 shade(vec3 base, vec3 n, vec3 p) {
    vec3 up = normalize((viewMatrix * vec4(0.0, 1.0, 0.0, 0.0)).xyz);
    vec3 hemi = mix(u_ground, u_sky, 0.5 + 0.5 * dot(n, up));
    vec3 l = normalize(u_light_position - p);
    float diffuse = max(dot(n, l), 0.0);
    vec3 h = normalize(l - normalize(p));
    float spec = diffuse > 0.0 ? pow(max(dot(n, h), 0.0), u_shininess) : 0.0;
    return base * (u_ambient + hemi + u_light_color * diffuse) + u_specular * spec * u_light_color;
}

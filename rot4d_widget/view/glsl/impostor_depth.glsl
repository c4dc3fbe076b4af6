uniform mat4 projectionMatrix;
void write_depth(vec3 hit) {
#if defined(GL_EXT_frag_depth) || __VERSION__ >= 300
    vec4 clip = projectionMatrix * vec4(hit, 1.0);
    gl_FragDepthEXT = 0.5 + 0.5 * clip.z / clip.w;
#endif
}

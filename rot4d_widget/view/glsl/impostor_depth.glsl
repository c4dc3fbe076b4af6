uniform mat4 projectionMatrix;
void write_depth(vec3 hit) {
#if defined(GL_EXT_frag_depth) || __VERSION__ >= 300
    // rows z and w of projectionMatrix * vec4(hit, 1.0): a three.js camera's (perspective or
    // orthographic) have nothing in their x and y columns, so z and w are exactly these
    float z = projectionMatrix[2].z * hit.z + projectionMatrix[3].z;
    float w = projectionMatrix[2].w * hit.z + projectionMatrix[3].w;
    gl_FragDepthEXT = 0.5 + 0.5 * z / w;
#endif
}

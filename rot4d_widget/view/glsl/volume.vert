// A field's cut drawn by ray casting (rendering "volume", "mip", "sections"): one box per cut,
// 36 vertices each (the unit cube's 12 triangles, CCW from outside), its back faces drawn
// (material side: BackSide, so the camera may be inside a box).  Per vertex, constant over a box:
// a_lo, a_span: the box of the grid's nodes in scene units (before the view's 3-D turn, the
// mesh's matrix); a_shape: nodes along x, y, z; a_tile: the box's region of the atlas texture
// (first texel u0, v0 and tiles per row).  The companion sets them all as it applies one update.
attribute vec3 a_lo;
attribute vec3 a_span;
attribute vec3 a_shape;
attribute vec3 a_tile;
varying vec3 v_pos;
varying vec3 v_eye;
varying vec3 v_lo;
varying vec3 v_span;
varying vec3 v_shape;
varying vec3 v_tile;

void main() {
    vec3 p = a_lo + position * a_span;
    v_pos = p;
    // the eye in the box's frame: the mesh's matrix is a rotation (the view's turn)
    vec3 e = cameraPosition - modelMatrix[3].xyz;
    v_eye = vec3(dot(e, modelMatrix[0].xyz), dot(e, modelMatrix[1].xyz), dot(e, modelMatrix[2].xyz));
    v_lo = a_lo;
    v_span = a_span;
    v_shape = a_shape;
    v_tile = a_tile;
    gl_Position = projectionMatrix * modelViewMatrix * vec4(p, 1.0);
}

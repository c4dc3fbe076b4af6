// The page's own picture of a field's cut (issue 36): one box per cut (a stack has several), its
// back faces drawn (the camera may be inside); the fragment shader (field.frag) casts a ray
// through the box and reads the 4-D data there.  Per vertex, constant over a box (page/raycast.js
// sets them from the predicted state):
//   position   the box's corner, in scene units (the kernel's grid box: where its rays start)
//   a_g0 .. a_gz  the affine map from a scene point X of this box to the data's 4-D index
//              coordinates, g = a_g0 + a_gx X.x + a_gy X.y + a_gz X.z (x, y, z, w)
//   a_lo, a_span  the kernel's grid box (first node, first to last node), scene units
//   a_cell     the kernel's grid spacing in scene units (x), the box's colour index (y)
attribute vec4 a_g0;
attribute vec4 a_gx;
attribute vec4 a_gy;
attribute vec4 a_gz;
attribute vec3 a_lo;
attribute vec3 a_span;
attribute vec2 a_cell;
varying vec3 v_pos;
varying vec3 v_eye;
varying vec4 v_g0;
varying vec4 v_gx;
varying vec4 v_gy;
varying vec4 v_gz;
varying vec3 v_lo;
varying vec3 v_span;
varying vec2 v_cell;

void main() {
    v_pos = position;
    // the eye in the box's frame: the mesh's matrix is a rotation (the view's turn)
    vec3 e = cameraPosition - modelMatrix[3].xyz;
    v_eye = vec3(dot(e, modelMatrix[0].xyz), dot(e, modelMatrix[1].xyz), dot(e, modelMatrix[2].xyz));
    v_g0 = a_g0;
    v_gx = a_gx;
    v_gy = a_gy;
    v_gz = a_gz;
    v_lo = a_lo;
    v_span = a_span;
    v_cell = a_cell;
    gl_Position = projectionMatrix * modelViewMatrix * vec4(position, 1.0);
}

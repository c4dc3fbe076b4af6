// 4-D rotations in the page, as rot4d_widget.core.rotation computes them: 4 x 4 matrices as
// Float64Array(16), row-major; points are rows rotated as p @ M^T; steps compose extrinsically
// (new = step @ old) and every composed matrix is re-orthonormalised by one Newton-Schulz step.

const AXES = "xyzw";

function planeAxes(plane) {
  if (typeof plane !== "string" || plane.length !== 2) throw new Error(`unknown rotation plane ${plane}`);
  const i = AXES.indexOf(plane[0]), j = AXES.indexOf(plane[1]);
  if (i < 0 || j <= i) throw new Error(`unknown rotation plane ${plane}`);
  return [i, j];
}

export function identity4() {
  const m = new Float64Array(16);
  m[0] = m[5] = m[10] = m[15] = 1;
  return m;
}

function setPlane(m, plane, angle) {
  const [i, j] = planeAxes(plane);
  const c = Math.cos(angle), s = Math.sin(angle);
  m[4 * i + i] = c;
  m[4 * i + j] = -s;
  m[4 * j + i] = s;
  m[4 * j + j] = c;
  return m;
}

// simple_rotation(plane, angle): cos, -sin / sin, cos in rows and columns (i, j) of the plane.
export function simpleRotation(plane, angle) {
  return setPlane(identity4(), plane, angle);
}

// double_rotation("xy,zw", alpha, beta): the two commuting blocks in one identity.
export function doubleRotation(planes, alpha, beta) {
  const [p1, p2] = String(planes).split(",");
  return setPlane(setPlane(identity4(), p1, alpha), p2, beta);
}

// a @ b, both 4 x 4 row-major; each entry summed in the order numpy's matmul does for 4 x 4
// (k = 0..3 left to right).
export function matmul4(a, b) {
  const out = new Float64Array(16);
  for (let i = 0; i < 4; i++) {
    for (let j = 0; j < 4; j++) {
      out[4 * i + j] = a[4 * i] * b[j] + a[4 * i + 1] * b[4 + j] + a[4 * i + 2] * b[8 + j] + a[4 * i + 3] * b[12 + j];
    }
  }
  return out;
}

export function transpose4(a) {
  const out = new Float64Array(16);
  for (let i = 0; i < 4; i++) for (let j = 0; j < 4; j++) out[4 * j + i] = a[4 * i + j];
  return out;
}

// reorthonormalize(M) = 1.5 M - 0.5 M (M^T M): squares the deviation from orthogonality.
export function reorthonormalize(m) {
  const mtm = matmul4(transpose4(m), m);
  const k = matmul4(m, mtm);
  const out = new Float64Array(16);
  for (let i = 0; i < 16; i++) out[i] = 1.5 * m[i] - 0.5 * k[i];
  return out;
}

// Arithmetic in the order numpy does it, so that the page's slicer and rows round as the kernel's
// (slicer.js, rows.js).  Where the order of additions or the sign of a zero decides a result
// (which side of atan2's branch cut a corner falls on, which triangle is drawn first), the page
// must make the same operations; each rule here was measured on numpy 2.4 (x86-64), signed
// zeros included, and is checked through the slicer's and rows' tests against numpy itself.

const TWO_PI = 2 * Math.PI;

// einsum("ij,ij->i") of three columns: (a0 b0 + a2 b2) + a1 b1, into an accumulator that starts
// at +0 (a zero sum is +0).
export const dot3 = (a0, a1, a2, b0, b1, b2) => ((a0 * b0 + a2 * b2) + a1 * b1) + 0;

// np.mod(a, 2 pi): fmod, moved into [0, 2 pi) when negative, +0 for a zero.
export function mod2pi(a) {
  const r = a % TWO_PI;
  if (r === 0) return 0;
  return r < 0 ? r + TWO_PI : r;
}

// The sum of a[lo .. lo + n) as np.add.reduce sums a float64 array: pairwise, in blocks of up to
// 128 summed in eight lanes.
export function pairwiseSum(a, lo, n) {
  if (n < 8) {
    let s = 0;
    for (let i = 0; i < n; i++) s += a[lo + i];
    return s;
  }
  if (n <= 128) {
    const r = [];
    for (let j = 0; j < 8; j++) r.push(a[lo + j]);
    let i = 8;
    for (; i < n - (n % 8); i += 8) for (let j = 0; j < 8; j++) r[j] += a[lo + i + j];
    let s = ((r[0] + r[1]) + (r[2] + r[3])) + ((r[4] + r[5]) + (r[6] + r[7]));
    for (; i < n; i++) s += a[lo + i];
    return s;
  }
  let half = Math.floor(n / 2);
  half -= half % 8;
  return pairwiseSum(a, lo, half) + pairwiseSum(a, lo + half, n - half);
}

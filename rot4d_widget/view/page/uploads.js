// What the companion uploads into three.js objects of its own or of pythreejs: versions that only
// rise, the volume box template, textures like pythreejs's placeholders.

// three.js re-uploads an attribute only when its `version` exceeds the one it uploaded last.
// pythreejs resets `version` to its model's (small) value when it re-syncs an attribute from the
// kernel, so counting up from there can stay below what the GPU holds and the upload is
// skipped: the old, shorter buffer is drawn with the new index count ("glDrawElements:
// Insufficient buffer size", no surface).  The surface's versions come from one counter that
// starts far above any pythreejs value and only rises.
let surfaceVersion = 2 ** 30;
export const nextSurfaceVersion = () => ++surfaceVersion;

// The unit cube's 12 triangles, counter-clockwise seen from outside (a volume box's template).
export const CUBE = [0,0,0,0,1,1,0,1,0,0,0,0,0,0,1,0,1,1,1,0,0,1,1,0,1,1,1,1,0,0,1,1,1,1,0,1,0,0,0,1,0,0,1,0,1,0,0,0,1,0,1,0,0,1,
  0,1,0,1,1,1,1,1,0,0,1,0,0,1,1,1,1,1,0,0,0,1,1,0,1,0,0,0,0,0,0,1,0,1,1,0,0,0,1,1,0,1,1,1,1,0,0,1,1,1,1,0,1,1];

// A texture of the same class and settings as ``t`` (a THREE.DataTexture), holding a 1 x 1 image.
export function likeTexture(t) {
  const T = t.constructor;
  const data = new Uint8Array(4);
  const c = new T(data, 1, 1, t.format, t.type, t.mapping, t.wrapS, t.wrapT, t.magFilter, t.minFilter);
  c.generateMipmaps = false;
  c.flipY = false;
  c.unpackAlignment = 1;
  return c;
}


// The page's copy of a field's 4-D data (issue 36; rot4d_widget/view/pagefield.py): the one-time
// transfers "field" (the quantised data, time tiled into one 3-D texture's texels) and
// "field_box" (the box's tables, for its cut: the outline bars), decoded once per key, the
// kernel told the page holds them, and the 3-D textures made from them once (three.js's
// DataTexture3D class taken from the layer's placeholder).  One copy per widget (its companion
// model), shared by its views; freed when the widget closes (`freeField`).
//
// The page asks for the data only when its WebGL can hold them (`noteContext`: a WebGL2 context
// whose MAX_3D_TEXTURE_SIZE reaches the texture's longest side, `field_config.texture_side`);
// otherwise it never holds a copy and every picture is the kernel's.

import { decodePolytope } from "./slicer.js";
import { transferStore, unpack } from "./transfer.js";

// three.js r97 constants
const LUMINANCE = 1024;
const RGBA = 1023;
const NEAREST = 1003;
const UNSIGNED_BYTE = 1009;
const LINEAR = 1006;

const held = new WeakMap();  // model -> {store, key, boxKey, copy, box, textures}
let context = null;  // {webgl2, max3d}: what the page's WebGL can hold, once a renderer was seen

// The renderer's context (a THREE.WebGLRenderer): WebGL2?  its 3-D texture limit.  True the first
// time it is known (the caller asks for the transfers then).
export function noteContext(renderer) {
  if (context || !renderer || !renderer.capabilities) return false;
  const gl = renderer.context;
  const webgl2 = !!renderer.capabilities.isWebGL2;
  context = { webgl2, max3d: webgl2 && gl ? gl.getParameter(gl.MAX_3D_TEXTURE_SIZE) : 0 };
  return true;
}

// Whether the page asks for transfer `name`: the field's data only where the context holds them.
export function wantsTransfer(model, name) {
  if (name !== "field") return true;
  const side = (model.get("field_config") || {}).texture_side;
  return !!context && context.webgl2 && Number.isFinite(side) && side <= context.max3d;
}

function entry(model) {
  let h = held.get(model);
  if (!h) {
    h = { store: transferStore(model), key: null, boxKey: null, copy: null, box: null, textures: null };
    held.set(model, h);
  }
  return h;
}

// The copy's numbers and arrays from a whole transfer: {shape, tiles, size, range, masked, texels,
// mask} (the arrays views of the transfer's bytes).
export function decodeField(meta, bytes) {
  const { arrays, scalars } = unpack(meta, bytes);
  const size = scalars.size;
  const texels = arrays.texels;
  if (!texels || texels.length !== 2 * size[0] * size[1] * size[2]) {
    throw new Error(`field transfer: ${texels ? texels.length : 0} texel bytes for a ${size.join(" x ")} texture`);
  }
  const bs = scalars.block_size;
  if (!arrays.blocks || arrays.blocks.length !== 4 * bs[0] * bs[1] * bs[2]) {
    throw new Error(`field transfer: ${arrays.blocks ? arrays.blocks.length : 0} block bytes for ${bs.join(" x ")} blocks`);
  }
  return { shape: scalars.shape, tiles: scalars.tiles, size, range: scalars.range, masked: !!scalars.masked,
           texels, mask: arrays.mask || null, block: scalars.block, blockShape: scalars.block_shape,
           blockTiles: scalars.block_tiles, blockSize: bs, blocks: arrays.blocks };
}

// The field and box the page holds for this widget, decoded once when their transfers are whole
// (the kernel told); {copy, box, key, boxKey, textures} or null while either is missing.
export function fieldArrived(model) {
  const store = transferStore(model);
  const t = store.done.get("field");
  const b = store.done.get("field_box");
  const h = entry(model);
  if (t && t.key !== h.key) {
    disposeTextures(h);
    h.copy = decodeField(t.meta, t.bytes);
    h.key = t.key;
    model.send({ event: "holds", name: "field", key: t.key });
  }
  if (b && b.key !== h.boxKey) {
    const { arrays, scalars } = unpack(b.meta, b.bytes);
    const msg = { ...scalars };
    for (const [name, a] of Object.entries(arrays)) msg[name] = new DataView(a.buffer, a.byteOffset, a.byteLength);
    h.box = decodePolytope(msg);
    h.boxKey = b.key;
    model.send({ event: "holds", name: "field_box", key: b.key });
  }
  const offered = model.get("page_data") || {};
  return h.copy && h.box && h.key === offered.field && h.boxKey === offered.field_box ? h : null;
}

// The texels of the data texture the shader reads (glsl/field_data.glsl): each node's code at its
// time k (r, g: high, low byte) and at time k + 1 (b, a; the last time's own again), in time k's
// tile, so one trilinear read gives both times a quadrilinear value mixes.  `copy`: decodeField's
// (`texels` two bytes a texel, `shape` [nx, ny, nz, nw], `tiles`, `size`).  Texels of no time stay 0.
export function pairedTexels(copy) {
  const [nx, ny, nz, nw] = copy.shape;
  const [tx, ty] = copy.tiles;
  const [W, H, D] = copy.size;
  const src = copy.texels;
  const out = new Uint8Array(4 * W * H * D);
  const origin = (k) => [(k % tx) * nx, (Math.floor(k / tx) % ty) * ny, Math.floor(k / (tx * ty)) * nz];
  for (let k = 0; k < nw; k++) {
    const [ax, ay, az] = origin(k);
    const [bx, by, bz] = origin(Math.min(k + 1, nw - 1));
    for (let z = 0; z < nz; z++) {
      for (let y = 0; y < ny; y++) {
        let a = 2 * ((az + z) * H * W + (ay + y) * W + ax);
        let b = 2 * ((bz + z) * H * W + (by + y) * W + bx);
        let o = 2 * a;
        for (let x = 0; x < nx; x++, a += 2, b += 2, o += 4) {
          out[o] = src[a];
          out[o + 1] = src[a + 1];
          out[o + 2] = src[b];
          out[o + 3] = src[b + 1];
        }
      }
    }
  }
  return out;
}

// The copy's 3-D textures ({data, mask, blocks}: the data's texels paired in time (`pairedTexels`),
// the mask a 1-texel one when every node is finite), made once with the class `T3`
// (THREE.DataTexture3D).  Once made, the textures hold all the page needs of the copy (each
// renderer uploads from their arrays): the transfer's bytes -- two a node, the mask's one -- are
// let go (`releaseBytes`), so the page keeps the paired texels alone beside the GPU's copy.
export function fieldTextures(h, T3) {
  if (h.textures) return h.textures;
  const c = h.copy;
  const make = (data, format, w, ht, d, filter = LINEAR) => {
    const t = new T3(data, w, ht, d);
    t.format = format;
    t.type = UNSIGNED_BYTE;
    t.magFilter = t.minFilter = filter;
    t.unpackAlignment = 1;
    t.flipY = false;
    t.generateMipmaps = false;
    t.needsUpdate = true;
    return t;
  };
  const [w, ht, d] = c.size;
  h.textures = {
    data: make(pairedTexels(c), RGBA, w, ht, d),
    mask: c.mask ? make(c.mask.slice(), LUMINANCE, w, ht, d) : make(new Uint8Array([255]), LUMINANCE, 1, 1, 1),
    blocks: make(c.blocks.slice(), RGBA, c.blockSize[0], c.blockSize[1], c.blockSize[2], NEAREST),
  };
  releaseBytes(h);
  return h.textures;
}

// The transfer's bytes of a copy whose textures are made: gone from the copy (its arrays) and
// from the widget's transfer store (its key stays, so the same copy is not asked for again).  A
// new copy comes as a new transfer and is decoded from that.
function releaseBytes(h) {
  h.copy = { ...h.copy, texels: null, mask: null, blocks: null };
  const t = h.store.done.get("field");
  if (t && t.key === h.key) t.bytes = null;
}

function disposeTextures(h) {
  if (!h.textures) return;
  for (const t of Object.values(h.textures)) t.dispose();
  h.textures = null;
}

// The widget closed: its textures go from the GPU, its copy and the transfers' bytes from memory.
export function freeField(model) {
  const h = held.get(model);
  if (h) disposeTextures(h);
  held.delete(model);
  const store = transferStore(model);
  for (const name of ["field", "field_box"]) {
    store.done.delete(name);
    store.asked.delete(name);
  }
}

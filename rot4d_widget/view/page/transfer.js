// One-time transfers from the kernel (rot4d_widget.view.transfer): data the page keeps -- a
// polytope to cut, a field's data to ray-cast -- offered by name and key in the companion's
// `page_data`, asked for once per page when not held, sent in chunks (each acknowledged: a paced
// transfer sends the next ones then), put together here and unpacked into typed arrays.  The
// store is per widget (its companion model) and shared by its views.

const TYPES = { float64: Float64Array, float32: Float32Array, int32: Int32Array, uint32: Uint32Array,
                uint8: Uint8Array, int8: Int8Array, uint16: Uint16Array, int16: Int16Array };

// {arrays: {name: TypedArray}, scalars} from `pack`'s meta and the payload's bytes (a Uint8Array).
export function unpack(meta, bytes) {
  const arrays = {};
  for (const [name, a] of Object.entries(meta.arrays || {})) {
    const T = TYPES[a.type];
    if (!T) throw new Error(`transfer: unknown array type ${a.type}`);
    if (a.offset % T.BYTES_PER_ELEMENT || a.offset + a.length * T.BYTES_PER_ELEMENT > bytes.byteLength) {
      throw new Error(`transfer: array ${name} lies outside the payload`);
    }
    arrays[name] = new T(bytes.buffer, bytes.byteOffset + a.offset, a.length);
  }
  return { arrays, scalars: meta.scalars || {} };
}

const stores = new WeakMap();

export function transferStore(model) {
  let s = stores.get(model);
  if (!s) {
    s = { done: new Map(), partial: new Map(), asked: new Map(), listeners: new Set() };
    stores.set(model, s);
  }
  return s;
}

// Ask for every transfer the kernel offers that this page does not hold (once per key) and
// `accept(name)` takes (default: all).
export function askForTransfers(model, accept = () => true) {
  const s = transferStore(model);
  const offered = model.get("page_data") || {};
  for (const [name, key] of Object.entries(offered)) {
    const have = s.done.get(name);
    if ((have && have.key === key) || s.asked.get(name) === key || !accept(name)) continue;
    s.asked.set(name, key);
    model.send({ event: "want", name, key });
  }
}

// A transfer chunk arrived (a custom message and its one buffer, a DataView): true when it made
// a transfer whole (then held in `done` under its name: {key, meta, bytes}, and listeners told).
export function receiveChunk(model, msg, buffer) {
  if (!msg || msg.event !== "transfer" || !buffer) return false;
  const s = transferStore(model);
  const id = `${msg.name}\u0000${msg.key}`;
  if (s.done.has(msg.name) && s.done.get(msg.name).key === msg.key) return false;  // another view's copy
  let p = s.partial.get(id);
  if (!p) {
    if (msg.part !== 0) return false;  // a transfer joined halfway (asked by another page): skip it
    p = { bytes: new Uint8Array(msg.bytes), filled: 0, next: 0, meta: msg.meta };
    s.partial.set(id, p);
  }
  if (msg.part !== p.next) return false;  // a chunk seen already (several views get each message)
  const chunk = new Uint8Array(buffer.buffer, buffer.byteOffset, buffer.byteLength);
  p.bytes.set(chunk, p.filled);
  p.filled += chunk.byteLength;
  p.next += 1;
  model.send({ event: "got", name: msg.name, key: msg.key, part: msg.part });  // a paced transfer sends on
  if (p.next < msg.parts) return false;
  s.partial.delete(id);
  s.done.set(msg.name, { key: msg.key, meta: p.meta, bytes: p.bytes });
  for (const f of [...s.listeners]) f(msg.name);
  return true;
}

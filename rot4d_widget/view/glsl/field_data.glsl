// The page's copy of a field's 4-D data (rot4d_widget/view/pagefield.py): one 3-D texture whose
// tiles are the times (w), tile k at (kx, ky, kz) = (k mod tx, (k div tx) mod ty, k div (tx ty)),
// each texel a node's 16-bit code over the copy's range at time k as two bytes (r: high, g: low)
// and at time k + 1 (b, a; page/field.js pairedTexels), filtered linearly each and recombined: the
// codes filtered linearly, both times of a quadrilinear value in one read.  A mask texture of the
// same layout (255 where the node is finite; one time a texel) is read only when the copy has a
// node that is not.
precision highp sampler3D;
uniform sampler3D u_data;
uniform sampler3D u_mask;
uniform vec4 u_shape;   // nodes along x, y, z, w
uniform vec3 u_tiles;   // tiles a side: tx, ty, tz
uniform vec3 u_size;    // the texture's texels: W, H, D
uniform float u_masked;

// the first texel of time k's tile
vec3 tileOrigin(float k) {
    float row = floor((k + 0.5) / u_tiles.x);
    float kz = floor((row + 0.5) / u_tiles.y);
    return vec3(k - row * u_tiles.x, row - kz * u_tiles.y, kz) * u_shape.xyz;
}

// the texture coordinates of node coordinates p (x, y, z, clamped into the tile: half a texel
// inside it at most, so linear filtering never reads a neighbouring tile) in time k's tile
vec3 texel(vec3 p, float k) {
    return (tileOrigin(k) + p + 0.5) / u_size;
}

// the codes at node coordinates p at times k and k + 1 (the last time's twice), in [0, 1]
vec2 codes(vec3 p, float k) {
    vec4 t = texture(u_data, texel(p, k));
    return vec2(t.r * 65280.0 + t.g * 255.0, t.b * 65280.0 + t.a * 255.0) / 65535.0;
}

// (the value at 4-D index coordinates g, in [0, 1] over the copy's range -- quadrilinear: trilinear
// in the two times around g.w, mixed; 1 if every node it mixes with a weight is finite, else 0)
vec2 field(vec4 g) {
    vec3 p = clamp(g.xyz, vec3(0.0), u_shape.xyz - 1.0);
    float w = clamp(g.w, 0.0, u_shape.w - 1.0);
    float k0 = min(floor(w), max(u_shape.w - 2.0, 0.0));
    float f = w - k0;
    vec2 c = codes(p, k0);
    bool two = u_shape.w > 1.5 && f > 0.0;
    float v = two ? mix(c.x, c.y, f) : c.x;
    float ok = 1.0;
    if (u_masked > 0.5) {
        float m = texture(u_mask, texel(p, k0)).r;
        if (two) m = mix(m, texture(u_mask, texel(p, k0 + 1.0)).r, f);
        ok = m > 0.9999 ? 1.0 : 0.0;
    }
    return vec2(v, ok);
}

// The block ranges (rot4d_widget/view/pagefield.py): the least and greatest code over each block of
// u_block cells a side in x, y, z and w, one RGBA texel a block (min high, min low, max high, max
// low), laid out as the data (block-time tiles); read without filtering.
uniform sampler3D u_blocks;
uniform vec4 u_block_shape;  // blocks along x, y, z, w
uniform vec3 u_block_tiles;
uniform float u_block;

// The block holding the cell (and the two times) the value at g is mixed from.
vec4 blockOf(vec4 g) {
    vec4 cell = min(floor(max(g, vec4(0.0))), max(u_shape - 2.0, vec4(0.0)));
    return min(floor(cell / u_block), u_block_shape - 1.0);
}

// (least, greatest) value of block b, in [0, 1] over the copy's range
vec2 blockRange(vec4 b) {
    float row = floor((b.w + 0.5) / u_block_tiles.x);
    float kz = floor((row + 0.5) / u_block_tiles.y);
    vec3 origin = vec3(b.w - row * u_block_tiles.x, row - kz * u_block_tiles.y, kz) * u_block_shape.xyz;
    vec4 t = texelFetch(u_blocks, ivec3(origin + b.xyz + 0.5), 0);
    return vec2(t.r * 65280.0 + t.g * 255.0, t.b * 65280.0 + t.a * 255.0) / 65535.0;
}

// Where a ray g = gE + t gD leaves block b (its cells' index range on every axis).
float blockExit(vec4 gE, vec4 gD, vec4 b) {
    float t = 1e30;
    for (int j = 0; j < 4; j++) {
        float r = gD[j];
        if (abs(r) < 1e-9) continue;
        float bound = r > 0.0 ? (b[j] + 1.0) * u_block : b[j] * u_block;
        t = min(t, (bound - gE[j]) / r);
    }
    return t;
}

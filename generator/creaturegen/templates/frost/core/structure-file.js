// Pure JS, zero three imports: decode the package's structure file into the two RGBA8 maps the GPU samples.
// The JavaScript twin of generator/creaturegen/frost/structure_file.py and structure.py derive_normals: the
// file holds four row-filtered 8-bit planes (density, thickness, height, detail height) in one zlib stream,
// and the normal map is derived here from the two heights. The derivation uses the same float64
// operations in the same order as numpy (IEEE 754 rounds each one identically), so the bytes uploaded
// are the bytes creaturegen's reference and its tests use. Do not reorder the arithmetic.

/** A fetched asset is not this package's file (wrong size, wrong content or a failed download). */
export class FrostAssetError extends Error {
  constructor(message) {
    super(message);
    this.name = 'FrostAssetError';
  }
}

/** Inflate a zlib stream with the browser's own decoder (Chromium, Firefox 113+, Safari 16.4+, Node 18+). */
export async function inflate(bytes) {
  if (typeof DecompressionStream !== 'function') {
    throw new FrostAssetError('frost: DecompressionStream is not available (needs Chromium, Firefox 113+, Safari 16.4+)');
  }
  const stream = new Blob([bytes]).stream().pipeThrough(new DecompressionStream('deflate'));
  return new Uint8Array(await new Response(stream).arrayBuffer());
}

/** Adler-32 of the inflated payload: the zlib stream's last four bytes, big-endian. */
export function zlibTrailer(bytes) {
  const n = bytes.length;
  return ((bytes[n - 4] << 24) | (bytes[n - 3] << 16) | (bytes[n - 2] << 8) | bytes[n - 1]) >>> 0;
}

/**
 * Undo one plane's row filter in place (bytes mod 256, texels outside the plane read as 0):
 * 'none', 'sub' (left), 'up' (above) or 'gradient' (left + above − above-left).
 */
export function unfilterPlane(plane, n, filter) {
  if (filter === 'none') return plane;
  if (filter !== 'sub' && filter !== 'up' && filter !== 'gradient') {
    throw new FrostAssetError(`frost: unknown structure-file filter ${JSON.stringify(filter)}`);
  }
  for (let y = 0; y < n; y++) {
    const row = y * n;
    for (let x = 0; x < n; x++) {
      const i = row + x;
      const left = x > 0 ? plane[i - 1] : 0;
      const above = y > 0 ? plane[i - n] : 0;
      const corner = x > 0 && y > 0 ? plane[i - n - 1] : 0;
      let prediction = left;
      if (filter === 'up') prediction = above;
      else if (filter === 'gradient') prediction = left + above - corner;
      plane[i] = (plane[i] + prediction) & 255;
    }
  }
  return plane;
}

/** Whole-sample mirror about the border texels (h[−k] = h[k]), as numpy's pad(mode="reflect"). */
function reflect(i, n) {
  if (i < 0) return -i;
  if (i >= n) return 2 * (n - 1) - i;
  return i;
}

/**
 * Encoded normal xy of an 8-bit height into out[4·texel + offset], out[4·texel + offset + 1]: the slope is
 * a central difference over `spacing` texels, n = normalise(−scale·Δu, −scale·Δv, 1), code = ⌊(0.5 + 0.5·n)·255 + 0.5⌋.
 */
export function deriveNormalCodes(height, n, { spacing, scale }, out, offset) {
  const k = spacing;
  for (let y = 0; y < n; y++) {
    const up = reflect(y + k, n) * n;
    const down = reflect(y - k, n) * n;
    for (let x = 0; x < n; x++) {
      const du = height[y * n + reflect(x + k, n)] - height[y * n + reflect(x - k, n)];
      const dv = height[up + x] - height[down + x];
      const nx = -scale * du;
      const ny = -scale * dv;
      const inv = 1.0 / Math.sqrt(nx * nx + ny * ny + 1.0);
      const o = 4 * (y * n + x) + offset;
      out[o] = Math.floor((0.5 + 0.5 * (nx * inv)) * 255.0 + 0.5);
      out[o + 1] = Math.floor((0.5 + 0.5 * (ny * inv)) * 255.0 + 0.5);
    }
  }
  return out;
}

/**
 * Decode a structure file (its bytes) with the plan's layout (PLAN.assets.structure). Returns the structure
 * map (R density, G thickness, B height, A 255) and the normal map (RG main xy, BA detail xy), both RGBA8,
 * N × N, row 0 = texture v = 0. Throws FrostAssetError when the file is not the one the layout describes.
 */
export async function decodeStructureFile(bytes, layout, source = 'the structure file') {
  if (bytes.length !== layout.bytes || zlibTrailer(bytes) !== layout.adler32) {
    throw new FrostAssetError(`frost: asset mismatch: ${source} is not ${layout.file} of this package `
      + `(${bytes.length} bytes, Adler-32 ${zlibTrailer(bytes)}; expected ${layout.bytes} bytes, Adler-32 ${layout.adler32})`);
  }
  const n = layout.resolution;
  const area = n * n;
  const payload = await inflate(bytes);
  if (payload.length !== layout.planes.length * area) {
    throw new FrostAssetError(`frost: ${source} inflates to ${payload.length} bytes, expected ${layout.planes.length * area}`);
  }
  const planes = layout.planes.map((_, p) => unfilterPlane(payload.subarray(p * area, (p + 1) * area), n, layout.filters[p]));
  const [density, thickness, height, detail] = planes;
  const structure = new Uint8Array(4 * area);
  for (let i = 0; i < area; i++) {
    structure[4 * i] = density[i];
    structure[4 * i + 1] = thickness[i];
    structure[4 * i + 2] = height[i];
    structure[4 * i + 3] = 255;
  }
  const normals = new Uint8Array(4 * area);
  deriveNormalCodes(height, n, layout.normals.main, normals, 0);
  deriveNormalCodes(detail, n, layout.normals.detail, normals, 2);
  return { structure, normals };
}

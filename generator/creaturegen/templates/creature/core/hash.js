// stateHash: two 32-bit FNV-1a lanes (different offsets) over bytes, printed as 16 hex digits.
// Used to prove seekTick(n) and stepTicks(n) reach the same state, byte for byte.

/** Hash of `tick` then every byte of `bytes` (a Uint8Array, or an array of them hashed in order). */
export function hashBytes(bytes, tick) {
  let h1 = 0x811c9dc5 >>> 0;
  let h2 = 0x050c5d1f >>> 0;
  const mix = (b) => {
    h1 = Math.imul(h1 ^ b, 0x01000193) >>> 0;
    h2 = Math.imul(h2 ^ b, 0x01000193) >>> 0;
    h2 = ((h2 << 13) | (h2 >>> 19)) >>> 0;
  };
  for (let k = 0; k < 4; k++) mix((tick >>> (8 * k)) & 255);
  for (const chunk of bytes instanceof Uint8Array ? [bytes] : bytes) {
    for (let i = 0; i < chunk.length; i++) mix(chunk[i]);
  }
  return h1.toString(16).padStart(8, '0') + h2.toString(16).padStart(8, '0');
}

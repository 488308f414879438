// stateHash: two 32-bit FNV-1a lanes (different offsets) over bytes, printed as 16 hex digits.
// Used to prove seekTick(n) and stepTicks(n) reach the same state, byte for byte.

export function hashBytes(bytes, tick) {
  let h1 = 0x811c9dc5 >>> 0;
  let h2 = 0x050c5d1f >>> 0;
  const mix = (b) => {
    h1 = Math.imul(h1 ^ b, 0x01000193) >>> 0;
    h2 = Math.imul(h2 ^ b, 0x01000193) >>> 0;
    h2 = ((h2 << 13) | (h2 >>> 19)) >>> 0;
  };
  for (let k = 0; k < 4; k++) mix((tick >>> (8 * k)) & 255);
  for (let i = 0; i < bytes.length; i++) mix(bytes[i]);
  return h1.toString(16).padStart(8, '0') + h2.toString(16).padStart(8, '0');
}

// A minimal reader for the reference-surface .glb this package ships (glTF 2.0 binary, one mesh).
// Pure JS, no three: returns typed arrays keyed by glTF attribute name. Any glTF viewer opens the
// same file; this reader exists so the runtime does not depend on three's addons.

const COMPONENTS = { 5123: Uint16Array, 5125: Uint32Array, 5126: Float32Array };
const SIZES = { SCALAR: 1, VEC2: 2, VEC3: 3, VEC4: 4, MAT4: 16 };

/** `source` names the file in errors (a server answering a missing file with an HTML page is common). */
export function parseGlb(buffer, source = 'surface') {
  const view = new DataView(buffer);
  if (buffer.byteLength < 20 || view.getUint32(0, true) !== 0x46546c67 || view.getUint32(4, true) !== 2) {
    throw new Error(`${source}: not a glTF 2.0 binary`);
  }
  const jsonLength = view.getUint32(12, true);
  const doc = JSON.parse(new TextDecoder().decode(new Uint8Array(buffer, 20, jsonLength)));
  const binStart = 20 + jsonLength + 8;
  const read = (index) => {
    const acc = doc.accessors[index];
    const bv = doc.bufferViews[acc.bufferView];
    const Type = COMPONENTS[acc.componentType];
    const count = acc.count * SIZES[acc.type];
    const offset = binStart + (bv.byteOffset || 0) + (acc.byteOffset || 0);
    return { array: new Type(buffer.slice(offset, offset + count * Type.BYTES_PER_ELEMENT)), itemSize: SIZES[acc.type] };
  };
  const node = doc.nodes[doc.scenes[doc.scene || 0].nodes[0]];
  const primitive = doc.meshes[node.mesh].primitives[0];
  const attributes = {};
  for (const [name, index] of Object.entries(primitive.attributes)) attributes[name] = read(index);
  // The candidate program tapes (vec4 rows: a header per program, then the instructions) travel in the
  // same file as the mesh they were compiled for; the node's extras name their accessor.
  const programIndex = node.extras?.programAccessor;
  const program = Number.isInteger(programIndex) ? read(programIndex).array : null;
  return { attributes, index: read(primitive.indices), program, extras: doc.asset.extras || {} };
}

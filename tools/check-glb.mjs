// Load a .glb with three.js's own GLTFLoader (generator/creaturegen/web_lab/node_modules, r185) in Node and print what it saw
// as JSON: the creaturegen surface asset's round trip through the loader a viewer would use.
//
//   node tools/check-glb.mjs surface.glb [--values]
//
// --values adds every attribute's values (small files only). Loader warnings are collected into the
// output instead of going to stderr.
import { readFileSync } from 'node:fs';

const here = new URL('../generator/creaturegen/web_lab/node_modules/three/examples/jsm/loaders/GLTFLoader.js', import.meta.url);
const { GLTFLoader } = await import(here.href);

const [file, ...flags] = process.argv.slice(2);
if (!file) {
	console.error('usage: node tools/check-glb.mjs FILE.glb [--values]');
	process.exit(2);
}
const withValues = flags.includes('--values');

const warnings = [];
console.warn = (...args) => warnings.push(args.map(String).join(' '));

const bytes = readFileSync(file);
const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);

function describe(attribute) {
	const data = attribute.isInterleavedBufferAttribute ? attribute.data : attribute;
	const out = {
		itemSize: attribute.itemSize,
		count: attribute.count,
		normalized: attribute.normalized,
		arrayType: data.array.constructor.name,
		interleaved: attribute.isInterleavedBufferAttribute === true,
	};
	if (attribute.isInterleavedBufferAttribute) out.stride = attribute.data.stride;
	if (withValues) {
		const values = [];
		for (let i = 0; i < attribute.count; i++) {
			for (let c = 0; c < attribute.itemSize; c++) values.push(attribute.getComponent(i, c));
		}
		out.values = values;
	}
	return out;
}

const gltf = await new Promise((resolve, reject) => new GLTFLoader().parse(buffer, '', resolve, reject));

const meshes = [];
gltf.scene.traverse((object) => {
	if (object.isMesh) meshes.push(object);
});
const mesh = meshes[0];
const geometry = mesh.geometry;
const attributes = {};
for (const name of Object.keys(geometry.attributes).sort()) attributes[name] = describe(geometry.attributes[name]);

let restFrames = null;
const restIndex = mesh.userData.restFramesAccessor;
if (restIndex !== undefined) {
	restFrames = describe(await gltf.parser.getDependency('accessor', restIndex));
}

console.log(
	JSON.stringify({
		meshCount: meshes.length,
		meshName: mesh.name,
		isMesh: mesh.isMesh === true,
		drawMode: mesh.isSkinnedMesh ? 'skinned' : 'triangles',
		vertexCount: geometry.attributes.position.count,
		index: describe(geometry.index),
		attributes,
		userData: mesh.userData,
		assetExtras: gltf.asset.extras ?? null,
		generator: gltf.asset.generator,
		restFrames,
		warnings,
	}),
);

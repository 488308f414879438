// The static crystalline structure: generated once at build time, shipped as one asset file (shared by
// content hash), fetched and decoded here into two RGBA8 data textures: structure (R density, G thickness,
// B height) and normals (RG main-scale normal, BA detail-scale normal), mirrored-repeat and linear-filtered.
import { DataTexture, LinearFilter, MirroredRepeatWrapping, NoColorSpace, RGBAFormat, UnsignedByteType } from 'three/webgpu';
import { PLAN } from '../core/plan.js';
import { FrostAssetError, decodeStructureFile } from '../core/structure-file.js';
import { assetUrl } from './assets.js';

/**
 * Fetch and decode the structure file: from beside the package, or from `assetBase` when given (for bundlers
 * that do not copy assets referenced relative to import.meta.url, such as esbuild, and for CDNs).
 */
async function loadStructure(assetBase) {
  const url = assetUrl('structure', assetBase);
  let response;
  try {
    response = await fetch(url);
  } catch (cause) {
    throw new FrostAssetError(`frost: cannot fetch ${url} (${cause}); pass options.assetBase if the assets live elsewhere`);
  }
  if (!response.ok) {
    throw new FrostAssetError(`frost: cannot load ${url} (HTTP ${response.status}); `
      + 'copy the package\'s assets/ folder where your bundle expects it, or pass options.assetBase');
  }
  try {
    return await decodeStructureFile(new Uint8Array(await response.arrayBuffer()), PLAN.assets.structure, String(url));
  } catch (error) {
    // Vite's dev-server dependency optimizer moves this module into node_modules/.vite/ without its assets,
    // and its fallback page then answers for the file: say how to fix that rather than only what failed.
    if (error instanceof FrostAssetError && String(url).includes('/.vite/')) {
      error.message += `; Vite's dependency optimizer moved ${PLAN.slug} away from its assets: add `
        + `optimizeDeps: { exclude: [${JSON.stringify(PLAN.slug)}] } to vite.config, or pass options.assetBase`;
    }
    throw error;
  }
}

function dataTexture(bytes, size, name) {
  const tex = new DataTexture(bytes, size, size, RGBAFormat, UnsignedByteType);
  tex.name = name;
  tex.colorSpace = NoColorSpace;
  tex.wrapS = MirroredRepeatWrapping;
  tex.wrapT = MirroredRepeatWrapping;
  tex.magFilter = LinearFilter;
  tex.minFilter = LinearFilter;
  tex.generateMipmaps = false;
  tex.flipY = false;
  tex.needsUpdate = true;
  return tex;
}

/**
 * The structure and normal textures, with the decoded bytes they were made from. Throws FrostAssetError
 * when the file cannot be fetched or decoded.
 */
export async function loadStructureTextures(assetBase) {
  const { structure: structureBytes, normals: normalBytes } = await loadStructure(assetBase);
  return {
    structureBytes,
    normalBytes,
    structureTex: dataTexture(structureBytes, PLAN.structure.resolution, 'frost.structure'),
    normalTex: dataTexture(normalBytes, PLAN.structure.resolution, 'frost.normals'),
  };
}

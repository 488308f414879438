// The projected-size contract a body's tier is chosen by (creaturegen creature/lod.py, the Python reference
// tests hold this to): its length L on screen, in pixels, from the camera's unjittered projection, against
// each built tier's subpixel size (CREATURE.projectedSizeMaxPx), with hysteresis so that a body at a
// boundary does not switch every frame. Pure JS: a three camera is read for fov, zoom, top and bottom only,
// never for a projection matrix a TAA pass may have offset by a subpixel jitter.

/** Coarse to fine: a body is drawn by the coarsest built tier whose subpixel size covers it. */
export const TIER_ORDER = Object.freeze(['distant', 'repeated', 'hero']);
/** A body moves to a coarser tier only once it is this fraction inside that tier's subpixel size. */
export const TIER_HYSTERESIS = 0.15;

/**
 * L on screen in pixels at view depth `depth` (along the camera's axis) for a viewport `viewportHeight`
 * pixels tall: a perspective camera by its vertical fov and zoom, an orthographic one by (top − bottom)
 * and zoom.
 */
export function projectedSizePx(length, depth, viewportHeight, camera) {
  const zoom = camera.zoom ?? 1;
  if (camera.isOrthographicCamera) return length * viewportHeight * zoom / (camera.top - camera.bottom);
  const half = Math.tan(camera.fov * Math.PI / 180 / 2);
  return length * viewportHeight * zoom / (2 * half * Math.max(depth, 1e-9));
}

/**
 * The tier for a body of `sizePx` now drawn by `current` (null: not yet drawn), among the built tiers
 * `ceilings` ({ tier: subpixel size }). The finest built tier takes any size; a coarser one a size up to
 * its ceiling, and a body switches down into it only below (1 − TIER_HYSTERESIS) of it.
 */
export function chooseTier(sizePx, current, ceilings) {
  // Indexed loops, no closure, array or iterator per call: a crowd asks this for every body every frame,
  // and a for-of allocates an iterator and a result per step until V8 optimises the caller.
  let finest = null;
  for (let i = 0; i < TIER_ORDER.length; i++) if (TIER_ORDER[i] in ceilings) finest = TIER_ORDER[i];
  if (finest === null) throw new Error('chooseTier: no tier is built');
  if (current !== null && current in ceilings && (current === finest || sizePx <= ceilings[current])) {
    for (let i = 0; i < TIER_ORDER.length; i++) {
      const t = TIER_ORDER[i];
      if (t === current) return current;
      if (t in ceilings && sizePx <= ceilings[t] * (1 - TIER_HYSTERESIS)) return t;
    }
  }
  for (let i = 0; i < TIER_ORDER.length; i++) {
    const t = TIER_ORDER[i];
    if (t in ceilings && (t === finest || sizePx <= ceilings[t])) return t;
  }
  return finest;
}

// Frost demo: a built frost package (/out/<slug>/, ?pkg=<slug>; &pointer=page forces the page's own pointer
// wiring even where the package has effect.attachPointer) used through its public API only, as an app
// would: a lit three.js scene behind the frozen pane, the canvas sized to the window (devicePixelRatio
// included), the pointer wiping the pane, and a requestAnimationFrame loop passing its timestamp / 1000 to
// effect.update(previousInstant, currentInstant). Pointer instants are event.timeStamp / 1000: the same clock.
//
// window.__lab (for the headless test) is ready once the first frames have rendered; its history() and
// capture() read the GPU back (diagnostics, never called per frame).
import * as THREE from 'three/webgpu';
import { checker, color, mix, positionWorld, screenUV, smoothstep } from 'three/tsl';
import { runPacedLoop, toBase64, watchPixelRatio } from './lab-common.js';

const params = new URLSearchParams(location.search);
const slug = params.get('pkg');
const statusLine = document.getElementById('status');
const problem = document.getElementById('problem');
const READY_AFTER_FRAMES = 3;
/** One clock for the frame loop and the pointer: requestAnimationFrame's timestamp and event.timeStamp are both
 *  milliseconds since the page's time origin; the effect takes seconds. */
const clock = (ms) => ms / 1000;

/** A scene worth seeing through the pane: a gradient sky, a chequered ground, bright lit shapes, shadows. */
function buildScene() {
  const scene = new THREE.Scene();
  // screenUV has v down on WebGPU: deep blue at the top, a warm horizon below.
  scene.backgroundNode = mix(color(0x0b2250), color(0xf0a060), smoothstep(0.05, 0.75, screenUV.y));

  const groundMaterial = new THREE.MeshStandardNodeMaterial({ roughness: 0.95 });
  groundMaterial.colorNode = mix(color(0x2c4f27), color(0x44703a), checker(positionWorld.xz.mul(0.5)));
  const ground = new THREE.Mesh(new THREE.PlaneGeometry(60, 60), groundMaterial);
  ground.rotation.x = -Math.PI / 2;
  ground.receiveShadow = true;
  scene.add(ground);

  const shapes = new THREE.Group();
  const add = (geometry, hex, x, y, z, options = {}) => {
    const mesh = new THREE.Mesh(geometry, new THREE.MeshStandardNodeMaterial({ color: hex, roughness: 0.35, metalness: 0.05, ...options }));
    mesh.position.set(x, y, z);
    mesh.castShadow = true;
    mesh.receiveShadow = true;
    shapes.add(mesh);
    return mesh;
  };
  const knot = add(new THREE.TorusKnotGeometry(0.7, 0.24, 200, 32), 0xe8702a, 0, 1.5, 0);
  const ball = add(new THREE.SphereGeometry(0.6, 48, 24), 0xd7263d, -2.3, 0.6, 0.8);
  const box = add(new THREE.BoxGeometry(1, 1, 1), 0x2e86de, 2.3, 0.5, 0.6);
  box.rotation.y = 0.5;
  add(new THREE.ConeGeometry(0.55, 1.4, 40), 0xf6c90e, 1.2, 0.7, -1.8);
  add(new THREE.CylinderGeometry(0.35, 0.35, 2.2, 40), 0x8e44ad, -1.4, 1.1, -2.0);
  const ring = add(new THREE.TorusGeometry(0.5, 0.16, 24, 64), 0x1abc9c, 3.4, 0.9, -1.2);
  // A row of white posts receding into the distance: depth and parallax behind the blur.
  for (let i = 0; i < 7; i++) add(new THREE.BoxGeometry(0.25, 1.6, 0.25), 0xf2f2f2, -6 + 2 * i, 0.8, -6);
  scene.add(shapes);

  scene.add(new THREE.HemisphereLight(0xcfe4ff, 0x3a4a2a, 1.1));
  const sun = new THREE.DirectionalLight(0xfff1dc, 2.6);
  sun.position.set(5, 8, 4);
  sun.castShadow = true;
  sun.shadow.mapSize.set(1024, 1024);
  Object.assign(sun.shadow.camera, { left: -9, right: 9, top: 9, bottom: -9, near: 0.5, far: 30 });
  sun.shadow.camera.updateProjectionMatrix();
  scene.add(sun);

  const camera = new THREE.PerspectiveCamera(45, window.innerWidth / window.innerHeight, 0.1, 100);
  function animate(t) {
    knot.rotation.set(0.3 * t, 0.5 * t, 0);
    ball.position.y = 0.6 + 0.5 * Math.abs(Math.sin(1.6 * t));
    ring.rotation.y = 0.8 * t;
    // A slow sway, so the thawed window shows a living scene.
    camera.position.set(7 * Math.sin(0.07 * t), 3.2, 7 * Math.cos(0.07 * t));
    camera.lookAt(0, 1, 0);
  }
  return { scene, camera, animate };
}

/**
 * The page's own pointer wiring, for packages without effect.attachPointer: one segment per pair of successive
 * samples (coalesced events included) while a button, a finger or a pen is down, in history UV (origin top-left,
 * v down) through the canvas's bounding rect, timed by event.timeStamp / 1000. Returns detach().
 */
function wirePointer(element, effect, warnings) {
  let active = null; // the pointerId being followed
  let last = null; // { t, uv, p } of the previous sample
  const sample = (event) => {
    const rect = element.getBoundingClientRect();
    const pressure = event.pointerType === 'mouse' || !(event.pressure > 0) ? 1 : event.pressure;
    return { t: clock(event.timeStamp), uv: [(event.clientX - rect.left) / rect.width, (event.clientY - rect.top) / rect.height], p: pressure };
  };
  const down = (event) => {
    // One pointer stream (segments must not overlap in time); a mouse wipes with its main button only.
    if (active !== null || (event.pointerType === 'mouse' && event.button !== 0)) return;
    active = event.pointerId;
    element.setPointerCapture?.(event.pointerId);
    last = sample(event);
  };
  const move = (event) => {
    if (event.pointerId !== active || last === null) return;
    const samples = event.getCoalescedEvents?.() ?? [];
    for (const e of samples.length ? samples : [event]) {
      const s = sample(e);
      if (!(s.t > last.t)) continue; // equal instants carry no time; the segment would do nothing
      try {
        effect.pointer({ t0: last.t, t1: s.t, start: last.uv, end: s.uv, pressure0: last.p, pressure1: s.p });
      } catch (error) {
        warnings.push(String(error?.message ?? error));
      }
      last = s;
    }
  };
  const up = (event) => {
    if (event.pointerId !== active) return;
    move(event);
    active = null;
    last = null;
  };
  element.addEventListener('pointerdown', down);
  element.addEventListener('pointermove', move);
  element.addEventListener('pointerup', up);
  element.addEventListener('pointercancel', up);
  return () => {
    element.removeEventListener('pointerdown', down);
    element.removeEventListener('pointermove', move);
    element.removeEventListener('pointerup', up);
    element.removeEventListener('pointercancel', up);
  };
}

/** Calls back whenever devicePixelRatio changes (browser zoom, a window dragged to another screen). */
async function main() {
  if (!slug) throw new Error('frost demo: add ?pkg=<slug> (a frost package folder of out/); the index at / lists them');
  document.getElementById('package').textContent = slug;
  document.title = `creaturegen demo: ${slug}`;
  const errors = window.__lab.errors;
  const warnings = [];

  const renderer = new THREE.WebGPURenderer({ antialias: true });
  renderer.onError = (info) => errors.push(`${info.api} ${info.type}: ${info.message}`);
  renderer.setPixelRatio(window.devicePixelRatio);
  renderer.setSize(window.innerWidth, window.innerHeight);
  renderer.shadowMap.enabled = true;
  document.body.prepend(renderer.domElement);
  await renderer.init();
  if (renderer.backend.isWebGPUBackend !== true) throw new Error('frost demo: this browser has no WebGPU (three fell back to WebGL2)');

  const pkg = await import(`/out/${encodeURIComponent(slug)}/index.js`);
  const { scene, camera, animate } = buildScene();
  const effect = await pkg.createFrostEffect(renderer, scene, camera);

  // The package's own pointer wiring when it has one (feature-detected: older packages lack it), the page's
  // otherwise. Both time a sample by clock(event.timeStamp), the loop's own clock.
  const attached = typeof effect.attachPointer === 'function' && params.get('pointer') !== 'page';
  const detachPointer = attached
    ? effect.attachPointer(renderer.domElement, { clock })
    : wirePointer(renderer.domElement, effect, warnings);
  const pointerSource = attached ? 'effect.attachPointer' : 'page fallback (pointer events → effect.pointer)';

  function resize() {
    renderer.setPixelRatio(window.devicePixelRatio);
    renderer.setSize(window.innerWidth, window.innerHeight);
    camera.aspect = window.innerWidth / window.innerHeight;
    camera.updateProjectionMatrix();
    effect.resize(window.innerWidth, window.innerHeight, renderer.getPixelRatio());
  }
  window.addEventListener('resize', resize);
  watchPixelRatio(resize);

  let previous = null; // the previous render instant (s), on the requestAnimationFrame clock
  let now = 0;
  let shownAt = -1;
  let fps = 0;
  function showStatus() {
    const [hw, hh] = effect.historySize;
    const size = renderer.getDrawingBufferSize(new THREE.Vector2());
    const c = effect.counters;
    statusLine.textContent = [
      `clock      t = ${now.toFixed(2)} s  (rAF timestamp and event.timeStamp, ms / 1000)`,
      `pointer    ${pointerSource}`,
      `tier       ${effect.tier}, history ${hw}×${hh} ${effect.format}`,
      `canvas     ${size.x}×${size.y} px (dpr ${renderer.getPixelRatio()}), ${fps.toFixed(0)} fps`,
      `segments   ${c.segmentsQueued} queued, ${c.segmentsRejected} rejected; ${c.catchUps ?? 0} stalls caught up, ${c.discontinuities} clock jumps`,
    ].join('\n');
    problem.textContent = [...errors, ...warnings].slice(-3).join('\n');
  }

  function frame(ms) {
    now = clock(ms);
    if (previous !== null) {
      effect.update(previous, now); // dt from two instants; a stall is caught up, a longer jump runs the policy
      fps = 0.9 * fps + 0.1 / Math.max(now - previous, 1e-3);
    }
    previous = now;
    animate(now);
    effect.render();
    if (now - shownAt > 0.25) { showStatus(); shownAt = now; }
  }
  const loop = runPacedLoop(renderer, frame, fail, READY_AFTER_FRAMES);

  // Diagnostics for the headless test: GPU readbacks, never part of the frame loop.
  let captureTarget = null;
  Object.assign(window.__lab, {
    package: slug,
    pointerSource,
    warnings,
    frames: loop.frames,
    instant: () => now,
    counters: () => JSON.parse(JSON.stringify(effect.counters)),
    /** R (visible thaw) of the history at UV points (origin top-left, v down), and its mean. */
    async history(points = []) {
      const { width, height, data } = await effect.readHistory();
      let sum = 0;
      for (let i = 0; i < width * height; i++) sum += data[4 * i];
      const at = ([u, v]) => {
        const x = Math.min(width - 1, Math.max(0, Math.floor(u * width)));
        const y = Math.min(height - 1, Math.max(0, Math.floor(v * height)));
        return data[4 * (y * width + x)];
      };
      return { width, height, mean: sum / (width * height), values: points.map(at) };
    },
    /** The frame as the canvas shows it (or one of the effect's debug views, e.g. 'scene': the scene without
     *  the pane), rendered off-screen and read back: mean RGB (0..255) of a (2r+1)² patch at each UV point
     *  (origin top-left, v down). Views captured in one call show the same instant. */
    async capture(points = [], { views = ['final'], r = 2, image = false } = {}) {
      const size = renderer.getDrawingBufferSize(new THREE.Vector2());
      if (!captureTarget || captureTarget.width !== size.x || captureTarget.height !== size.y) {
        captureTarget?.dispose();
        captureTarget = new THREE.RenderTarget(size.x, size.y, { depthBuffer: false });
      }
      const shown = effect.debugView;
      const reads = views.map((view) => {
        effect.setDebugView(view);
        renderer.setRenderTarget(captureTarget);
        effect.render();
        renderer.setRenderTarget(null);
        return renderer.readRenderTargetPixelsAsync(captureTarget, 0, 0, size.x, size.y);
      });
      effect.setDebugView(shown);
      const result = { width: size.x, height: size.y };
      for (const [i, view] of views.entries()) {
        const padded = await reads[i];
        result[view] = sample(padded, points, size, r);
        if (image && i === 0) result.image = unpad(padded, size);
      }
      return result;
    },
    detachPointer,
  });
}

/** The readback's rows without their padding, as base64 RGBA8 (first row first). */
function unpad(padded, size) {
  const rowBytes = Math.ceil((size.x * 4) / 256) * 256;
  const rgba = new Uint8Array(size.x * size.y * 4);
  for (let y = 0; y < size.y; y++) rgba.set(padded.subarray(y * rowBytes, y * rowBytes + size.x * 4), y * size.x * 4);
  return toBase64(rgba);
}

/** Mean RGB of a (2r+1)² patch at each UV point of a padded RGBA8 readback (rows of 256-byte multiples). */
function sample(padded, points, size, r) {
  const rowBytes = Math.ceil((size.x * 4) / 256) * 256;
  return points.map(([u, v]) => {
    const cx = Math.floor(u * size.x);
    const cy = Math.floor(v * size.y);
    const rgb = [0, 0, 0];
    let n = 0;
    for (let y = Math.max(0, cy - r); y <= Math.min(size.y - 1, cy + r); y++) {
      for (let x = Math.max(0, cx - r); x <= Math.min(size.x - 1, cx + r); x++) {
        for (let k = 0; k < 3; k++) rgb[k] += padded[y * rowBytes + 4 * x + k];
        n += 1;
      }
    }
    return rgb.map((c) => c / n);
  });
}

function fail(error) {
  console.error(error);
  problem.textContent = String(error?.message ?? error);
  statusLine.textContent = '';
  window.__lab.error = String(error?.stack ?? error);
  window.__lab.ready = true;
}

main().catch(fail);

// WebGPU smoke page: proves the lab's whole path works before any generated package is involved.
// three from the import map -> WebGPURenderer on a real WebGPU adapter -> one TSL compute kernel
// -> GPU-to-CPU readback -> window.__lab telemetry for the Playwright harness.
// Deterministic on purpose: no Math.random, Date.now or performance.now, so two runs publish the
// same numbers.

import * as THREE from 'three/webgpu';
import { Fn, float, instanceIndex, instancedArray, sin } from 'three/tsl';

const N = 1024;
const SCALE = 0.01;
// WGSL guarantees sin() only to an absolute error of 2^-11 (on [-pi, pi]); the kernel multiplies
// sin by i, so the honest bound on element i is 2^-11 * i plus a few float32 ulps for the rest.
const SIN_ABS_ERR = 2 ** -11;

window.__lab = { ready: false, error: null, smoke: null };

const out = document.getElementById('out');

// Spacing of float32 values around x: the unit the tolerance is counted in.
function ulp32(x) {
  const a = Math.abs(Math.fround(x));
  if (a === 0) return 2 ** -149;
  const e = Math.floor(Math.log2(a));
  return 2 ** Math.max(e - 23, -149);
}

// The same formula on the CPU in float32 steps (Math.fround after every operation), mirroring the
// kernel's order of operations; f64 sin rounded once is the best a float32 sin can do.
function referenceF32(i) {
  const fi = Math.fround(i);
  const x = Math.fround(fi * Math.fround(SCALE));
  const s = Math.fround(Math.sin(x));
  return Math.fround(Math.fround(s * fi) + 1);
}

async function main() {
  const gpuErrors = [];
  const renderer = new THREE.WebGPURenderer({ antialias: false });
  renderer.onError = (info) => {
    gpuErrors.push(`${info.api} ${info.type}: ${info.message}`);
  };
  renderer.onDeviceLost = (info) => {
    gpuErrors.push(`${info.api} device lost (${info.reason}): ${info.message}`);
  };
  await renderer.init();

  const backend = renderer.backend;
  const isWebGPUBackend = backend.isWebGPUBackend === true;
  const device = isWebGPUBackend ? backend.device : null;

  // Prefer the adapter behind the device three actually uses; ask for a fresh one only if the
  // browser does not expose GPUDevice.adapterInfo.
  let architecture = null;
  let architectureSource = null;
  let vendor = null;
  if (device && device.adapterInfo) {
    architecture = device.adapterInfo.architecture ?? null;
    vendor = device.adapterInfo.vendor ?? null;
    architectureSource = 'device.adapterInfo';
  } else if (navigator.gpu) {
    const adapter = await navigator.gpu.requestAdapter();
    if (adapter) {
      architecture = adapter.info.architecture ?? null;
      vendor = adapter.info.vendor ?? null;
      architectureSource = 'navigator.gpu.requestAdapter().info';
    }
  }

  const arr = instancedArray(N, 'float');
  const kernel = Fn(() => {
    const i = float(instanceIndex);
    arr.element(instanceIndex).assign(sin(i.mul(SCALE)).mul(i).add(1.0));
  })().compute(N);
  kernel.setName('smoke');

  // An error scope catches validation errors of this dispatch here, not at some later frame.
  if (device) device.pushErrorScope('validation');
  renderer.compute(kernel);
  const buffer = await renderer.getArrayBufferAsync(arr.value);
  if (device) {
    const scoped = await device.popErrorScope();
    if (scoped) gpuErrors.push(`WebGPU validation (scoped): ${scoped.message}`);
    await device.queue.onSubmittedWorkDone();
  }

  const gpu = new Float32Array(buffer);
  let maxAbsErr = 0;
  let maxAbsErrF32 = 0;
  let maxErrOverBound = 0;
  let worstIndex = -1;
  for (let i = 0; i < N; i++) {
    const exact = Math.sin(i * SCALE) * i + 1;
    const errF64 = Math.abs(gpu[i] - exact);
    const errF32 = Math.abs(gpu[i] - referenceF32(i));
    const bound = SIN_ABS_ERR * i + 4 * ulp32(exact);
    if (errF64 > maxAbsErr) maxAbsErr = errF64;
    if (errF32 > maxAbsErrF32) maxAbsErrF32 = errF32;
    if (errF64 / bound > maxErrOverBound) {
      maxErrOverBound = errF64 / bound;
      worstIndex = i;
    }
  }

  return {
    isWebGPUBackend,
    architecture,
    architectureSource,
    vendor,
    count: gpu.length,
    formula: 'sin(i*0.01)*i + 1',
    values: Array.from(gpu.subarray(0, 16)),
    allValues: Array.from(gpu),
    maxAbsErr,
    maxAbsErrF32,
    maxErrOverBound,
    worstIndex,
    gpuErrors,
  };
}

main().then(
  (smoke) => {
    window.__lab = { ready: true, error: null, smoke };
    out.textContent = JSON.stringify({ ...smoke, allValues: `[${smoke.allValues.length} values]` }, null, 2);
  },
  (err) => {
    const message = err && err.stack ? String(err.stack) : String(err);
    window.__lab = { ready: true, error: message, smoke: null };
    out.textContent = `error: ${message}`;
  },
);
